#pragma once
// Motion files to Clips: BVH and ASF/AMC, converted to metres (units guessed from the
// skeleton's size unless given), the CMU T-pose reference frame dropped, and resampled to
// the motion rate.

#include <optional>
#include <span>
#include <string>

#include "drape/formats/bvh.hpp"
#include "drape/motion/skeleton.hpp"

namespace drape::formats {
struct AsfSkeleton;
struct AmcMotion;
}  // namespace drape::formats

namespace drape::motion {

/// CMU's ASF length unit as the cgspeed BVH conversions keep it: (1/0.45) inch = 0.0564 m.
inline constexpr double kCmuMetresPerUnit = 2.54 / 0.45 / 100.0;

struct UnitsGuess {
  double metresPerUnit = 1.0;
  std::string name;        ///< "m", "cm", "mm", "in" or "CMU units (0.0564 m)"
  double extentInUnits = 0.0;  ///< the skeleton's rest extent in file units
};

/// Picks the unit that makes a human skeleton of `extentInUnits` closest to 1.7 m:
/// m, cm, mm, inches, or CMU's 0.0564 m.
[[nodiscard]] UnitsGuess guessUnits(double extentInUnits);

struct ClipLoadOptions {
  double rate = 30.0;                      ///< resample to this many frames per second (0: keep)
  std::optional<double> metresPerUnit;     ///< overrides the units guess (--motion-scale)
  bool skipReferenceTPose = true;          ///< drop a CMU-style T-pose first frame
  bool skipRestUnfold = true;              ///< drop a Daz-style unfolding from the rest pose (restUnfoldFrames)
  std::string asfPath;                     ///< for .amc files: the skeleton (default: the .asf next to it)
};

/// What loading found, for `drape inspect` and logs.
struct ClipLoadReport {
  UnitsGuess units;
  bool unitsOverridden = false;
  double sourceRate = 0.0;                 ///< frames per second in the file
  std::size_t sourceFrames = 0;            ///< frames in the file
  bool referenceTPoseSkipped = false;
  std::size_t restUnfoldFramesSkipped = 0;  ///< file frames of an unfolding from the rest pose, not played
  std::string standingAxis = "+y";         ///< the axis the file stands the capture along (standing.hpp)
  Quat standingTurn = Quat::Identity();    ///< the turn that stood it up along +y

  /// "it stands along +z: turned to stand along +y, as drape's scenes do"; empty for +y.
  [[nodiscard]] std::string stoodUp() const;

  /// "frame 1 is a reference T-pose, not played"; empty without one.
  [[nodiscard]] std::string referenceTPose() const;
  /// "frames 2-5 unfold from the rest pose (not played; the lead-in blends into frame 6)",
  /// file frames counted from 1; empty without such frames.
  [[nodiscard]] std::string restUnfoldSkipped() const;
};

/// BVH channels to local rotations: the rotation channels in file order compose left to
/// right (Z Y X = Rz * Ry * Rx); the root's position channels (plus its offset) give the
/// root translation. Position channels of other joints are ignored.
[[nodiscard]] Clip clipFromBvh(const formats::BvhFile& bvh, const ClipLoadOptions& options = {},
                               ClipLoadReport* report = nullptr);

/// One BVH frame's values (file units, degrees) as clipFromBvh converts them: each joint's
/// local rotation into `rotations` (bvh.joints.size() of them) and the root's position
/// channels into `root`, still in file units (a clip scales them to metres). Allocates nothing.
void bvhFramePose(const formats::BvhFile& bvh, const double* values, std::span<Quat> rotations, Vec3& root);

/// ASF skeleton + AMC motion to a clip (see asf_amc.hpp for the conventions).
[[nodiscard]] Clip clipFromAsfAmc(const formats::AsfSkeleton& asf, const formats::AmcMotion& amc,
                                  const ClipLoadOptions& options = {}, ClipLoadReport* report = nullptr);

/// Reads FILE.bvh or FILE.amc (with options.asfPath or FILE's .asf) into a clip.
/// Throws drape::Error with "file:line:column: ..." on bad files.
[[nodiscard]] Clip loadClip(const std::string& path, const ClipLoadOptions& options = {},
                            ClipLoadReport* report = nullptr);

/// True if frame 0 of the raw clip is a reference T-pose that is not part of the motion:
/// its arms are near horizontal and far apart, and the pose jumps to frame 1 by more than
/// 20 degrees at some joint while frame 1 to frame 2 changes much less.
[[nodiscard]] bool firstFrameIsReferenceTPose(const Clip& clip);

/// The frames at the start of a clip (after any reference T-pose) that unfold the skeleton
/// from its rest pose into the motion, as some exporters write them (Daz, Poser: frame 0
/// with the body's rotations zero, then a few frames that turn joints far faster than the
/// motion ever does): a run of frame-to-frame joint speeds from frame 0 above four times the
/// clip's median (and above 180 degrees per second) that ends within a quarter second, in
/// which every joint that turns more than 10 degrees starts nearer its rest orientation than
/// a quarter of its turn. Returns the run's length, the frames to drop so that the clip
/// starts where the unfolding ends (the lead-in then blends into that pose over its own
/// time); 0 for any other clip.
[[nodiscard]] std::size_t restUnfoldFrames(const Clip& clip);

/// Resamples the clip to `rate` (SLERP of local rotations, linear root translation).
[[nodiscard]] Clip resample(const Clip& clip, double rate);

/// Drops the first `count` frames.
void dropLeadingFrames(Clip& clip, std::size_t count);

}  // namespace drape::motion
