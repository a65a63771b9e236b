// `drape bench studio --json`: the studio's roles (docs/STUDIO.md) on a NATS JetStream server,
// beside drape run's loop in one process as the reference, timed in the same run. The roles
// run as processes of this drape (an anim-server and a cloth-server); the times are the
// stream's own, the instants the server stored each message, so they say what a player
// anywhere would see:
//
//   fast   the anim-server sends the take as fast as the server takes it: the cloth frames
//          per second the cloth-server publishes, against the reference's, the same work
//          without a bus
//   live   the anim-server sends in real time: per cloth frame past the lead-in, how long after
//          the last pose frame it needed the stream held it (the cloth-server's latency)
//   capture  the anim-server takes the motion live (--live) from a capture broadcast the
//          benchmark serves on a TCP port, a frame line at a time at the capture's own rate:
//          per pose frame and per cloth frame, how long after the capture sent the last
//          source frame it needed the stream held it (capture to pose, capture to cloth)

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <thread>
#include <iostream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "bench_machine.hpp"
#include "command.hpp"
#include "drape/core/error.hpp"
#include "drape/core/files.hpp"
#include "drape/core/log.hpp"
#include "drape/formats/bvh.hpp"
#include "drape/motion/live_motion.hpp"
#include "drape/studio/bus.hpp"
#include "drape/studio/local_server.hpp"
#include "drape/studio/messages.hpp"
#include "drape/studio/takes.hpp"
#include "measure.hpp"
#include "run_setup.hpp"

namespace drape::cli {
namespace {

namespace fs = std::filesystem;

struct StudioBenchOptions {
  std::string scene = std::string(DRAPE_SOURCE_DIR) + "/examples/walking_skirt/scene.wrl";
  std::string motion = std::string(DRAPE_SOURCE_DIR) + "/examples/walking_skirt/walk.bvh";
  std::string server;  ///< "": a nats-server of the benchmark's own
  std::string positions = "double";
  bool json = false;
};

/// drape run's loop without outputs: the frames are taken and dropped.
class DiscardSink final : public FrameSink {
 public:
  void begin(const std::vector<const sim::CharacterWorld*>&) override {}
  void write(const FrameTaken&) override {}
  void end(long) override {}
  void stats(const nlohmann::json& s) override { stats_ = s; }
  nlohmann::json stats_;
};

std::string slurpText(const fs::path& path) { return readFileText(path).value_or(""); }

/// This drape with `args`, its output in `log`; returns its process.
pid_t spawnDrape(const std::vector<std::string>& args, const fs::path& log) {
  const std::string exe = fs::read_symlink("/proc/self/exe").string();
  std::vector<std::string> all{exe};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int fd = ::creat(log.c_str(), 0644);
    if (fd >= 0) {
      ::dup2(fd, 1);
      ::dup2(fd, 2);
    }
    ::execv(exe.c_str(), argv.data());
    ::_exit(127);
  }
  if (pid < 0) throw Error("drape bench studio: cannot start a role (fork failed)", ExitCode::Internal);
  return pid;
}

int waitFor(pid_t pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// When the stream stored each frame of a take: pose frames by motion frame, cloth frames by
/// cloth frame (its last garment), and the take's End.
struct TakeTimes {
  std::vector<std::int64_t> frame_ns;
  std::int64_t end_ns = 0;
  std::size_t frameBytes = 0;
  std::string stats;
};

TakeTimes readTake(studio::Bus& bus, const std::string& source) {
  TakeTimes t;
  const studio::StreamRange range = bus.range(source);
  for (std::uint64_t seq = range.first; seq != 0 && seq <= range.last; ++seq) {
    const std::optional<studio::Received> r = bus.get(source, seq);
    if (!r) continue;
    const studio::Message m = studio::decode(r->data);
    const auto place = [&](std::int64_t frame) {
      if (t.frame_ns.size() <= static_cast<std::size_t>(frame)) t.frame_ns.resize(static_cast<std::size_t>(frame) + 1, 0);
      t.frame_ns[static_cast<std::size_t>(frame)] = std::max(t.frame_ns[static_cast<std::size_t>(frame)], r->time_ns);
      t.frameBytes = std::max(t.frameBytes, r->data.size());
    };
    if (const auto* p = std::get_if<studio::PoseFrame>(&m.payload)) place(p->frame);
    if (const auto* c = std::get_if<studio::ClothFrame>(&m.payload)) place(c->frame);
    if (const auto* e = std::get_if<studio::End>(&m.payload)) {
      t.end_ns = r->time_ns;
      t.stats = e->stats;
      if (!e->error.empty()) throw Error("drape bench studio: the take ended early: " + e->error);
    }
  }
  return t;
}

/// A capture program's broadcast of a BVH: a TCP server on a free loopback port that sends
/// the header to the first client at once, then each frame line at its time (frame i at
/// i * Frame Time after the first), noting when each was sent (ns on the clock the stream's
/// times are on). It leaves Nagle's algorithm on, as a capture program may.
class CaptureBroadcast {
 public:
  explicit CaptureBroadcast(const std::string& bvhPath) {
    const std::string text = readFileText(bvhPath).value_or("");
    const std::size_t headerBytes = formats::bvhHeaderLength(text).value_or(text.size());
    header_ = text.substr(0, headerBytes);
    frameTime_s_ = formats::parseBvhHeader(header_, bvhPath).frameTime;
    std::istringstream rest(text.substr(headerBytes));
    for (std::string line; std::getline(rest, line);)
      if (line.find_first_not_of(" \t\r") != std::string::npos) frames_.push_back(line + "\n");
    listener_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t length = sizeof address;
    if (listener_ < 0 || ::bind(listener_, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
        ::getsockname(listener_, reinterpret_cast<sockaddr*>(&address), &length) != 0 || ::listen(listener_, 1) != 0)
      throw Error("drape bench studio: cannot listen on a loopback port for the capture broadcast", ExitCode::Internal);
    url_ = "tcp://127.0.0.1:" + std::to_string(ntohs(address.sin_port));
    written_ns_.assign(frames_.size(), 0);
    thread_ = std::thread([this] { serve(); });
  }
  ~CaptureBroadcast() {
    ::shutdown(listener_, SHUT_RDWR);
    if (thread_.joinable()) thread_.join();
    ::close(listener_);
  }
  CaptureBroadcast(const CaptureBroadcast&) = delete;
  CaptureBroadcast& operator=(const CaptureBroadcast&) = delete;

  [[nodiscard]] const std::string& url() const { return url_; }
  [[nodiscard]] const std::string& header() const { return header_; }
  [[nodiscard]] const std::vector<std::string>& frames() const { return frames_; }
  /// When each frame line was written: waits for the broadcast to have sent them all.
  [[nodiscard]] const std::vector<std::int64_t>& writtenNs() {
    if (thread_.joinable()) thread_.join();
    return written_ns_;
  }

 private:
  static void sendAll(int fd, const std::string& text) {
    for (std::size_t done = 0; done < text.size();) {
      const ssize_t n = ::send(fd, text.data() + done, text.size() - done, MSG_NOSIGNAL);
      if (n <= 0) return;
      done += static_cast<std::size_t>(n);
    }
  }
  void serve() {
    const int peer = ::accept(listener_, nullptr, nullptr);
    if (peer < 0) return;
    sendAll(peer, header_);
    const auto began = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < frames_.size(); ++i) {
      std::this_thread::sleep_until(began + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                std::chrono::duration<double>(frameTime_s_ * static_cast<double>(i))));
      // Noted as the line goes, before the send returns: the anim-server may have it by then.
      written_ns_[i] = std::chrono::duration_cast<std::chrono::nanoseconds>(
                           std::chrono::system_clock::now().time_since_epoch())
                           .count();
      sendAll(peer, frames_[i]);
    }
    ::close(peer);
  }

  std::string header_, url_;
  std::vector<std::string> frames_;
  double frameTime_s_ = 1.0 / 30.0;
  int listener_ = -1;
  std::vector<std::int64_t> written_ns_;
  std::thread thread_;
};

/// For each pose frame a live take of `capture` makes on `setup`'s avatar, the source frames
/// that had come when it was ready (motion::LiveMotion, run here over the same lines).
std::vector<std::size_t> readyAfter(const RunSetup& setup, const CaptureBroadcast& capture) {
  const formats::BvhFile header = formats::parseBvhHeader(capture.header(), "capture");
  motion::LiveMotion live(*setup.characters.front().avatar, header, motionOptions(setup));
  std::vector<double> values(header.channelCount);
  std::vector<RigidTransform> joints(live.jointCount());
  std::vector<std::size_t> ready;
  int line = 0;
  for (const std::string& text : capture.frames()) {
    formats::parseBvhFrameLine(std::string_view(text).substr(0, text.size() - 1), "capture", ++line, values);
    live.push(values);
    while (live.next(joints)) ready.push_back(static_cast<std::size_t>(line));
  }
  live.finish();
  while (live.next(joints)) ready.push_back(capture.frames().size());
  return ready;
}

/// One take through an anim-server and a cloth-server of this drape; the streams' times.
std::pair<TakeTimes, TakeTimes> runTake(const StudioBenchOptions& o, const std::string& url, const fs::path& dir,
                                        const std::string& tag, bool fast, const std::string& live = "") {
  // Streams of their own for each take, beside whatever else the server holds.
  const std::string anim = fmt::format("bench-{}-anim-{}", tag, ::getpid());
  const std::string cloth = fmt::format("bench-{}-cloth-{}", tag, ::getpid());
  const pid_t server = spawnDrape({"cloth-server", o.scene, "--poses", anim, "--name", cloth, "--takes", "1",
                                   "--positions", o.positions, "--server", url, "--give-up", "120"},
                                  dir / (tag + "-cloth.log"));
  // The take starts once the cloth-server is up (its part fields built, following the
  // poses), as in a studio whose servers run before the takes.
  const fs::path clothLog = dir / (tag + "-cloth.log");
  for (int i = 0; i < 1200 && slurpText(clothLog).find("following the poses of") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  std::vector<std::string> animArgs{"anim-server", o.scene, "--name", anim, "--take", tag,
                                    "--server", url, "--give-up", "120"};
  animArgs.insert(animArgs.begin() + 2, {live.empty() ? "--motion" : "--live", live.empty() ? o.motion : live});
  if (fast) animArgs.push_back("--fast");
  const pid_t sender = spawnDrape(animArgs, dir / (tag + "-anim.log"));
  const int sent = waitFor(sender), served = waitFor(server);
  if (sent != 0 || served != 0)
    throw Error(fmt::format("drape bench studio: a role failed (anim-server {}, cloth-server {}); see {}", sent, served,
                            dir.string()));
  studio::Bus bus = studio::Bus::connect(url, "drape bench studio");
  std::pair<TakeTimes, TakeTimes> times{readTake(bus, anim), readTake(bus, cloth)};
  bus.remove(anim);
  bus.remove(cloth);
  return times;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5))];
}

RunFunction setupStudioBench(CLI::App& app) {
  static StudioBenchOptions o;
  app.add_flag("--json", o.json, "Print the figures as JSON")->required();
  app.add_option("--scene", o.scene, "Scene (default: the walking skirt)");
  app.add_option("--motion", o.motion, "Motion (default: the walking skirt's walk)");
  app.add_option("--server", o.server, "A NATS server with JetStream (default: the benchmark starts its own)");
  app.add_option("--positions", o.positions, "How the cloth-server sends positions: double or float")
      ->capture_default_str();
  return [] {
    if (lowerExtension(o.motion) != ".bvh")
      throw Error(fmt::format("drape bench studio: --motion {}: the capture take broadcasts a BVH", o.motion));
    // The reference: the same setup through drape run's loop in one process, no outputs.
    RunSetup setup = runSetupFromScene(o.scene);
    CharacterSetup* character = oneCharacter(setup, "drape bench studio");
    if (!character) throw Error(fmt::format("{}: the scene has no avatar", o.scene));
    addMotion(setup, *character, o.motion);
    setup.frames = defaultFrames(setup);
    DiscardSink reference;
    simulateInto(setup, reference, nullptr);

    char pattern[] = "/tmp/drape-bench-studio-XXXXXX";
    const char* made = ::mkdtemp(pattern);
    if (made == nullptr) throw Error("drape bench studio: cannot make a temporary directory", ExitCode::Internal);
    const fs::path dir(made);
    std::optional<studio::LocalServer> own;
    std::string url = o.server;
    if (url.empty()) {
      own.emplace(dir / "nats");
      url = own->url();
    }
    const auto [fastPoses, fastCloth] = runTake(o, url, dir, "fast", true);
    const auto [livePoses, liveCloth] = runTake(o, url, dir, "live", false);
    CaptureBroadcast capture(o.motion);
    const auto [capturePoses, captureCloth] = runTake(o, url, dir, "capture", false, capture.url());
    own.reset();
    std::error_code ignored;
    fs::remove_all(dir, ignored);

    const auto frames = static_cast<long>(fastCloth.frame_ns.size()) - 1;  // after frame 0
    const double rate = setup.settings.frameRate_hz, leadIn = character->leadIn_s;
    const double fastSeconds = 1e-9 * static_cast<double>(fastCloth.end_ns - fastCloth.frame_ns.front());
    std::vector<double> latency_ms;
    for (std::size_t k = 1; k < liveCloth.frame_ns.size(); ++k) {
      if (static_cast<double>(k) / rate <= leadIn) continue;  // the lead-in needs motion frame 0 only
      const auto need = static_cast<std::size_t>(studio::motionFramesNeeded(static_cast<std::int64_t>(k), rate, leadIn, rate));
      if (need > livePoses.frame_ns.size()) continue;  // the take's end: it needed the End
      latency_ms.push_back(1e-6 * static_cast<double>(liveCloth.frame_ns[k] - livePoses.frame_ns[need - 1]));
    }
    // Capture to pose and to cloth: a pose frame waits for the source frames LiveMotion
    // needed for it; a cloth frame for the pose frames its substeps read.
    const std::vector<std::size_t> ready = readyAfter(setup, capture);
    const std::vector<std::int64_t>& written = capture.writtenNs();
    std::vector<double> toPose_ms, toCloth_ms;
    for (std::size_t k = 0; k < capturePoses.frame_ns.size() && k < ready.size(); ++k)
      toPose_ms.push_back(1e-6 * static_cast<double>(capturePoses.frame_ns[k] - written[ready[k] - 1]));
    for (std::size_t k = 1; k < captureCloth.frame_ns.size(); ++k) {
      if (static_cast<double>(k) / rate <= leadIn) continue;
      const auto need = static_cast<std::size_t>(studio::motionFramesNeeded(static_cast<std::int64_t>(k), rate, leadIn, rate));
      if (need > ready.size() || need > capturePoses.frame_ns.size()) continue;
      toCloth_ms.push_back(1e-6 * static_cast<double>(captureCloth.frame_ns[k] - written[ready[need - 1] - 1]));
    }
    const auto largest = [](const std::vector<double>& v) { return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()); };
    const nlohmann::json clothStats = nlohmann::json::parse(fastCloth.stats, nullptr, false);

    nlohmann::json j;
    j["scene"] = o.scene;
    j["motion"] = o.motion;
    j["frames"] = frames;
    j["frame_rate"] = rate;
    j["positions"] = o.positions;
    j["bytes_per_pose_frame"] = fastPoses.frameBytes;
    j["bytes_per_cloth_frame"] = fastCloth.frameBytes;
    j["reference"] = {{"workload", "drape run's loop in one process (simulateInto), frames taken and dropped"},
                      {"loop_ms_per_frame", reference.stats_.value("loop_wall_ms_per_frame", 0.0)},
                      {"simulation_ms_per_frame", reference.stats_.value("ms_per_frame", 0.0)}};
    j["fast"] = {{"what", "anim-server --fast: cloth frames 1 to the End, as the stream stored them"},
                 {"cloth_frames_per_second", static_cast<double>(frames) / fastSeconds},
                 {"ms_per_frame", 1e3 * fastSeconds / static_cast<double>(frames)},
                 {"cloth_server_simulation_ms_per_frame", clothStats.value("ms_per_frame", 0.0)},
                 {"cloth_server_loop_ms_per_frame", clothStats.value("loop_wall_ms_per_frame", 0.0)}};
    j["live"] = {{"what", "anim-server in real time: per cloth frame past the lead-in, its time in the stream less "
                          "the time of the last pose frame it needed"},
                 {"frames_measured", latency_ms.size()},
                 {"latency_ms_median", median(latency_ms)},
                 {"latency_ms_p95", percentile(latency_ms, 0.95)},
                 {"latency_ms_max", latency_ms.empty() ? 0.0 : *std::max_element(latency_ms.begin(), latency_ms.end())},
                 {"frame_period_ms", 1e3 / rate}};
    j["capture"] = {{"what", "anim-server --live from a TCP capture broadcast of the motion at its own rate: per pose "
                             "frame and per cloth frame past the lead-in, its time in the stream less the time the "
                             "capture sent the last source frame it needed"},
                    {"source_frames", capture.frames().size()},
                    {"pose_frames", capturePoses.frame_ns.size()},
                    {"capture_to_pose_ms_median", median(toPose_ms)},
                    {"capture_to_pose_ms_p95", percentile(toPose_ms, 0.95)},
                    {"capture_to_pose_ms_max", largest(toPose_ms)},
                    {"capture_to_cloth_ms_median", median(toCloth_ms)},
                    {"capture_to_cloth_ms_p95", percentile(toCloth_ms, 0.95)},
                    {"capture_to_cloth_ms_max", largest(toCloth_ms)},
                    {"cloth_frames_measured", toCloth_ms.size()}};
    j["server"] = o.server.empty() ? "a nats-server of the benchmark's own on 127.0.0.1" : o.server;
    j["machine"] = benchMachine();
    std::cout << j.dump(2) << std::endl;
    return 0;
  };
}

const bool registered_bench_studio = registerCommand(
    {"studio", "The studio's roles on a NATS JetStream server beside drape run's loop, from a motion file and a live capture", "bench", 45, &setupStudioBench});

}  // namespace
}  // namespace drape::cli
