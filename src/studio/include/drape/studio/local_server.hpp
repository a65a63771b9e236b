#pragma once
// A nats-server of our own on this machine: started on 127.0.0.1 at a free port of its own
// choosing, with JetStream and a store in a directory given, stopped when the object goes.
// For what needs a real server without one running (drape bench studio, the tests); a studio
// runs its own server as a service.

#include <sys/types.h>

#include <filesystem>
#include <string>

namespace drape::studio {

class LocalServer {
 public:
  /// Starts nats-server (with JetStream unless `jetStream` is false, its store in `store`)
  /// and waits until it listens. Throws drape::Error (Unavailable) when nats-server is not
  /// installed or does not start.
  explicit LocalServer(std::filesystem::path store, bool jetStream = true);
  ~LocalServer();
  LocalServer(const LocalServer&) = delete;
  LocalServer& operator=(const LocalServer&) = delete;

  [[nodiscard]] std::string url() const { return "nats://127.0.0.1:" + std::to_string(port_); }
  [[nodiscard]] int port() const { return port_; }

  /// Starts it again on the same port and store (after stop()).
  void start();
  /// Stops it (SIGTERM: it closes its store cleanly) and waits for it.
  void stop();

 private:
  std::filesystem::path store_;
  bool jetStream_ = true;
  int port_ = 0;
  pid_t pid_ = -1;
};

/// The nats-server executable ("" when none is installed).
[[nodiscard]] std::string natsServerExecutable();

}  // namespace drape::studio
