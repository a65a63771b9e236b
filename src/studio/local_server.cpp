#include "drape/studio/local_server.hpp"

#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
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

int freePort() {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr = loopback(0);
  socklen_t length = sizeof addr;
  const bool ok = s >= 0 && ::bind(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0 &&
                  ::getsockname(s, reinterpret_cast<sockaddr*>(&addr), &length) == 0;
  if (s >= 0) ::close(s);
  if (!ok) throw Error("no free port on 127.0.0.1 for a nats-server", ExitCode::Unavailable);
  return ntohs(addr.sin_port);
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
    : store_(std::move(store)), jetStream_(jetStream), port_(freePort()) {
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
  const std::string port = std::to_string(port_), store = store_.string(), log = (store_ / "server.log").string();
  std::vector<std::string> args{exe, "-a", "127.0.0.1", "-p", port, "-l", log};
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
  while (!listening(port_)) {
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      throw Error(fmt::format("nats-server exited as it started (its log: {})", log), ExitCode::Unavailable);
    }
    if (std::chrono::steady_clock::now() > deadline) {
      stop();
      throw Error(fmt::format("nats-server does not listen on 127.0.0.1:{} after 20 s (its log: {})", port_, log),
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
