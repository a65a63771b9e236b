#pragma once
// A real NATS server with JetStream for the studio's tests: studio::LocalServer (nats-server
// on 127.0.0.1 at a free port) with its store in this test process's temporary directory.
// stop() and start() restart it on the same port and store, as a studio's server restarted
// by its operator.

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

}  // namespace drape::testing
