// `drape inspect FILE.egml`: an EGML event graph (docs/EVENTS.md) as a tree: each event with
// its line, what it does and, where the graph says so by itself, how long it lasts.

#include <cmath>
#include <optional>

#include <fmt/ostream.h>
#include <fmt/ranges.h>

#include "command.hpp"
#include "drape/events/graph.hpp"
#include "drape/events/runtime.hpp"

namespace drape::cli {
namespace {

/// How long an event lasts where its fields alone say (a Play with its `to`, waits and the
/// control events over them); none where it depends on the motion's length, a parameter, an
/// event sent from outside, or it runs for ever.
std::optional<double> lasts(const events::Event& e) {
  using events::Kind;
  std::optional<double> d = 0.0;
  switch (e.kind) {
    case Kind::Wait: return e.duration_s;
    case Kind::Wind: return e.duration_s < 0.0 ? 0.0 : e.duration_s;
    case Kind::Path: {
      const double d = events::PathCourse(e).duration();
      return d >= 0.0 ? std::optional<double>(d) : std::nullopt;  // steering: as far as the motion walks
    }
    case Kind::Play:
      if (e.to_s < 0.0) return std::nullopt;
      return (e.to_s - e.from_s) / e.speed;
    case Kind::Condition:
    case Kind::StateMachine: return std::nullopt;
    case Kind::Sequence:
    case Kind::Loop:
      for (const events::Event& c : e.children) {
        const std::optional<double> l = lasts(c);
        d = d && l ? std::optional<double>(*d + *l) : std::nullopt;
      }
      if (e.kind == Kind::Loop) d = e.count > 0 && d ? std::optional<double>(*d * e.count) : std::nullopt;
      break;
    case Kind::Parallel:
    case Kind::Parameters:
      for (const events::Event& c : e.children) {
        const std::optional<double> l = lasts(c);
        d = d && l ? std::optional<double>(std::max(*d, *l)) : std::nullopt;
      }
      break;
  }
  if (e.kind != Kind::Parameters && e.kind != Kind::Path && d) d = *d / e.speed;
  if ((e.kind == Kind::Sequence || e.kind == Kind::Parallel || e.kind == Kind::Loop) && e.duration_s >= 0.0)
    d = d ? std::min(*d, e.duration_s) : e.duration_s;
  return d;
}

std::string what(const events::Event& e) {
  using events::Kind;
  switch (e.kind) {
    case Kind::Sequence:
    case Kind::Parallel:
    case Kind::Loop: {
      std::string s = e.kind == Kind::Loop ? (e.count > 0 ? fmt::format("{} times", e.count) : "for ever") : "";
      if (e.speed != 1.0) s += fmt::format("{}at {:g} times the speed", s.empty() ? "" : ", ", e.speed);
      if (e.duration_s >= 0.0) s += fmt::format("{}cut after {:g} s", s.empty() ? "" : ", ", e.duration_s);
      if (!e.character.empty()) s += fmt::format("{}on '{}'", s.empty() ? "" : ", ", e.character);
      return s;
    }
    case Kind::Parameters: {
      std::vector<std::string> p;
      for (const auto& [name, value] : e.parameters) p.push_back(name + "=" + value);
      return fmt::format("{}", fmt::join(p, ", "));
    }
    case Kind::Condition: return fmt::format("if {} is {}", e.parameter, fmt::join(e.equals, " or "));
    case Kind::StateMachine: return fmt::format("starting in '{}'", e.children[e.initial].name);
    case Kind::Wait: return fmt::format("{:g} s", e.duration_s);
    case Kind::Play:
      return fmt::format("{}{}, from {:g} s to {}{}{}{}", e.motion, e.animation.empty() ? "" : " '" + e.animation + "'",
                         e.from_s, e.to_s < 0.0 ? "its end" : fmt::format("{:g} s", e.to_s),
                         e.speed != 1.0 ? fmt::format(" at {:g} times its speed", e.speed) : "",
                         fmt::format(", blending in over {:g} s", e.blend_s), e.anchor ? "" : ", not anchored");
    case Kind::Path: {
      const events::PathCourse course(e);
      return fmt::format("{} points, {:.3g} m, {}{}", e.points.size(), course.length(),
                         e.pathSpeed_mps > 0.0 ? fmt::format("carried at {:g} m/s", e.pathSpeed_mps)
                                               : std::string("steering the character's own travel"),
                         e.turn ? fmt::format(", turning {:.0f} degrees", course.turn(course.length()) * 180.0 / M_PI)
                                : ", not turning");
    }
    case Kind::Wind:
      return fmt::format("{:g} {:g} {:g} m/s{}", e.velocity.x(), e.velocity.y(), e.velocity.z(),
                         e.duration_s < 0.0 ? " from then on" : fmt::format(" for {:g} s", e.duration_s));
  }
  return "";
}

void print(const events::Event& e, int depth, std::ostream& out, bool isState = false) {
  const std::optional<double> d = lasts(e);
  const std::string kind = isState ? "State" : events::kindName(e.kind);
  fmt::print(out, "{:{}}{}{}  (line {}){}{}\n", "", 2 * depth, kind, e.name.empty() ? "" : " '" + e.name + "'", e.where.line,
             what(e).empty() || isState ? "" : ": " + what(e), d ? fmt::format(", {:g} s", *d) : "");
  if (isState) {
    for (std::size_t k = 0; k < e.on.size(); ++k)
      fmt::print(out, "{:{}}on '{}' to state {}\n", "", 2 * depth + 2, e.on[k], e.to[k]);
    if (e.next >= 0) fmt::print(out, "{:{}}then state {}\n", "", 2 * depth + 2, e.next);
  }
  for (const events::Event& c : e.children) print(c, depth + 1, out, e.kind == events::Kind::StateMachine);
}

void inspectEvents(const std::string& path, std::ostream& out) {
  const events::Graph g = events::readGraph(path);
  const std::optional<double> d = lasts(g.root);
  fmt::print(out, "{}: EGML event graph{}, {} event{} at its top, {} motion{}{}\n", path,
             g.name.empty() ? "" : " '" + g.name + "'", g.root.children.size(), g.root.children.size() == 1 ? "" : "s",
             g.motions().size(), g.motions().size() == 1 ? "" : "s",
             d ? fmt::format(", {:g} s", *d) : " (how long depends on its motions, parameters or events)");
  for (const events::Event& c : g.root.children) print(c, 1, out);
}

const bool registered_cmd_inspect_events =
    registerInspector({".egml"}, "EGML event graphs: the events, their lines and durations", &inspectEvents);

}  // namespace
}  // namespace drape::cli
