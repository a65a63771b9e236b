#pragma once
// The studio's frames (docs/STUDIO.md): what the roles send each other, as plain values, and
// their encoding on the wire (FlatBuffers, studio_frames.fbs). Every take on a stream is
//
//   PoseStart  PoseFrame 0  PoseFrame 1 ...  End        (an anim-server's poses)
//   ClothStart ClothFrame 0 (one per garment) ...  End  (a cloth-server's garments)
//
// and every message names its source (the broadcaster) and its take. decode() verifies the
// bytes before it reads them: a truncated, corrupted or foreign message is a drape::Error
// that says what is wrong, never a read out of bounds.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/core/timecode.hpp"

namespace drape::studio {

/// The wire format's major version: a reader refuses messages of another.
inline constexpr std::uint16_t kWireVersion = 1;

struct PoseStart {
  std::string character;            ///< the avatar's name
  std::vector<std::string> joints;  ///< the avatar's joints, in every PoseFrame's order
  std::vector<int> driving;         ///< per joint, its driving motion joint (-1: none)
  TimeCode start;                   ///< time code of motion frame 0 (and the rate)
  std::int64_t frames = 0;          ///< frames the take holds; 0 while not known (live)
};

struct PoseFrame {
  std::int64_t frame = 0;                ///< motion frame, from 0
  std::vector<RigidTransform> joints;    ///< world transforms, in PoseStart's joint order
  std::optional<Vec3> wind;              ///< the wind an event graph set (none: the scene's)
};

struct GarmentInfo {
  std::string name;
  std::uint32_t vertices = 0;
};

struct ClothStart {
  std::string poses;                  ///< the pose stream's source
  std::string poseTake;               ///< the pose take this cloth take simulates
  std::string character;
  TimeCode start;                     ///< time code of cloth frame 0 (and the rate)
  double leadIn_s = 0.0;              ///< the blend from the rest pose before motion frame 0
  std::vector<GarmentInfo> garments;  ///< ClothFrame::garment indexes this list
};

struct ClothFrame {
  std::int64_t frame = 0;    ///< cloth frame, from 0 (the state before the first step)
  std::uint32_t garment = 0;
  std::vector<Vec3> positions;           ///< m
  std::vector<std::uint8_t> states;      ///< per vertex, as render/frame.hpp's vertex_state
};

struct End {
  std::int64_t frames = 0;  ///< frames sent: motion frames, or cloth frames after frame 0
  std::string stats;        ///< a cloth take's stats.json
  std::string error;        ///< why the take ended early, "" when it ran to its end
  int exitCode = 0;         ///< drape's exit code for that error
};

/// To an anim-server playing an event graph (drape inject): a graph to start at once (EGML
/// text, its relative motion paths found in `baseDir` on the anim-server's machine), an
/// event for its state machines, or both.
struct Inject {
  std::string graph;
  std::string baseDir;
  std::string event;
};

struct InjectReply {
  bool accepted = false;
  std::string message;
};

using Payload = std::variant<PoseStart, PoseFrame, ClothStart, ClothFrame, End, Inject, InjectReply>;

struct Message {
  std::string source;  ///< the broadcaster
  std::string take;
  Payload payload;
};

/// How a ClothFrame's positions travel: doubles (the simulation's own values: a player's
/// recording is byte for byte what drape run writes) or floats (half the bytes; what PC2
/// caches and renderers keep anyway).
enum class Precision : std::uint8_t { Double, Float };

[[nodiscard]] std::vector<std::uint8_t> encode(const Message& message, Precision precision = Precision::Double);

/// The message in `bytes`. Throws drape::Error (BadInput) naming what is wrong: not a drape
/// studio message, another wire version, a table that fails verification, or contents that
/// contradict themselves (a transform that is not finite, positions not a multiple of three).
[[nodiscard]] Message decode(std::span<const std::uint8_t> bytes);

/// "PoseFrame 12" and the like, for logs.
[[nodiscard]] std::string describe(const Payload& payload);

}  // namespace drape::studio
