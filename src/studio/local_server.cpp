#include "drape/studio/local_server.hpp"

#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <iterator>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "drape/core/error.hpp"

namespace drape::studio {
namespace {

sockaddr_in loopback(int port) {
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  return addr;
}

/// The client port nats-server `pid` wrote to its ports file in `dir` once it listened (0
/// while it has written none). The file names the process, so a server of another process
/// on the same port is never taken for ours.
int portFileSays(const std::filesystem::path& dir, pid_t pid) {
  std::ifstream in(dir / fmt::format("nats-server_{}.ports", pid));
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string marker = "nats://127.0.0.1:";
  const std::size_t at = text.find(marker);
  if (at == std::string::npos) return 0;
  int port = 0;
  for (std::size_t i = at + marker.size(); i < text.size() && text[i] >= '0' && text[i] <= '9'; ++i)
    port = port * 10 + (text[i] - '0');
  return port;
}

bool listening(int port) {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  if (s < 0) return false;
  const sockaddr_in addr = loopback(port);
  const bool ok = ::connect(s, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) == 0;
  ::close(s);
  return ok;
}

}  // namespace

std::string natsServerExecutable() {
  for (const char* dir : {"/usr/sbin", "/usr/bin", "/usr/local/sbin", "/usr/local/bin"}) {
    const std::filesystem::path p = std::filesystem::path(dir) / "nats-server";
    if (::access(p.c_str(), X_OK) == 0) return p.string();
  }
  return "";
}

LocalServer::LocalServer(std::filesystem::path store, bool jetStream)
    : store_(std::move(store)), jetStream_(jetStream) {
  std::filesystem::create_directories(store_);
  start();
}

LocalServer::~LocalServer() { stop(); }

void LocalServer::start() {
  if (pid_ > 0) return;
  const std::string exe = natsServerExecutable();
  if (exe.empty())
    throw Error("nats-server is not installed (Debian's nats-server package; scripts/install-deps installs it)",
                ExitCode::Unavailable);
  // The first start lets nats-server choose a free port itself (-p -1) rather than taking
  // one found free a moment before, which another process may take in between; a restart
  // asks for the same port again.
  const std::string port = port_ > 0 ? std::to_string(port_) : "-1", store = store_.string(),
                    log = (store_ / "server.log").string(), portsDir = store_.string();
  std::vector<std::string> args{exe, "-a", "127.0.0.1", "-p", port, "-l", log, "--ports_file_dir", portsDir};
  if (jetStream_) args.insert(args.end(), {"-js", "-sd", store});
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_ = ::fork();
  if (pid_ == 0) {
    ::execv(exe.c_str(), argv.data());
    ::_exit(127);
  }
  if (pid_ < 0) throw Error("cannot start nats-server (fork failed)", ExitCode::Unavailable);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  for (;;) {
    const int said = portFileSays(store_, pid_);
    if (said > 0 && listening(said)) {
      port_ = said;
      return;
    }
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      throw Error(fmt::format("nats-server exited as it started (its log: {})", log), ExitCode::Unavailable);
    }
    if (std::chrono::steady_clock::now() > deadline) {
      stop();
      throw Error(fmt::format("nats-server does not listen on 127.0.0.1{} after 20 s (its log: {})",
                              port_ > 0 ? ":" + port : "", log),
                  ExitCode::Unavailable);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

void LocalServer::stop() {
  if (pid_ <= 0) return;
  ::kill(pid_, SIGTERM);
  int status = 0;
  ::waitpid(pid_, &status, 0);
  pid_ = -1;
}

}  // namespace drape::studio
