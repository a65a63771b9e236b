#include "live_capture.hpp"

#include <thread>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/core/files.hpp"
#include "drape/core/log.hpp"

namespace drape::cli {
namespace {

/// Waits between lines of a live source, and how often it says what it waits for.
constexpr std::chrono::milliseconds kLiveTick{200};

/// Opens `--live SOURCE`; a TCP source that is not up yet is tried again each second, saying
/// so every `patience`, until `giveUp` (0: for ever) or `stop`.
LineStream openLiveSource(const std::string& source, std::chrono::milliseconds patience, std::chrono::milliseconds giveUp,
                          const std::atomic<bool>& stop) {
  const auto began = std::chrono::steady_clock::now();
  auto said = began;
  for (;;) {
    try {
      return LineStream::open(source);
    } catch (const Error& e) {
      if (e.code() != ExitCode::Unavailable) throw;
      const auto now = std::chrono::steady_clock::now();
      if (stop || (giveUp.count() > 0 && now - began >= giveUp))
        throw Error(fmt::format("{}; gave up after {:.0f} s", e.what(), std::chrono::duration<double>(now - began).count()),
                    ExitCode::Unavailable);
      if (now - said >= patience) {
        spdlog::info("{}; trying again each second", e.what());
        said = now;
      }
      std::this_thread::sleep_for(std::chrono::seconds(1));
    }
  }
}

/// Waits for a line of a live source, saying what it waits for every `patience`; nothing
/// when the source has ended, `stop` was set, or it stayed silent for `giveUp` (0: for
/// ever), which `silent` then says.
std::optional<std::string> nextLiveLine(LineStream& source, std::chrono::milliseconds patience,
                                        std::chrono::milliseconds giveUp, const std::atomic<bool>& stop,
                                        const char* awaiting, bool& silent) {
  const auto began = std::chrono::steady_clock::now();
  auto said = began;
  std::string line;
  for (;;) {
    const LineStream::Status status = source.next(line, kLiveTick);
    if (status == LineStream::Status::Line) return line;
    if (status == LineStream::Status::Ended || stop) return std::nullopt;
    const auto now = std::chrono::steady_clock::now();
    if (giveUp.count() > 0 && now - began >= giveUp) {
      silent = true;
      return std::nullopt;
    }
    if (now - said >= patience) {
      spdlog::info("waiting for {} from {} ({:.0f} s silent, after line {})", awaiting, source.name(),
                   std::chrono::duration<double>(now - began).count(), source.lineNumber());
      said = now;
    }
  }
}

/// The BVH header of a live source: its lines up to "Frame Time:". Throws where the source
/// ends or goes silent first, or the header runs past any BVH's size.
std::string readLiveHeader(LineStream& source, const LiveCapture::Options& options, const std::atomic<bool>& stop) {
  constexpr std::size_t kMaxHeader = std::size_t{16} << 20;
  std::string header;
  bool silent = false;
  while (const std::optional<std::string> line =
             nextLiveLine(source, options.patience, options.giveUp, stop, "a BVH header", silent)) {
    header += *line;
    header += '\n';
    if (formats::endsBvhHeader(*line)) return header;
    if (header.size() > kMaxHeader)
      throw Error(fmt::format("{}:{}: no 'Frame Time:' in the first {} MiB: not a BVH header", source.name(),
                              source.lineNumber(), kMaxHeader >> 20));
  }
  if (silent) throw Error(fmt::format("{}: no BVH header came within --give-up", source.name()), ExitCode::Unavailable);
  if (stop) throw Error(fmt::format("{}: stopped (a signal) before the BVH header came", source.name()));
  if (!source.endReason().empty())
    throw Error(fmt::format("{}: {} before its BVH header ended", source.name(), source.endReason()), ExitCode::Unavailable);
  // What there is, parsed, says what is missing where.
  (void)formats::parseBvhHeader(header, source.name());
  throw Error(fmt::format("{}:{}: the source ended before its BVH header did", source.name(), source.lineNumber()));
}

/// `--live-header FILE`: a BVH file's header, its lines up to "Frame Time:" (its frames are
/// not read), for a source that sends frame lines only.
std::optional<formats::BvhFile> headerOfFile(const std::string& path) {
  if (path.empty()) return std::nullopt;
  if (lowerExtension(path) != ".bvh")
    throw Error(fmt::format("--live-header {}: expected a .bvh file (its skeleton: the header up to Frame Time)", path));
  const std::optional<std::string> text = readFileText(path);
  if (!text) throw Error(fmt::format("--live-header {}: no such file", path));
  if (const std::optional<std::size_t> length = formats::bvhHeaderLength(*text))
    return formats::parseBvhHeader(std::string_view(*text).substr(0, *length), path);
  (void)formats::parseBvhHeader(*text, path);  // says what is missing where
  throw Error(fmt::format("{}: no 'Frame Time:' line, so no BVH header", path));
}

/// The source, opened, with what it reads from.
LineStream openedAndSaid(const LiveCapture::Options& options, const std::atomic<bool>& stop, bool headerFromFile) {
  LineStream source = openLiveSource(options.source, options.patience, options.giveUp, stop);
  spdlog::info("reading a live BVH from {}{}", source.name(),
               headerFromFile ? fmt::format(" (frame lines only: the skeleton is {}'s)", options.headerFile) : "");
  return source;
}

}  // namespace

LiveCapture::LiveCapture(const scene::Avatar& avatar, const Options& options, const motion::MotionOptions& motion,
                         const std::atomic<bool>& stop)
    // A header file first: a bad one is said before the source is waited for.
    : LiveCapture(avatar, options, motion, stop, headerOfFile(options.headerFile)) {}

LiveCapture::LiveCapture(const scene::Avatar& avatar, const Options& options, const motion::MotionOptions& motion,
                         const std::atomic<bool>& stop, std::optional<formats::BvhFile> fileHeader)
    : options_(options),
      stop_(stop),
      source_(openedAndSaid(options, stop, fileHeader.has_value())),
      header_(fileHeader ? std::move(*fileHeader)
                         : formats::parseBvhHeader(readLiveHeader(source_, options_, stop_), source_.name())),
      live_(avatar, header_, motion),
      values_(header_.channelCount) {}

void LiveCapture::keepApart(std::shared_ptr<sim::LiveKeepApart> keep) {
  keep_ = std::move(keep);
  retargeted_.resize(live_.jointCount());
}

bool LiveCapture::next(std::span<RigidTransform> joints) {
  if (!keep_) return nextRetargeted(joints);
  while (!keep_->next(joints)) {
    if (keepFinished_) return false;
    if (nextRetargeted(retargeted_)) {
      keep_->push(retargeted_);
    } else {
      keep_->finish();
      keepFinished_ = true;
    }
  }
  return true;
}

bool LiveCapture::nextRetargeted(std::span<RigidTransform> joints) {
  for (;;) {
    if (live_.next(joints)) return true;
    if (finished_) return false;
    const std::optional<std::string> line =
        nextLiveLine(source_, options_.patience, options_.giveUp, stop_, "motion frames", silent_);
    if (!line) {
      // However the source ended, the frames it sent are the motion's: the last ones resampled out.
      live_.finish();
      finished_ = true;
      continue;
    }
    if (line->find_first_not_of(" \t\r") == std::string::npos) continue;
    try {
      formats::parseBvhFrameLine(*line, source_.name(), source_.lineNumber(), values_);
      previous_ = values_;
    } catch (const Error& e) {
      // A live motion survives a bad line: the frame before it stands in, so it keeps its time.
      if (++badLines_ <= 10 || badLines_ % 100 == 0)
        spdlog::warn("{} ({})", e.what(), previous_.empty() ? "skipped: no frame before it" : "the frame before it stands in");
      if (previous_.empty()) continue;
      values_ = previous_;
    }
    live_.push(values_);
  }
}

std::string LiveCapture::ended() const {
  if (silent_)
    return fmt::format("{} went silent for {:g} s (--give-up)", source_.name(),
                       static_cast<double>(options_.giveUp.count()) / 1000.0);
  if (stop_) return "stopped (a signal)";
  if (!source_.endReason().empty()) return fmt::format("{}: {}", source_.name(), source_.endReason());
  return "";
}

}  // namespace drape::cli
