#pragma once
// The manifest of a run's output directory (DIR/manifest.json): what `drape run` wrote and
// what players, renderers and exporters read back. Every animated mesh is a topology file
// (OBJ, its frame-0 positions) plus a PC2 point cache of world positions in metres, one
// sample per frame, Y up. Garments, avatar segments and the avatar's skinned body are listed
// alike; `role` tells a renderer how to draw them.
//
// In a run of several characters, each segment, skin and garment names its character.
//
// A garment may also have a state cache (formats/state_cache.hpp): per vertex and frame,
// its collision state and whether it is pinned or bound, for the overlays.
//
//   {"format": "drape-run", "version": 1, "frame_rate": 30, "frames": 90, "start_frame": 0,
//    "meshes": [{"name": "dress", "role": "garment", "topology": "garment.obj",
//                "cache": "garment.pc2", "states": "garment.states"}, ...]}

#include <optional>
#include <string>
#include <string_view>

#include "drape/core/math.hpp"
#include <vector>

namespace drape::formats {

struct RunMesh {
  std::string name;
  /// "garment", "segment" (an avatar body part), "skin" (the avatar's smooth body) or
  /// "drawn" (skinned meshes drawn with it, never collided with: hair, eyes)
  std::string role;
  std::string topology;  ///< OBJ file, relative to the run directory
  std::string cache;     ///< PC2 file, relative to the run directory
  std::string states;    ///< state cache, relative to the run directory; "": none (optional key)
  /// The character a segment or skin belongs to, or that wears a garment, in a run of
  /// several characters; "": the run's only one (optional key).
  std::string character;
  /// The garment's colour as its scene gives it (sRGB, 0 to 1); none: the players' own
  /// (optional key `colour`, three numbers).
  std::optional<Vec3> colour;
};

struct RunManifest {
  double frameRate = 30.0;   ///< frames per second of the caches
  long frames = 0;           ///< frames in every cache
  long startFrame = 0;       ///< time code frame number of the first sample
  std::vector<RunMesh> meshes;
};

/// Writes DIR/manifest.json.
void writeRunManifest(const std::string& directory, const RunManifest& manifest);
/// Parses manifest text read from `name` (used in messages); throws drape::Error
/// "name:line:column: ..." on bad JSON, "name: ..." naming the key on anything missing or
/// of the wrong type.
[[nodiscard]] RunManifest parseRunManifest(std::string_view text, const std::string& name);
/// Reads DIR/manifest.json; throws drape::Error naming the file and the key on anything
/// missing or malformed (including a file that is not a drape run directory).
[[nodiscard]] RunManifest readRunManifest(const std::string& directory);

}  // namespace drape::formats
