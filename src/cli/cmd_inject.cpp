// `drape inject --to NAME (--graph FILE.egml | --event NAME)`: to an anim-server playing an
// event graph live (docs/EVENTS.md): a graph that starts at once, its Plays blending from
// what the character does, or an event for the state machines of the graphs running.

#include <filesystem>
#include <iostream>

#include <fmt/format.h>

#include "command.hpp"
#include "drape/core/error.hpp"
#include "drape/core/files.hpp"
#include "drape/events/graph.hpp"
#include "drape/studio/bus.hpp"
#include "drape/studio/messages.hpp"
#include "studio_options.hpp"

namespace drape::cli {
namespace {

struct InjectOptions {
  std::string to = "anim", graph, event;
  double timeout_s = 10.0;
  StudioOptions studio;
};

int runInject(const InjectOptions& o) {
  studio::checkSourceName(o.to, "--to");
  if (o.graph.empty() && o.event.empty()) throw Error("drape inject: give --graph FILE.egml, --event NAME, or both");
  studio::Inject in;
  in.event = o.event;
  if (!o.graph.empty()) {
    // Read here first, so that a script with a mistake is told here, with its lines.
    (void)events::readGraph(o.graph);
    in.graph = readFileText(o.graph).value_or("");
    in.baseDir = std::filesystem::absolute(o.graph).parent_path().string();
  }
  studio::Bus bus = studio::Bus::connect(o.studio.server, "drape inject");
  std::vector<std::uint8_t> answer;
  try {
    answer = bus.request(studio::requestSubjectOf(o.to), studio::encode(studio::Message{"inject", "", in}),
                         std::chrono::milliseconds(static_cast<long long>(1000.0 * o.timeout_s)));
  } catch (const Error& e) {
    if (e.code() != ExitCode::Unavailable) throw;
    throw Error(fmt::format("{} (is 'drape anim-server --name {} --events FILE.egml' running on it?)", e.what(), o.to),
                ExitCode::Unavailable);
  }
  const studio::Message m = studio::decode(answer);
  const auto* reply = std::get_if<studio::InjectReply>(&m.payload);
  if (reply == nullptr) throw Error(fmt::format("'{}' answered with a {}, not a reply", o.to, studio::describe(m.payload)));
  if (!reply->accepted) throw Error(fmt::format("'{}' refused it: {}", o.to, reply->message));
  std::cout << fmt::format("{} (take {} of '{}')\n", reply->message, m.take, o.to);
  return 0;
}

RunFunction setupInject(CLI::App& app) {
  static InjectOptions o;
  app.add_option("--to", o.to, "The anim-server (its --name) playing an event graph with --events")->capture_default_str();
  app.add_option("--graph", o.graph,
                 "An EGML graph to start at once (its motions' relative paths are found where the file is, on the "
                 "anim-server's machine)");
  app.add_option("--event", o.event, "An event for the running graphs' state machines");
  app.add_option("--timeout", o.timeout_s, "Seconds to wait for the anim-server's answer")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  o.studio.add(app, "an answer");
  app.footer("Exit codes: 0 done, 2 the graph has a mistake or the anim-server refused it, 4 no anim-server listens.");
  return [] { return runInject(o); };
}

const bool registered_cmd_inject = registerCommand(
    {"inject", "Studio: start an event graph, or send an event, in an anim-server's live take", "", 73, &setupInject});

}  // namespace
}  // namespace drape::cli
