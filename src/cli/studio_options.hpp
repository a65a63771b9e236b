#pragma once
// What the studio's roles (drape anim-server, cloth-server, player) share on their command
// lines: the NATS server, how long to wait for a peer, and the durable consumers' names.

#include <unistd.h>

#include <chrono>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "drape/studio/bus.hpp"

namespace drape::cli {

/// The NATS server every role uses unless told: nats-server's default address.
inline constexpr const char* kDefaultServer = "nats://127.0.0.1:4222";

struct StudioOptions {
  std::string server = kDefaultServer;
  double giveUp_s = 0.0;   ///< 0: wait for peers for ever (a server); else give up after this
  double patience_s = 5.0;  ///< say what is awaited after this long, and again each time

  void add(CLI::App& app, const char* waitsFor) {
    app.add_option("--server", server, "The NATS server with JetStream (nats-server -js)")->capture_default_str();
    app.add_option("--give-up", giveUp_s,
                   fmt::format("Stop with exit code 4 after S seconds without {} (default: wait for ever)", waitsFor))
        ->check(CLI::PositiveNumber);
  }

  [[nodiscard]] std::chrono::milliseconds patience() const {
    return std::chrono::milliseconds(static_cast<long long>(1000.0 * patience_s));
  }
  [[nodiscard]] std::chrono::milliseconds giveUp() const {
    return std::chrono::milliseconds(static_cast<long long>(1000.0 * giveUp_s));
  }
};

/// A consumer name for this process: `role` and, for roles that may run side by side
/// (players), the host and the process.
[[nodiscard]] inline std::string consumerName(const std::string& role, bool perProcess) {
  if (!perProcess) return role;
  char host[256] = {};
  if (gethostname(host, sizeof host - 1) != 0) host[0] = '\0';
  std::string name = fmt::format("{}-{}-{}", role, host, ::getpid());
  for (char& c : name)
    if (c == '.' || c == '*' || c == '>' || c == ' ') c = '_';
  return name;
}

}  // namespace drape::cli
