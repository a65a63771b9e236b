// EGML scripts: the VRML97 reader's tree (vrml::Document) into a checked event graph.

#include "drape/events/graph.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <tuple>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drape/core/files.hpp"
#include "drape/formats/vrml_read.hpp"

namespace drape::events {
namespace {

namespace vrml = formats::vrml;

const std::map<std::string, Kind, std::less<>>& kinds() {
  static const std::map<std::string, Kind, std::less<>> table{
      {"Sequence", Kind::Sequence},     {"Parallel", Kind::Parallel},         {"Loop", Kind::Loop},
      {"Parameters", Kind::Parameters}, {"Condition", Kind::Condition},       {"StateMachine", Kind::StateMachine},
      {"Wait", Kind::Wait},             {"Play", Kind::Play},                 {"Wind", Kind::Wind},
      {"Path", Kind::Path}};
  return table;
}

class Builder {
 public:
  Builder(const vrml::Document& doc, std::string baseDir) : doc_(doc), baseDir_(std::move(baseDir)) {}

  Graph build() {
    Graph g;
    g.file = doc_.file;
    g.root.kind = Kind::Parallel;
    g.root.where = {doc_.file, 0, 0};
    int graphs = 0;
    for (const std::int32_t r : doc_.roots) {
      if (r < 0) continue;
      const vrml::Node& n = doc_.nodes[static_cast<std::size_t>(r)];
      if (n.type == "EventGraph") {
        if (++graphs > 1) throw fail(n, "a script holds one EventGraph (put the events of both in it)");
        g.name = text(n, "name");
        g.root.name = g.name;
        g.root.where = where(n);
        g.root.character = text(n, "character");
        for (const std::int32_t c : nodes(n, "children")) g.root.children.push_back(event(c));
      } else if (kinds().contains(n.type)) {
        g.root.children.push_back(event(r));
      }
    }
    if (g.root.children.empty())
      throw Error(fmt::format("{}: no events: an EGML script holds an EventGraph, or events (Sequence, Parallel, "
                              "Loop, Play, ...) at its top level (docs/EVENTS.md)",
                              doc_.file));
    return g;
  }

 private:
  [[nodiscard]] SourcePos where(const vrml::Node& n, const char* field = nullptr) const {
    int line = n.line;
    if (field != nullptr)
      if (const vrml::Field* f = n.field(field); f != nullptr && f->line > 0) line = f->line;
    return {n.file.empty() ? doc_.file : n.file, line, 0};
  }
  [[nodiscard]] Error fail(const vrml::Node& n, const std::string& what, const char* field = nullptr) const {
    return Error::at(where(n, field), fmt::format("{}: {}", n.type, what));
  }

  static double number(const vrml::Node& n, const char* name, double otherwise) {
    const vrml::Field* f = n.field(name);
    return f != nullptr && !f->numbers.empty() ? f->numbers[0] : otherwise;
  }
  static std::string text(const vrml::Node& n, const char* name) {
    const vrml::Field* f = n.field(name);
    return f != nullptr && !f->strings.empty() ? f->strings[0] : std::string();
  }
  static std::vector<std::string> texts(const vrml::Node& n, const char* name) {
    const vrml::Field* f = n.field(name);
    return f != nullptr ? f->strings : std::vector<std::string>{};
  }
  static std::vector<std::int32_t> nodes(const vrml::Node& n, const char* name) {
    const vrml::Field* f = n.field(name);
    std::vector<std::int32_t> out;
    if (f != nullptr)
      for (const std::int32_t i : f->nodes)
        if (i >= 0) out.push_back(i);
    return out;
  }

  /// A duration field: >= 0, or -1 (none).
  double duration(const vrml::Node& n, const char* name, double otherwise) const {
    const double d = number(n, name, otherwise);
    if (!(d >= 0.0 || d == -1.0) || !std::isfinite(d))
      throw fail(n, fmt::format("{} {} must be >= 0 seconds, or -1", name, d), name);
    return d;
  }
  double positive(const vrml::Node& n, const char* name) const {
    const double v = number(n, name, 1.0);
    if (!(v > 0.0) || !std::isfinite(v)) throw fail(n, fmt::format("{} {} must be > 0", name, v), name);
    return v;
  }

  Event event(std::int32_t index) {
    const vrml::Node& n = doc_.nodes[static_cast<std::size_t>(index)];
    const auto kind = kinds().find(n.type);
    if (kind == kinds().end())
      throw Error::at(where(n), fmt::format("{} is not an event (an EGML event is one of: {})", n.type,
                                            fmt::join(names(), ", ")));
    if (std::find(open_.begin(), open_.end(), index) != open_.end())
      throw fail(n, "contains itself (through USE)");
    open_.push_back(index);
    Event e;
    e.kind = kind->second;
    e.name = text(n, "name");
    e.where = where(n);
    switch (e.kind) {
      case Kind::Sequence:
      case Kind::Parallel:
      case Kind::Loop:
        e.speed = positive(n, "speed");
        e.character = text(n, "character");
        e.duration_s = duration(n, "duration", -1.0);
        if (e.kind == Kind::Loop) {
          e.count = static_cast<int>(number(n, "count", 0));
          if (e.count < 0) throw fail(n, fmt::format("count {} must be >= 0 (0: for ever)", e.count), "count");
        }
        for (const std::int32_t c : nodes(n, "children")) e.children.push_back(event(c));
        if (e.kind == Kind::Loop && e.children.empty()) throw fail(n, "repeats no events (its children are empty)");
        break;
      case Kind::Parameters: {
        const std::vector<std::string> names = texts(n, "names"), values = texts(n, "values");
        if (names.size() != values.size())
          throw fail(n, fmt::format("{} names and {} values: one value per name", names.size(), values.size()), "values");
        for (std::size_t k = 0; k < names.size(); ++k) e.parameters.emplace_back(names[k], values[k]);
        for (const std::int32_t c : nodes(n, "children")) e.children.push_back(event(c));
        break;
      }
      case Kind::Condition: {
        e.parameter = text(n, "parameter");
        if (e.parameter.empty()) throw fail(n, "names no parameter to test", "parameter");
        e.equals = texts(n, "equals");
        for (const char* branch : {"then", "otherwise"}) {
          const std::vector<std::int32_t> b = nodes(n, branch);
          if (b.empty()) {
            Event nothing;
            nothing.kind = Kind::Wait;
            nothing.duration_s = 0.0;
            nothing.where = e.where;
            e.children.push_back(nothing);
          } else {
            e.children.push_back(event(b.front()));
          }
        }
        break;
      }
      case Kind::StateMachine:
        machine(n, e);
        break;
      case Kind::Wait:
        e.duration_s = duration(n, "duration", 1.0);
        if (e.duration_s < 0) throw fail(n, "duration -1 would wait for ever: give the seconds to wait", "duration");
        break;
      case Kind::Play:
        play(n, e);
        break;
      case Kind::Path:
        path(n, e);
        break;
      case Kind::Wind: {
        const vrml::Field* v = n.field("velocity");
        if (v != nullptr && v->numbers.size() == 3) e.velocity = Vec3(v->numbers[0], v->numbers[1], v->numbers[2]);
        if (!e.velocity.allFinite()) throw fail(n, "velocity must be finite", "velocity");
        e.duration_s = duration(n, "duration", -1.0);
        break;
      }
    }
    open_.pop_back();
    return e;
  }

  void machine(const vrml::Node& n, Event& e) {
    std::vector<const vrml::Node*> states;
    for (const std::int32_t s : nodes(n, "states")) {
      const vrml::Node& state = doc_.nodes[static_cast<std::size_t>(s)];
      if (state.type != "State") throw fail(n, fmt::format("its states are State nodes, not {}", state.type), "states");
      states.push_back(&state);
    }
    if (states.empty()) throw fail(n, "has no states", "states");
    std::vector<std::string> names;
    for (const vrml::Node* s : states) {
      const std::string name = text(*s, "name").empty() ? s->def : text(*s, "name");
      if (name.empty()) throw Error::at(where(*s), "State: a state needs a name (its transitions name it)");
      if (std::find(names.begin(), names.end(), name) != names.end())
        throw Error::at(where(*s, "name"), fmt::format("State: '{}' names two states of one machine", name));
      names.push_back(name);
    }
    const auto find = [&](const vrml::Node& at, const std::string& name, const char* field) {
      const auto it = std::find(names.begin(), names.end(), name);
      if (it == names.end())
        throw Error::at(where(at, field), fmt::format("{}: '{}' is no state of the machine (it has: {})", at.type, name,
                                                      fmt::join(names, ", ")));
      return static_cast<std::size_t>(it - names.begin());
    };
    const std::string initial = text(n, "initial");
    e.initial = initial.empty() ? 0 : find(n, initial, "initial");
    for (std::size_t k = 0; k < states.size(); ++k) {
      const vrml::Node& s = *states[k];
      Event state;
      state.kind = Kind::Parallel;
      state.name = names[k];
      state.where = where(s);
      for (const std::int32_t c : nodes(s, "children")) state.children.push_back(event(c));
      state.on = texts(s, "on");
      const std::vector<std::string> to = texts(s, "to");
      if (to.size() != state.on.size())
        throw Error::at(where(s, "to"), fmt::format("State: {} events in 'on' and {} states in 'to': one state per event",
                                                    state.on.size(), to.size()));
      for (const std::string& t : to) state.to.push_back(find(s, t, "to"));
      const std::string next = text(s, "next");
      state.next = next.empty() ? -1 : static_cast<long>(find(s, next, "next"));
      e.children.push_back(std::move(state));
    }
  }

  void path(const vrml::Node& n, Event& e) {
    e.character = text(n, "character");
    const vrml::Field* p = n.field("points");
    if (p != nullptr)
      for (std::size_t k = 0; k + 2 < p->numbers.size(); k += 3)
        e.points.emplace_back(p->numbers[k], p->numbers[k + 1], p->numbers[k + 2]);
    if (e.points.size() < 2) throw fail(n, fmt::format("{} points: a path goes through 2 or more", e.points.size()), "points");
    for (std::size_t k = 0; k < e.points.size(); ++k) {
      if (!e.points[k].allFinite()) throw fail(n, fmt::format("point {} is not finite", k), "points");
      if (k > 0) {
        const Vec3 d = e.points[k] - e.points[k - 1];
        if (std::hypot(d.x(), d.z()) < 1e-6)
          throw fail(n, fmt::format("points {} and {} are one place on the floor: a path goes somewhere", k - 1, k),
                     "points");
      }
    }
    e.pathSpeed_mps = number(n, "speed", 0.0);
    e.ease_s = number(n, "ease", 0.5);
    e.corner_m = number(n, "corner", 0.5);
    e.turn = number(n, "turn", 1.0) != 0.0;
    if (!(e.pathSpeed_mps >= 0.0) || !std::isfinite(e.pathSpeed_mps))
      throw fail(n, fmt::format("speed {} must be >= 0 m/s (0: as the character's motion travels)", e.pathSpeed_mps),
                 "speed");
    if (!(e.ease_s >= 0.0) || !std::isfinite(e.ease_s)) throw fail(n, fmt::format("ease {} must be >= 0 s", e.ease_s), "ease");
    if (!(e.corner_m >= 0.0) || !std::isfinite(e.corner_m))
      throw fail(n, fmt::format("corner {} must be >= 0 m", e.corner_m), "corner");
  }

  void play(const vrml::Node& n, Event& e) {
    e.character = text(n, "character");
    e.animation = text(n, "animation");
    e.from_s = number(n, "from", 0.0);
    e.to_s = number(n, "to", -1.0);
    e.speed = positive(n, "speed");
    e.blend_s = number(n, "blend", 0.3);
    e.anchor = number(n, "anchor", 1.0) != 0.0;
    if (!(e.from_s >= 0.0) || !std::isfinite(e.from_s)) throw fail(n, fmt::format("from {} must be >= 0 s", e.from_s), "from");
    if (!(e.to_s == -1.0 || e.to_s > e.from_s) || !std::isfinite(e.to_s))
      throw fail(n, fmt::format("to {} must be after from {} (or -1: the motion's end)", e.to_s, e.from_s), "to");
    if (!(e.blend_s >= 0.0) || !std::isfinite(e.blend_s)) throw fail(n, fmt::format("blend {} must be >= 0 s", e.blend_s), "blend");
    const std::vector<std::string> urls = texts(n, "motion");
    if (urls.empty()) throw fail(n, "names no motion to play (motion \"walk.bvh\")", "motion");
    for (const std::string& url : urls) {
      std::filesystem::path p(url);
      if (p.is_relative()) p = std::filesystem::path(baseDir_) / p;
      std::error_code ec;
      if (std::filesystem::is_regular_file(p, ec)) {
        e.motion = p.lexically_normal().string();
        break;
      }
    }
    if (e.motion.empty())
      throw fail(n, fmt::format("motion {} is not there (looked in {})", fmt::join(urls, ", "), baseDir_.empty() ? "." : baseDir_),
                 "motion");
    const std::string map = text(n, "jointMap");
    if (!map.empty()) {
      std::filesystem::path p(map);
      if (p.is_relative()) p = std::filesystem::path(baseDir_) / p;
      e.jointMap = p.lexically_normal().string();
    }
  }

  static std::vector<std::string> names() {
    std::vector<std::string> out{"EventGraph"};
    for (const auto& [name, kind] : kinds()) out.push_back(name);
    return out;
  }

  const vrml::Document& doc_;
  std::string baseDir_;
  std::vector<std::int32_t> open_;  ///< the events being built, outermost first
};

void collect(const Event& e, std::vector<std::tuple<std::string, std::string, std::string>>& motions,
             std::vector<std::string>& characters) {
  if (e.kind == Kind::Play) {
    const auto key = std::make_tuple(e.motion, e.animation, e.jointMap);
    if (std::find(motions.begin(), motions.end(), key) == motions.end()) motions.push_back(key);
  }
  if (!e.character.empty() && std::find(characters.begin(), characters.end(), e.character) == characters.end())
    characters.push_back(e.character);
  for (const Event& c : e.children) collect(c, motions, characters);
}

}  // namespace

const char* kindName(Kind kind) {
  switch (kind) {
    case Kind::Sequence: return "Sequence";
    case Kind::Parallel: return "Parallel";
    case Kind::Loop: return "Loop";
    case Kind::Parameters: return "Parameters";
    case Kind::Condition: return "Condition";
    case Kind::StateMachine: return "StateMachine";
    case Kind::Wait: return "Wait";
    case Kind::Play: return "Play";
    case Kind::Wind: return "Wind";
    case Kind::Path: return "Path";
  }
  return "?";
}

std::vector<std::tuple<std::string, std::string, std::string>> Graph::motions() const {
  std::vector<std::tuple<std::string, std::string, std::string>> m;
  std::vector<std::string> c;
  collect(root, m, c);
  return m;
}

std::vector<std::string> Graph::characters() const {
  std::vector<std::tuple<std::string, std::string, std::string>> m;
  std::vector<std::string> c;
  collect(root, m, c);
  return c;
}

Graph readGraph(const std::string& path) {
  const vrml::Document doc = vrml::readFile(path);
  return Builder(doc, std::filesystem::path(path).parent_path().string()).build();
}

Graph parseGraph(std::string_view text, const std::string& name, const std::string& baseDir) {
  const vrml::Document doc = vrml::readText(text, name, baseDir);
  return Builder(doc, baseDir).build();
}

bool isEgmlPath(const std::string& path) { return lowerExtension(path) == ".egml"; }

}  // namespace drape::events
