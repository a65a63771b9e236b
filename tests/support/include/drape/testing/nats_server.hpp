#pragma once
// A real NATS server with JetStream for the studio's tests: studio::LocalServer (nats-server
// on 127.0.0.1 at a free port) with its store in this test process's temporary directory.
// stop() and start() restart it on the same port and store, as a studio's server restarted
// by its operator.

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <stdexcept>
#include <string>

#include "drape/studio/local_server.hpp"
#include "drape/testing/temp_dir.hpp"

namespace drape::testing {

class NatsServer : public studio::LocalServer {
 public:
  explicit NatsServer(bool jetStream = true) : studio::LocalServer(freshStore(), jetStream) {}

 private:
  static std::filesystem::path freshStore() {
    static int count = 0;
    return processTempDir("nats-" + std::to_string(count++));
  }
};

/// A port on 127.0.0.1 where nobody answers, for as long as the object lives: bound and not
/// listening, so that a connection is refused and no other process (another test's
/// nats-server, under ctest -j) can take the port meanwhile, as it could a port let go.
class RefusingPort {
 public:
  RefusingPort() : socket_(::socket(AF_INET, SOCK_STREAM, 0)) {
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t length = sizeof addr;
    if (socket_ < 0 || ::bind(socket_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
        ::getsockname(socket_, reinterpret_cast<sockaddr*>(&addr), &length) != 0)
      throw std::runtime_error("no port to bind on 127.0.0.1");
    port_ = ntohs(addr.sin_port);
  }
  ~RefusingPort() {
    if (socket_ >= 0) ::close(socket_);
  }
  RefusingPort(const RefusingPort&) = delete;
  RefusingPort& operator=(const RefusingPort&) = delete;

  [[nodiscard]] std::string url() const { return "nats://127.0.0.1:" + std::to_string(port_); }

 private:
  int socket_ = -1;
  int port_ = 0;
};

}  // namespace drape::testing
