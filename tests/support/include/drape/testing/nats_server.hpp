#pragma once
// A real NATS server with JetStream for the studio's tests: nats-server started on
// 127.0.0.1 at a free port with a store of its own in a temporary directory, stopped (and
// its store removed) when the object goes. stop() and start() restart it on the same port
// and store, as a studio's server restarted by its operator.

#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "drape/testing/temp_dir.hpp"

namespace drape::testing {

class NatsServer {
 public:
  /// Starts the server (with JetStream unless `jetStream` is false). Throws
  /// std::runtime_error when nats-server is not installed or does not start listening.
  explicit NatsServer(bool jetStream = true) : jetStream_(jetStream) {
    static int count = 0;
    store_ = processTempDir("nats-" + std::to_string(count++));
    port_ = freePort();
    start();
  }
  ~NatsServer() { stop(); }
  NatsServer(const NatsServer&) = delete;
  NatsServer& operator=(const NatsServer&) = delete;

  [[nodiscard]] std::string url() const { return "nats://127.0.0.1:" + std::to_string(port_); }
  [[nodiscard]] int port() const { return port_; }

  void start() {
    if (pid_ > 0) return;
    const std::string exe = executable();
    const std::string port = std::to_string(port_), store = store_.string(), log = (store_ / "server.log").string();
    std::vector<std::string> args{exe, "-a", "127.0.0.1", "-p", port, "-l", log};
    if (jetStream_) args.insert(args.end(), {"-js", "-sd", store});
    pid_ = ::fork();
    if (pid_ == 0) {
      std::vector<char*> argv;
      for (std::string& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      ::execv(exe.c_str(), argv.data());
      ::_exit(127);
    }
    if (pid_ < 0) throw std::runtime_error("cannot fork for nats-server");
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (!listening()) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        throw std::runtime_error("nats-server exited at start (see " + log + ")");
      }
      if (std::chrono::steady_clock::now() > deadline) throw std::runtime_error("nats-server does not listen on " + port);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  /// Stops the server (SIGTERM: it closes its store cleanly) and waits for it.
  void stop() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGTERM);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
  }

 private:
  static std::string executable() {
    for (const char* dir : {"/usr/sbin", "/usr/bin", "/usr/local/bin", "/usr/local/sbin"}) {
      const std::filesystem::path p = std::filesystem::path(dir) / "nats-server";
      if (::access(p.c_str(), X_OK) == 0) return p.string();
    }
    throw std::runtime_error("nats-server is not installed (scripts/install-deps installs Debian's nats-server)");
  }

  static int freePort() {
    const int s = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = 0;
    socklen_t length = sizeof addr;
    if (s < 0 || ::bind(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
        ::getsockname(s, reinterpret_cast<sockaddr*>(&addr), &length) != 0)
      throw std::runtime_error("no free port on 127.0.0.1");
    ::close(s);
    return ntohs(addr.sin_port);
  }

  [[nodiscard]] bool listening() const {
    const int s = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = htons(static_cast<std::uint16_t>(port_));
    const bool ok = ::connect(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0;
    ::close(s);
    return ok;
  }

  bool jetStream_ = true;
  std::filesystem::path store_;
  int port_ = 0;
  pid_t pid_ = -1;
};

}  // namespace drape::testing
