#pragma once
// Keeping the body out of itself: a correction of the retargeted motion.
//
// Motion captured on another body can swing a forearm through the small of the back
// (sim/body_overlap.hpp). Cloth caught there has no place, and no collision response mends
// it. This pass changes the motion instead, before the simulation: frame by frame, each
// part it is asked to keep apart is swung out of every collidable part it goes into (those
// it does not meet at a joint) by rotating its limb about the joint above it (a forearm and
// its hand about the shoulder, a shin about the hip), until its surface keeps a margin from
// that part's surface, read from that part's distance field. Each step turns the limb by the
// least angle that lifts its deepest vertex out along the field's gradient.
//
// Frame by frame alone, a correction would start and stop with a kink in the limb's path,
// and the cloth on it would feel the jolt. So the corrections (one rotation per pivot joint
// and frame, in its parent joint's frame so that it moves with the body) are smoothed over
// time: each frame takes the largest turn within two sigmas of it, then a Gaussian blends
// them, so the limb turns away before it would touch and back after, about as far as each
// frame needed. A last solve, not smoothed, mends what the blend left short, so every
// frame keeps the margin where the field can say so.
//
// What it does not do: it moves only the parts named (the walking dress names the arms; its
// thighs press into each other on every walk, as real ones do, and spreading them would
// move the feet), it turns no joint by more than maxTurn_deg from the captured motion, and
// it does not search over joints: a limb the joint above cannot swing out (its deepest
// vertex in line with the joint and the gradient) is left where it is; what is left short
// is reported.

#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "drape/motion/animation.hpp"
#include "drape/scene/avatar.hpp"

namespace drape::sim {

struct PartField;

struct KeepApartSettings {
  /// The avatar's segments to move out of the collidable parts they go into (any segment:
  /// its own mesh is what must stay out). Empty: the motion is left as it is.
  std::vector<std::string> parts;
  /// Clearance to keep between a moved part's surface and the other part's (m), or the
  /// pair's clearance at rest where that is less. 0: CharacterWorld takes twice the
  /// garments' largest T2, room for cloth on both parts' collision surfaces.
  double margin_m = 0;
  /// Gaussian time constant (sigma, s) the corrections are smoothed with.
  double smoothing_s = 0.1;
  /// The most a joint is turned from the captured motion (degrees): a part that would need
  /// more is left short of its clearance and reported, rather than swung into a pose the
  /// performer never took.
  double maxTurn_deg = 30;
};

/// One moved part and a part it went into.
struct KeptApart {
  std::string part;        ///< the part moved
  std::string from;        ///< the part it went into
  std::string pivot;       ///< the joint it was swung about
  double target_m = 0;     ///< the clearance kept: the margin, or the pair's at rest if less
  double deepest_m = 0;    ///< before: the most the pair lacked of its clearance (m)
  long deepestFrame = 0;   ///< motion frame of that
  long frames = 0;         ///< motion frames in which it lacked clearance before
  double remaining_m = 0;  ///< after: the most it still lacks, in any frame (m)
  long framesRemaining = 0;  ///< frames that still lack more than a voxel's tenth
};

struct KeepApartReport {
  std::vector<std::string> parts;  ///< the parts asked for
  double maxTurn_deg = 0;          ///< the limit the turns were held to
  std::vector<KeptApart> pairs;  ///< pairs that lacked clearance in some frame, deepest first
  double largestAngle_deg = 0;   ///< the largest correction of any joint in any frame
  long framesChanged = 0;        ///< motion frames with any correction
  double seconds = 0;
};

/// Corrects `animation` (retargeted onto `avatar`) so that each of settings.parts keeps its
/// clearance from every one of `fields`' parts it does not meet at a joint (sim::jointsMeet)
/// and does not move with. Throws drape::Error naming an unknown part, or a part whose limb
/// has no joint above it that can swing it (the root).
[[nodiscard]] KeepApartReport keepBodyApart(const scene::Avatar& avatar, motion::AvatarAnimation& animation,
                                            const std::vector<PartField>& fields, const KeepApartSettings& settings);

/// The same correction of a motion that arrives a frame at a time (a live capture, or an
/// event graph played live): frame for frame what keepBodyApart makes of the whole motion,
/// to the bit, each frame out once delay() frames after it have come (the smoothing reads
/// that far ahead: 15 frames, half a second, at 30 Hz and the default 0.1 s), and the last
/// ones once the motion has ended. A frame allocates nothing.
///
///   sim::LiveKeepApart keep(avatar, fields, settings, live.rate());
///   keep.push(pose);                   // each frame's joints as it comes
///   while (keep.next(out)) use(out);   // every frame now corrected
///   keep.finish();                     // the motion ended: its last frames follow from next()
class LiveKeepApart {
 public:
  /// `avatar` and `fields` must outlive it; `rate` is the motion's, in frames per second.
  /// Throws drape::Error as keepBodyApart does.
  LiveKeepApart(const scene::Avatar& avatar, const std::vector<PartField>& fields, const KeepApartSettings& settings,
                double rate);
  ~LiveKeepApart();
  LiveKeepApart(const LiveKeepApart&) = delete;
  LiveKeepApart& operator=(const LiveKeepApart&) = delete;

  /// Takes the motion's next frame: every avatar joint's world transform. Throws drape::Error
  /// (Internal) on another count, after finish(), or when more than delay() frames came
  /// before it that next() has not taken.
  void push(std::span<const RigidTransform> pose);
  /// The motion has ended: its last frames become ready.
  void finish();
  /// The next corrected frame into `out` (every joint's world transform); false when none is
  /// ready.
  bool next(std::span<RigidTransform> out);

  /// Frames a frame waits for before it is corrected (0 without smoothing).
  [[nodiscard]] std::size_t delay() const;
  [[nodiscard]] std::size_t framesOut() const;
  /// What keepBodyApart reports, over the frames out so far (frames numbered from the first
  /// pushed).
  [[nodiscard]] KeepApartReport report() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// "LeftForeArm out of LowerBack about LeftArm: 39.0 mm short of its 12 mm clearance at
/// most, in 37 frames (most in frame 80); 0.0 mm after".
[[nodiscard]] std::string describe(const KeptApart& kept);

}  // namespace drape::sim
