#pragma once
// EGML event graphs (the paper's section 4; docs/EVENTS.md): scripted motion as a tree of
// events in VRML97 syntax, their node types declared by drape's prelude, so that the scene
// reader parses a script (pre-scan with file:line:column errors, Coin3D in a child process).
//
//   EventGraph { children [
//     Sequence { children [
//       Play { motion "walk.bvh" to 2.5 }
//       Play { motion "kick.bvh" blend 0.4 }
//       Wind { velocity 3 0 0 duration 2 }
//     ] }
//   ] }
//
// This is the graph as read and checked: plain values, each event with the source line it
// was written on. runtime.hpp runs it.

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "drape/core/error.hpp"
#include "drape/core/math.hpp"

namespace drape::events {

enum class Kind {
  Sequence,      ///< children one after another
  Parallel,      ///< children side by side (an EventGraph's root is one)
  Loop,          ///< children as a sequence, count times (0: for ever)
  Parameters,    ///< children side by side, with parameters set for them
  Condition,     ///< one of two events, by a parameter's value
  StateMachine,  ///< states and the transitions between them
  Wait,          ///< nothing, for a while
  Play,          ///< a motion played on a character
  Wind,          ///< the wind
  Path,          ///< the character's root moved along a path
};

[[nodiscard]] const char* kindName(Kind kind);

struct Event {
  Kind kind = Kind::Parallel;
  std::string name;
  SourcePos where;

  // Control events (Sequence, Parallel, Loop): their subtree's time rate (multiplied down
  // the graph), the character their leaves play on unless they name one, a cut after
  // `duration` seconds of their own time (< 0: none), and Loop's repetitions.
  double speed = 1.0;
  std::string character;
  double duration_s = -1.0;
  int count = 0;
  std::vector<Event> children;  ///< Condition: then, otherwise (Kind::Wait of 0 s where absent)

  // Parameters: name -> value for the subtree. Condition: the parameter tested.
  std::vector<std::pair<std::string, std::string>> parameters;
  std::string parameter;
  std::vector<std::string> equals;

  // StateMachine: its states are its children (Kind::Parallel, named), starting at `initial`.
  // A state: on event on[i] go to state to[i] (indices into the machine's children); when its
  // events end, go to `next` (-1: the machine ends).
  std::size_t initial = 0;
  std::vector<std::string> on;
  std::vector<std::size_t> to;
  long next = -1;

  // Play: the motion file (resolved against the script's directory), which of its
  // animations, the joint map, the span played (s of the motion; to < 0: its end), the blend
  // in (s) and whether its path goes on from where the character stands.
  std::string motion, animation, jointMap;
  double from_s = 0.0, to_s = -1.0, blend_s = 0.3;
  bool anchor = true;

  // Wind: its velocity (m/s), for `duration` (< 0: from now on).
  Vec3 velocity = Vec3::Zero();

  // Path: the points the root goes through (m, the scene's axes; only their differences
  // count: the path starts where the character stands), the speed along it (m/s; 0: as
  // fast as the character's own motion travels, which the path steers), the ease in and out
  // of that speed (s), the length over which a corner turns the character (m), and whether
  // it turns at all.
  std::vector<Vec3> points;
  double pathSpeed_mps = 0.0, ease_s = 0.5, corner_m = 0.5;
  bool turn = true;
};

struct Graph {
  std::string file;       ///< where it was read from ("" for text)
  std::string name;
  Event root;             ///< a Parallel of the script's events
  /// Every Play's (motion, animation, joint map), once each, in the order first met.
  [[nodiscard]] std::vector<std::tuple<std::string, std::string, std::string>> motions() const;
  /// Every character a Play names (the graph's, a control event's, its own), once each.
  [[nodiscard]] std::vector<std::string> characters() const;
};

/// Reads an EGML script. Throws drape::Error (BadInput) with "file:line: what" for an event
/// it cannot use (a field out of range, a motion file that is not there, a state that names
/// no state of its machine), and the reader's own messages for what is not VRML97.
[[nodiscard]] Graph readGraph(const std::string& path);

/// The same from text that came from elsewhere (a graph injected into an anim-server):
/// `name` stands for the file in messages, relative motion files are found in `baseDir`.
[[nodiscard]] Graph parseGraph(std::string_view text, const std::string& name, const std::string& baseDir);

/// Whether `path` names an EGML script (.egml).
[[nodiscard]] bool isEgmlPath(const std::string& path);

}  // namespace drape::events
