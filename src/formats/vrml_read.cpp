// The VRML97 reader's parent side: read bytes, pre-scan (file:line:column errors), then
// Coin in a child process (runIsolated), then the hand-over back into a Document.

#include "drape/formats/vrml_read.hpp"

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "vrml_internal.hpp"

// Present when a sanitizer runtime is linked (test and fuzz builds), absent otherwise.
extern "C" void __sanitizer_set_death_callback(void (*callback)(void)) __attribute__((weak));

namespace drape::formats::vrml {
namespace detail {
namespace {

/// First thing in the reader's child: a crash inside Coin must end the child by its own
/// signal so the parent reports it. Handlers inherited from the parent (a sanitizer's
/// death callback, a fuzzer's crash dump) would report it as the parent's crash.
void resetInheritedCrashHandlers() {
  for (const int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) std::signal(sig, SIG_DFL);
  if (__sanitizer_set_death_callback != nullptr) __sanitizer_set_death_callback(nullptr);
}

}  // namespace

extern const std::string_view kPreludeText;

const ScanOptions& scanOptions() {
  static const ScanOptions options = [] {
    ScanOptions o;
    o.knownProtos = scan(kPreludeText, "drape-nodes.wrl").declared;
    o.trackedTypes = {"ClothSet", "ClothMaterial", "Simulation", "Avatar",
                      // EGML's (docs/EVENTS.md): its errors name the line of the event too.
                      "EventGraph", "Sequence", "Parallel", "Loop", "Parameters", "Condition", "StateMachine",
                      "State", "Wait", "Play", "Wind", "Path"};
    return o;
  }();
  return options;
}

std::string readBytes(const std::string& path) {
  constexpr std::uintmax_t kMaxBytes = std::uintmax_t{512} << 20;
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw Error(fmt::format("{}: is a directory, not a VRML97 file", path));
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) throw Error(fmt::format("{}: cannot read ({})", path, ec.message()));
  if (size > kMaxBytes)
    throw Error(fmt::format("{}: {} bytes is more than drape reads as VRML97 (512 MiB)", path, size));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(fmt::format("{}: cannot open", path));
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string resolveUrl(const std::string& url, const std::string& baseDir) {
  std::string path = url;
  if (path.rfind("file://", 0) == 0) {
    path = path.substr(7);
  } else if (path.rfind("file:", 0) == 0) {
    path = path.substr(5);
  } else if (path.find("://") != std::string::npos) {
    return {};  // drape reads local files only
  }
  if (path.empty()) return {};
  std::filesystem::path p(path);
  if (p.is_relative() && !baseDir.empty()) p = std::filesystem::path(baseDir) / p;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(p, ec)) return {};
  return p.lexically_normal().string();
}

}  // namespace detail

std::string_view prelude() { return detail::kPreludeText; }

bool isDrapeNodeType(std::string_view type) {
  return type == "ClothSet" || type == "ClothMaterial" || type == "Simulation" || type == "Avatar";
}

Document readText(std::string_view text, const std::string& name, const std::string& baseDir,
                  const ReadOptions& options) {
  ScanResult scanned;
  if (options.prescan) {
    scanned = scan(text, name, detail::scanOptions());
  } else {
    scanned.text = std::string(text);
  }
  if (!options.isolate) return detail::fromWire(detail::toWire(detail::readWithCoin(scanned, name, baseDir)), name);
  const auto work = [&] {
    detail::resetInheritedCrashHandlers();
    return detail::toWire(detail::readWithCoin(scanned, name, baseDir));
  };
  return detail::fromWire(runIsolated(name, "VRML97 reader", work, options.limits), name);
}

Document readFile(const std::string& path, const ReadOptions& options) {
  const std::string text = detail::readBytes(path);
  return readText(text, path, std::filesystem::path(path).parent_path().string(), options);
}

}  // namespace drape::formats::vrml
