#pragma once
// What a player or renderer draws, as plain data. A run (replayed from a directory or
// simulated live) is a list of meshes that stay the same ("what it is": MeshInfo) and a
// stream of frames ("how it moves": Frame, one per simulation output frame).
//
// A live simulation drives the player through a FrameSource (see CallbackSource); a
// finished run directory is read by RunReplay (run_replay.hpp).

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/core/timecode.hpp"
#include "drape/mesh/trimesh.hpp"

namespace drape::render {

/// How a mesh is drawn: garments in cloth colours with collision-state colouring and
/// markers, segments (the avatar's rigid body parts, what the cloth collides with) in the
/// body colour with offset surfaces, the skin (the avatar's skinned body) in the body
/// colour instead of the segments when a run has one, and the avatar's drawn meshes (hair,
/// eyes: skinned with the body, never collided with) in a darker clay beside the skin.
enum class MeshRole : std::uint8_t { Garment, Segment, Skin, Drawn };

/// Parses "garment" / "segment" / "skin" / "drawn" (the run manifest's role names); throws
/// drape::Error otherwise.
[[nodiscard]] MeshRole parseMeshRole(const std::string& role);

/// The optional per-vertex state channel (one byte per vertex, per frame). The collision
/// stage fills it; the overlay toggles colour and mark vertices with it.
namespace vertex_state {
inline constexpr std::uint8_t kCollisionMask = 0x03;  ///< low two bits: the collision state
inline constexpr std::uint8_t kOutside = 0;           ///< outside every body volume (OutsideVol)
inline constexpr std::uint8_t kInsideVolume = 1;      ///< inside a part's volume, above T2 (InsideVol)
inline constexpr std::uint8_t kOnSurface = 2;         ///< held on the collision surface T2 (OnSurf)
inline constexpr std::uint8_t kPenaltyZone = 3;       ///< below T1: a penalty force pushes it out
inline constexpr std::uint8_t kPinned = 0x04;         ///< fixed by a pin (follows a transform)
inline constexpr std::uint8_t kBound = 0x08;          ///< bound to a body part by a constraint mask
}  // namespace vertex_state

/// A mesh of the run: constant from frame to frame.
struct MeshInfo {
  std::string name;
  MeshRole role = MeshRole::Garment;
  std::size_t vertexCount = 0;
  std::vector<mesh::Triangle> triangles;  ///< indices into the frame's positions
  /// The character a segment or skin belongs to, or that wears a garment, in a run of
  /// several; "": the only one.
  std::string character{};
  /// A garment's colour as its scene gives it (sRGB, 0 to 1); none: the renderer's cloth red.
  std::optional<Vec3> colour{};
};

/// Whether the run has an avatar's skinned body (drawn instead of the segments).
[[nodiscard]] bool hasSkin(const std::vector<MeshInfo>& meshes);
/// Whether `character`'s skinned body is in the run (drawn instead of its segments).
[[nodiscard]] bool hasSkin(const std::vector<MeshInfo>& meshes, const std::string& character);

/// Milliseconds one simulation stage took (forces, integrate, collide, ...).
struct StageTime {
  std::string stage;
  double ms = 0.0;
};

/// One frame: world positions (m, Y up) of every mesh, in MeshInfo order.
struct Frame {
  std::int64_t index = 0;                         ///< 0-based sample number within the run
  TimeCode time;                                  ///< studio time code of the sample
  std::vector<std::vector<Vec3>> positions;       ///< per mesh, MeshInfo::vertexCount entries
  std::vector<std::vector<std::uint8_t>> states;  ///< per mesh: vertex_state bits, or empty
  std::vector<StageTime> stages;                  ///< ms per stage for this frame (may be empty)
};

/// A stream of frames for the player. Replays allow any index; a live source only ever
/// sees increasing indices (0, 1, 2, ...), one call per frame it should advance.
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  [[nodiscard]] virtual const std::vector<MeshInfo>& meshes() const = 0;
  [[nodiscard]] virtual double frameRate() const = 0;
  /// Number of frames, or nullopt for a live source that runs until it returns false.
  [[nodiscard]] virtual std::optional<std::int64_t> frameCount() const = 0;
  /// Fills `out` with frame `index`; returns false when there is no such frame (the end).
  virtual bool read(std::int64_t index, Frame& out) = 0;
  /// Whether read(index) would answer at once. A live source whose next frame has not come
  /// says false, and a player draws the frame it has (turning, zooming, closing) and asks
  /// again.
  [[nodiscard]] virtual bool ready(std::int64_t /*index*/) { return true; }
};

/// A live source: `advance` fills the next frame (positions, states, stages, time) and
/// returns false when the simulation is finished. This is how `drape play SCENE` plugs the
/// simulation loop into the player.
class CallbackSource final : public FrameSource {
 public:
  using Advance = std::function<bool(Frame& out)>;
  /// Whether the next advance would answer at once (none: always).
  using Ready = std::function<bool(std::int64_t index)>;
  CallbackSource(std::vector<MeshInfo> meshes, double frameRate, Advance advance, Ready ready = {})
      : meshes_(std::move(meshes)), frameRate_(frameRate), advance_(std::move(advance)), ready_(std::move(ready)) {}
  [[nodiscard]] const std::vector<MeshInfo>& meshes() const override { return meshes_; }
  [[nodiscard]] double frameRate() const override { return frameRate_; }
  [[nodiscard]] std::optional<std::int64_t> frameCount() const override { return std::nullopt; }
  bool read(std::int64_t index, Frame& out) override {
    out.index = index;
    return advance_(out);
  }
  [[nodiscard]] bool ready(std::int64_t index) override { return !ready_ || ready_(index); }

 private:
  std::vector<MeshInfo> meshes_;
  double frameRate_;
  Advance advance_;
  Ready ready_;
};

/// Bounds of every position of a frame (m).
[[nodiscard]] Aabb frameBounds(const Frame& frame);

}  // namespace drape::render
