#pragma once
// One character's world, frame by frame: the core loop of the paper's cloth server
// (section 4). Poses come from a retargeted motion (micro-interpolated per substep, section
// 4.3.1); every collidable body part gets one distance field, built once (section 4.3.2);
// every garment steps its cloth against those fields (section 4.3.3), with its constraint
// mask bound to the nearest parts (section 4.1).
//
//   sim time 0 .. leadIn      the avatar blends from its rest pose (which the garments are
//                             modelled on) into the motion's first frame, so the cloth is
//                             not hit by a jump
//   sim time leadIn ..        the motion plays; its last frame holds after the end
//
// Used alike by `drape run`, the benchmarks and (later) the cloth server role.

#include <algorithm>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "drape/cloth/field_collider.hpp"
#include "drape/cloth/material.hpp"
#include "drape/cloth/layer_collider.hpp"
#include "drape/cloth/solver.hpp"
#include "drape/field/distance_field.hpp"
#include "drape/mesh/trimesh.hpp"
#include "drape/motion/animation.hpp"
#include "drape/scene/avatar.hpp"
#include "drape/sim/keep_apart.hpp"

namespace drape::sim {

/// A garment as it enters the simulation: plain data from a scene file or the command line.
struct GarmentSpec {
  std::string name;
  mesh::TriMesh mesh;                       ///< m, world, on the avatar's rest pose
  cloth::Material material;
  std::vector<std::uint32_t> pinned;        ///< vertices pinned in place in the world
  std::vector<std::uint32_t> bound;         ///< constraint-mask vertices: follow the nearest part
  double bindThreshold_m = 0.03;            ///< farthest a bound vertex may be from its part
  std::vector<std::string> collidesWith;    ///< body segment names
  /// Of collidesWith, the parts the triangles' centroids collide with too (face samples).
  std::vector<std::string> faceSamplesWith;
  std::vector<cloth::Stitch> stitches;      ///< vertices sewn together (ClothSolver::setStitches)
  cloth::OffsetSurfaces offsets;            ///< used when offsetsGiven, else from the voxel size
  bool offsetsGiven = false;
  int collisionEvery = 1;                   ///< collision tests every k substeps
  /// How far apart its own layers keep (cloth::LayerCollider, tested with the body); 0: none.
  double selfCollision_m = 0.0;
  /// The garments of the same world it is worn over, by name: kept overGap_m above them,
  /// one way (cloth::LayerCollider), and stepped after them each frame.
  std::vector<std::string> over;
  double overGap_m = 0.004;
  /// For display only: the scene's colour of the cloth (sRGB, 0 to 1), or none.
  std::optional<Vec3> colour;
};

struct WorldSettings {
  cloth::StepSettings step;
  double voxel_m = 0.005;                   ///< distance-field voxel size
  field::FieldMethod fieldMethod = field::FieldMethod::Dvdp;
  double leadIn_s = 1.0;                    ///< rest pose -> first motion frame blend
  /// Parts the motion is corrected to keep out of the collidable parts (sim/keep_apart.hpp).
  KeepApartSettings keepApart;
};

/// Joint world transforms of an animated avatar at any simulation time (with the lead-in),
/// cached for the two most recent times so that every part and fixture asking for the
/// start and end of a substep costs one evaluation each.
class AvatarPoses {
 public:
  AvatarPoses(const scene::Avatar& avatar, const motion::AvatarAnimation* animation, double leadIn_s);
  /// One joint's world transform at time t. The last two times asked for are cached joint by
  /// joint: a substep evaluates only the joints its colliders and fixtures follow.
  [[nodiscard]] const RigidTransform& jointAt(double t_s, int joint) const;
  /// All joints at time t into out (size = joint count).
  void evaluate(double t_s, std::span<RigidTransform> out) const;
  [[nodiscard]] double leadIn_s() const { return leadIn_s_; }
  /// Plays `animation` from now on (same avatar, same joint count); forgets the cached poses.
  void useAnimation(const motion::AvatarAnimation* animation);
  /// Simulation time at which the motion ends (its last frame).
  [[nodiscard]] double end_s() const;

 private:
  /// Where time t falls: the lead-in's eased blend u from the rest pose, or frame f and the
  /// fraction s towards f + 1.
  struct When {
    bool leadIn = false;
    double u = 0.0;
    std::size_t f = 0;
    double s = 0.0;
  };
  [[nodiscard]] When when(double t_s) const;
  [[nodiscard]] RigidTransform joint(const When& w, std::size_t j) const;

  const scene::Avatar& avatar_;
  const motion::AvatarAnimation* animation_;
  double leadIn_s_;
  mutable double cacheTime_[2];
  mutable When cacheWhen_[2];
  mutable std::vector<RigidTransform> cache_[2];
  mutable std::vector<std::uint8_t> cached_[2];  ///< per joint: cache_ holds it for cacheTime_
  mutable int next_ = 0;
};

struct PartField {
  std::string segment;
  int joint = -1;
  field::DistanceField field;
};

/// The distance fields a world builds for `garments` on `avatar`: one per segment any
/// garment collides with, in the order the garments first name them (CharacterWorld's
/// fields(), for a player that draws the body as the world's outputs do). Throws
/// drape::Error on a segment the avatar does not have.
[[nodiscard]] std::vector<PartField> buildPartFields(const scene::Avatar& avatar, const std::vector<GarmentSpec>& garments,
                                                     const WorldSettings& settings);
/// The garments' least T0, as CharacterWorld gives them their offsets: how far the drawn
/// skin may stand out of the body parts (BodySkin).
[[nodiscard]] double leastT0(const std::vector<GarmentSpec>& garments, const WorldSettings& settings);
/// settings.keepApart with its margin as a world keeps parts apart for `garments`: the one
/// given, or twice the garments' largest T2 (room for cloth on both parts' collision surfaces).
[[nodiscard]] KeepApartSettings keepApartSettings(const std::vector<GarmentSpec>& garments, const WorldSettings& settings);

/// Steps `count` solvers to `frame` in parallel (TBB); per solver, whether it stayed stable.
/// With `layers` (one per solver, sim/garment_layers.hpp), layer by layer from 0: a garment is
/// worn over garments of lower layers, whose frame its layer collider reads once they have
/// stepped it. The solvers of one layer must share nothing that changes (each garment has
/// its own poses and colliders).
std::vector<std::uint8_t> stepInParallel(std::size_t count, long frame,
                                         const std::function<cloth::ClothSolver&(std::size_t)>& solver,
                                         std::span<const int> layers = {});

/// Logs what a garment's solver did to get through `frame`: an info line when the frame
/// was computed again with more substeps, a warning when strain limiting came on in it.
void logFrameRecovery(const cloth::ClothSolver& solver, const std::string& garment, long frame);

/// What settling the garments before frame 0 did (CharacterWorld::settle).
struct SettleReport {
  long frames = 0;              ///< frames stepped at the rest pose, numbered up to 0
  double seconds = 0.0;         ///< their length: simulation time -seconds .. 0
  double wall_s = 0.0;          ///< what they took
  std::size_t pairsEased = 0;   ///< (vertex, part) pairs being eased out onto T2 when it began
  std::size_t pairsTimedOut = 0;  ///< of those, held below T2 by the garment: they collide as any other
  std::size_t pairsLeft = 0;    ///< of those, still being eased at frame 0 (the settling's cap came first)

  /// Another world's settling with this one's: the longest, the pairs of both.
  SettleReport& operator+=(const SettleReport& other) {
    frames = std::max(frames, other.frames);
    seconds = std::max(seconds, other.seconds);
    wall_s += other.wall_s;
    pairsEased += other.pairsEased;
    pairsTimedOut += other.pairsTimedOut;
    pairsLeft += other.pairsLeft;
    return *this;
  }
};

/// Another character of the scene, whose body a world's garments collide with too (two
/// characters that touch): its avatar, the motion it plays (as its own world plays it, kept
/// apart where it keeps parts apart; null: at rest) with the same lead-in, and its part
/// fields, the parts its own garments collide with. Its parts are named "NAME/PART".
struct Guest {
  std::string name;
  const scene::Avatar* avatar = nullptr;
  const motion::AvatarAnimation* animation = nullptr;
  std::shared_ptr<const std::vector<PartField>> fields;
};

class CharacterWorld {
 public:
  /// Builds the part fields, binds every garment's mask and establishes the initial
  /// collision states. `animation` may be null (the avatar stands in its rest pose).
  /// `fields`, when given, are the part fields buildPartFields built for the same avatar,
  /// garments and settings (a cloth-server builds them once for all its takes). Each
  /// garment also collides with the parts of `guests` (which, and what they point to, must
  /// outlive the world) whose fields keep normals out to its T3; masks bind to the avatar's
  /// own parts only. Throws drape::Error on unknown segment names or unbindable mask vertices.
  CharacterWorld(const scene::Avatar& avatar, const motion::AvatarAnimation* animation,
                 std::vector<GarmentSpec> garments, const WorldSettings& settings,
                 std::shared_ptr<const std::vector<PartField>> fields = nullptr, std::vector<Guest> guests = {});
  ~CharacterWorld();
  CharacterWorld(const CharacterWorld&) = delete;
  CharacterWorld& operator=(const CharacterWorld&) = delete;

  /// Before frame 0, steps the garments with the avatar at its rest pose (the pose they are
  /// modelled on) until every (vertex, part) pair that started below T2 has been eased out
  /// onto it or has timed out, for at most max_s: frame 0 then shows each garment out of the
  /// body's offset surfaces instead of as modelled, tighter than them (the MakeHuman suit
  /// starts inside the chest). Whole frames, numbered up to 0, from simulation time
  /// -report.seconds; nothing when no pair is eased or max_s is 0. The colliders' counters
  /// keep the settling's substeps; the solvers' and colliders' clocks start again after it.
  /// Call once, before the first stepFrame. False when a garment went unstable (see
  /// instability()).
  bool settle(double max_s, SettleReport& report);
  /// Computes frame `frame` (1-based) of every garment, the garments in parallel. False
  /// when a garment went unstable (see instability()).
  bool stepFrame(long frame);
  /// Steps every garment to `frame` in parallel; per garment, whether it stayed stable.
  std::vector<std::uint8_t> stepGarments(long frame);

  [[nodiscard]] const scene::Avatar& avatar() const { return avatar_; }
  [[nodiscard]] std::size_t garmentCount() const { return garments_.size(); }
  [[nodiscard]] const GarmentSpec& garment(std::size_t g) const { return garments_[g].spec; }
  [[nodiscard]] const cloth::ClothSolver& solver(std::size_t g) const { return *garments_[g].solver; }
  /// For adding extra colliders and stepping garments one by one.
  [[nodiscard]] cloth::ClothSolver& mutableSolver(std::size_t g) { return *garments_[g].solver; }
  [[nodiscard]] const cloth::FieldCollider* collider(std::size_t g) const { return garments_[g].collider.get(); }
  [[nodiscard]] cloth::FieldCollider* collider(std::size_t g) { return garments_[g].collider.get(); }
  /// The garment's layer collision (its own layers, the garments it is worn over), or null
  /// when it has none.
  [[nodiscard]] const cloth::LayerCollider* layerCollider(std::size_t g) const { return garments_[g].layers.get(); }
  /// The garment's layer (layersOf): the world steps the garments layer by layer.
  [[nodiscard]] int layer(std::size_t g) const { return layers_[g]; }
  [[nodiscard]] const std::vector<PartField>& fields() const { return *fields_; }
  [[nodiscard]] const AvatarPoses& poses() const { return *poses_; }
  /// The garment whose step failed and why, after stepFrame returned false.
  [[nodiscard]] std::string instability() const { return instability_; }
  /// Simulation time of the end of frame `frame`.
  [[nodiscard]] double frameTime(long frame) const { return double(frame) / settings_.step.frameRate_hz; }
  /// Seconds spent building the distance fields.
  [[nodiscard]] double fieldBuild_s() const { return fieldBuild_s_; }
  /// What keeping the body apart changed in the motion (empty unless settings asked).
  [[nodiscard]] const KeepApartReport& keepApartReport() const { return keepApart_; }
  /// The motion the avatar plays: the one the world was made with, or its corrected copy
  /// where the settings keep parts apart (null: at rest). A pose stream sends this one.
  [[nodiscard]] const motion::AvatarAnimation* playedMotion() const {
    return keptApartMotion_ ? keptApartMotion_.get() : animation_;
  }

 private:
  struct GarmentRun {
    GarmentSpec spec;
    std::unique_ptr<AvatarPoses> poses;  ///< its own pose cache: garments step in parallel
    std::vector<std::shared_ptr<const cloth::FixtureMotion>> motions;  ///< per field, from poses
    std::vector<std::unique_ptr<AvatarPoses>> guestPoses;  ///< its own pose cache of each guest
    std::unique_ptr<cloth::FieldCollider> collider;
    std::vector<std::uint32_t> fixed;  ///< the vertices its fixtures move (after the colliders)
    std::unique_ptr<cloth::LayerCollider> layers;  ///< null: no layers kept apart
    std::unique_ptr<cloth::ClothSolver> solver;
  };
  void buildFields(const std::vector<GarmentSpec>& garments, std::shared_ptr<const std::vector<PartField>> given);
  /// After stepping `frame`: logs each garment's recovery, and false (instability_ set, with
  /// `when` before it) at the first that went unstable.
  bool checkStable(const std::vector<std::uint8_t>& stables, long frame, const std::string& when);
  /// Corrects a copy of the motion so that settings_.keepApart's parts stay out of the fields'
  /// parts, and plays that copy.
  void keepBodyApart(const motion::AvatarAnimation& animation, const std::vector<GarmentSpec>& garments);
  [[nodiscard]] std::vector<cloth::PinGroup> bindMask(
      const GarmentSpec& spec, const std::vector<int>& parts,
      const std::vector<std::shared_ptr<const cloth::FixtureMotion>>& motions) const;
  /// Moves a constraint mask with vertices inside a collidable part at rest out onto the
  /// parts' surfaces, keeping its edges' lengths as far as it can: `local` (per mask vertex and part, as
  /// bindMask computes them) then places the mask there.
  void liftOutOfTheParts(const GarmentSpec& spec, const std::vector<int>& parts, std::vector<Vec3>& local) const;
  /// bindMask's distances (per mask vertex and part, `local` the vertex in each part's
  /// frame) for the vertices beyond every part's field, from the parts' surfaces.
  void measureBeyondTheFields(const std::vector<int>& parts, const std::vector<Vec3>& local,
                              std::vector<double>& distance, std::vector<int>& nearest) const;

  const scene::Avatar& avatar_;
  const motion::AvatarAnimation* animation_ = nullptr;
  WorldSettings settings_;
  std::unique_ptr<AvatarPoses> poses_;
  std::unique_ptr<motion::AvatarAnimation> keptApartMotion_;  ///< the corrected motion, when asked for
  KeepApartReport keepApart_;
  std::shared_ptr<const std::vector<PartField>> fields_;
  std::vector<std::shared_ptr<const cloth::FixtureMotion>> partMotions_;  ///< per field
  std::vector<GarmentRun> garments_;
  std::vector<int> layers_;  ///< per garment (layersOf)
  std::string instability_;
  double fieldBuild_s_ = 0;
};

}  // namespace drape::sim
