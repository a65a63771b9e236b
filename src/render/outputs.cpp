#include "drape/render/outputs.hpp"

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "drape/core/error.hpp"
#include "drape/core/progress.hpp"
#include "drape/render/follow.hpp"
#include "drape/render/headless.hpp"
#include "drape/render/run_replay.hpp"

namespace drape::render {
namespace {

namespace fs = std::filesystem;

constexpr int kSheetColumns = 4;
constexpr int kSheetTiles = kSheetColumns * kSheetColumns;
constexpr std::uint8_t kSheetBackground[3] = {18, 20, 26};

std::string shellQuote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

/// Streams RGB frames into the ffmpeg command, which encodes them as H.264 in an MP4
/// (padded to even sizes, yuv420p so every player can open it).
class VideoEncoder {
 public:
  VideoEncoder(const std::string& path, int width, int height, double frameRate) : path_(path) {
    if (!ffmpegAvailable())
      throw Error(fmt::format("{}: the ffmpeg command is needed for video (install ffmpeg)", path));
    const fs::path parent = fs::path(path).parent_path();
    if (!parent.empty() && !fs::is_directory(parent))
      throw Error(fmt::format("{}: directory {} does not exist", path, parent.string()));
    log_ = (fs::temp_directory_path() / fmt::format("drape-ffmpeg-{}.log", static_cast<long>(::getpid()))).string();
    const std::string command = fmt::format(
        "ffmpeg -hide_banner -loglevel error -y -f rawvideo -pixel_format rgb24 -video_size {}x{} -framerate {} -i - "
        "-vf {} -c:v libx264 -preset veryfast -crf 20 -pix_fmt yuv420p -movflags +faststart {} 2> {}",
        width, height, frameRate, shellQuote("pad=ceil(iw/2)*2:ceil(ih/2)*2"), shellQuote(path), shellQuote(log_));
    previousSigpipe_ = std::signal(SIGPIPE, SIG_IGN);  // a failing ffmpeg must not kill drape
    pipe_ = ::popen(command.c_str(), "w");
    if (pipe_ == nullptr) throw Error(fmt::format("{}: cannot start ffmpeg", path));
  }
  ~VideoEncoder() {
    if (pipe_ != nullptr) ::pclose(pipe_);
    std::signal(SIGPIPE, previousSigpipe_);
    std::error_code ignored;
    fs::remove(log_, ignored);
  }
  VideoEncoder(const VideoEncoder&) = delete;
  VideoEncoder& operator=(const VideoEncoder&) = delete;

  void write(const Image& image) {
    if (std::fwrite(image.rgb.data(), 1, image.rgb.size(), pipe_) != image.rgb.size())
      fail("ffmpeg stopped reading frames");
  }
  void finish() {
    const int status = ::pclose(pipe_);
    pipe_ = nullptr;
    if (status != 0) fail("ffmpeg failed");
  }

 private:
  [[noreturn]] void fail(const std::string& what) {
    std::ifstream in(log_);
    std::string line, last;
    while (std::getline(in, line))
      if (!line.empty()) last = line;
    throw Error(fmt::format("{}: {}{}", path_, what, last.empty() ? "" : ": " + last));
  }

  std::string path_;
  std::string log_;
  std::FILE* pipe_ = nullptr;
  void (*previousSigpipe_)(int) = SIG_DFL;
};

void checkSize(int width, int height, const char* what) {
  if (width < 16 || height < 16 || width > 8192 || height > 8192) {
    throw Error(fmt::format("{} {}x{} is outside 16x16 .. 8192x8192", what, width, height));
  }
}

void paste(Image& sheet, const Image& tile, int x0, int y0) {
  for (int y = 0; y < tile.height; ++y) {
    std::copy(tile.pixel(0, y), tile.pixel(0, y) + static_cast<std::ptrdiff_t>(tile.width) * 3,
              sheet.pixel(x0, y0 + y));
  }
}

/// The view at frame i of n: the job's camera, turned by its share of the orbit, framing
/// the follow camera's box when there is one.
ViewSettings viewAt(const ViewSettings& base, double orbitDeg, const std::vector<Aabb>& follow, std::int64_t i,
                    std::int64_t n) {
  ViewSettings v = base;
  if (n > 1) v.azimuthDeg += orbitDeg * static_cast<double>(i) / static_cast<double>(n - 1);
  if (!follow.empty()) v.bounds = follow[static_cast<std::size_t>(i)];
  return v;
}

HudInfo hudFor(const Frame& frame, const RunReplay& replay) {
  HudInfo hud;
  hud.time = frame.time;
  hud.frame = frame.index;
  hud.frames = replay.frameCount();
  hud.stages = frame.stages;
  return hud;
}

}  // namespace

std::vector<std::int64_t> contactSheetFrames(std::int64_t frames) {
  std::vector<std::int64_t> indices;
  if (frames <= 0) return indices;
  for (int i = 0; i < kSheetTiles; ++i) {
    indices.push_back(static_cast<std::int64_t>(
        std::llround(static_cast<double>(i) * static_cast<double>(frames - 1) / (kSheetTiles - 1))));
  }
  return indices;
}

bool ffmpegAvailable() { return std::system("ffmpeg -version >/dev/null 2>&1") == 0; }

RenderSummary renderRun(const std::string& runDirectory, const RenderJob& job) {
  const auto start = std::chrono::steady_clock::now();
  checkSize(job.width, job.height, "--size");
  checkSize(job.sheetWidth, job.sheetHeight, "contact sheet size");
  RunReplay replay(runDirectory);
  const std::int64_t frames = *replay.frameCount();
  const std::int64_t first = job.firstFrame, last = job.lastFrame < 0 ? frames - 1 : job.lastFrame;
  const std::string range = fmt::format("--range {}:{}", first, job.lastFrame < 0 ? "" : std::to_string(last));
  if (first < 0 || first >= frames || last >= frames)
    throw Error(fmt::format("{} is outside the run {}, which has frames 0 to {}", range, runDirectory, frames - 1));
  if (first > last) throw Error(fmt::format("{} ends before it starts", range));
  ViewSettings view = job.view;
  if (!view.bounds) view.bounds = replay.bounds();
  const std::vector<Aabb> follow = job.follow ? followFraming(replay) : std::vector<Aabb>{};
  if ((job.overlay.collisionColours || job.overlay.markers) && !replay.hasStates())
    spdlog::warn("{}: the run has no vertex states (it was made before drape recorded them): the collision "
                 "states and markers overlays show nothing",
                 runDirectory);

  if (!job.pngDirectory.empty()) {
    std::error_code ec;
    fs::create_directories(job.pngDirectory, ec);
    if (ec || !fs::is_directory(job.pngDirectory))
      throw Error(fmt::format("{}: cannot create the directory", job.pngDirectory));
  }
  std::unique_ptr<VideoEncoder> video;
  if (!job.videoPath.empty())
    video = std::make_unique<VideoEncoder>(job.videoPath, job.width, job.height, replay.frameRate());

  SubdividedSource shown(replay, job.subdivisionLevels);
  HeadlessRenderer renderer(shown.meshes(), job.width, job.height);
  RenderSummary summary;
  summary.glDescription = renderer.description();
  Frame frame;

  // Every frame, for PNG files and the video.
  if (!job.pngDirectory.empty() || video) {
    Progress progress("render", last - first + 1);
    for (std::int64_t i = first; i <= last; ++i) {
      shown.read(i, frame);
      HudInfo hud = hudFor(frame, replay);
      hud.show = job.hud;
      const Image image = renderer.render(frame, viewAt(view, job.orbitDeg, follow, i, frames), job.overlay, hud);
      if (!job.pngDirectory.empty())
        writePng((fs::path(job.pngDirectory) / fmt::format("frame_{:05d}.png", i)).string(), image);
      if (video) video->write(image);
      ++summary.frames;
      progress.update(i - first + 1);
    }
    if (video) video->finish();
  }

  // The contact sheet: 16 evenly spaced frames on a 4x4 grid, each labelled with its time code.
  if (!job.contactSheet.empty()) {
    const int gap = std::max(2, job.sheetWidth / 320);
    const int tileW = (job.sheetWidth - (kSheetColumns + 1) * gap) / kSheetColumns;
    const int tileH = (job.sheetHeight - (kSheetColumns + 1) * gap) / kSheetColumns;
    checkSize(tileW, tileH, "contact sheet tile");
    Image sheet;
    sheet.width = job.sheetWidth;
    sheet.height = job.sheetHeight;
    sheet.rgb.resize(static_cast<std::size_t>(sheet.width) * static_cast<std::size_t>(sheet.height) * 3);
    for (std::size_t p = 0; p < sheet.rgb.size(); ++p) sheet.rgb[p] = kSheetBackground[p % 3];
    renderer.resize(tileW, tileH);
    summary.sheetFrames = contactSheetFrames(last - first + 1);
    for (std::int64_t& index : summary.sheetFrames) index += first;
    for (int t = 0; t < kSheetTiles; ++t) {
      const std::int64_t index = summary.sheetFrames[static_cast<std::size_t>(t)];
      shown.read(index, frame);
      HudInfo hud = hudFor(frame, replay);
      hud.timeCodeOnly = true;
      const Image tile = renderer.render(frame, viewAt(view, job.orbitDeg, follow, index, frames), job.overlay, hud);
      paste(sheet, tile, gap + (t % kSheetColumns) * (tileW + gap), gap + (t / kSheetColumns) * (tileH + gap));
    }
    writePng(job.contactSheet, sheet);
  }
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

PreviewFiles renderPreview(const std::string& runDirectory) {
  PreviewFiles files;
  RenderJob job;
  job.follow = true;  // a character walking across the floor fills the picture
  files.contactSheet = (fs::path(runDirectory) / "preview.png").string();
  job.contactSheet = files.contactSheet;
  if (ffmpegAvailable()) {
    files.video = (fs::path(runDirectory) / "preview.mp4").string();
    job.videoPath = files.video;
  } else {
    spdlog::warn("ffmpeg is not installed: the preview has a contact sheet but no video");
  }
  renderRun(runDirectory, job);
  return files;
}

}  // namespace drape::render
