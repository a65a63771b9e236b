#pragma once
// LiveMotion: a BVH motion that arrives frame by frame while it is captured (a capture
// program writing its BVH into a pipe or a socket), retargeted onto an avatar as it comes.
//
// Frame for frame it is what loadAnimation makes of the same file (the same units, joint
// map, reference T-pose skip, resampling to the motion rate and retargeting, to the bit),
// with two differences a live source forces, both because they would need frames not yet
// captured (docs/MOTION.md):
//  - grounding follows the capture floor over trailing windows (the last second's lowest
//    point, smoothed over the last second), where a file's are centred on each frame;
//  - a Daz-style unfolding from the rest pose is not looked for (it is measured against the
//    whole clip's median speed); a reference T-pose first frame is, over the first three.
// A source frame comes out once the frame after it has come (resampling interpolates
// between the two), or at once where the source runs at the motion rate.
//
//   motion::LiveMotion live(avatar, formats::parseBvhHeader(text, "stdin"), options);
//   live.push(values);                       // each frame's channel values, as the file has them
//   while (live.next(joints)) send(joints);  // every frame at live.rate() now ready
//   live.finish();                           // the source closed: its last frames

#include <deque>
#include <span>
#include <vector>

#include "drape/formats/bvh.hpp"
#include "drape/motion/animation.hpp"
#include "drape/motion/clip_io.hpp"

namespace drape::motion {

class LiveMotion {
 public:
  /// `avatar` must outlive it. Throws drape::Error as loadAnimation does for the same header
  /// (no joint map fits, no motion joint drives the avatar's root, a rate out of range).
  LiveMotion(const scene::Avatar& avatar, const formats::BvhFile& header, const MotionOptions& options);

  /// Takes the source's next frame: header().channelCount values in the file's units and
  /// degrees. Throws drape::Error (Internal) on another count.
  void push(std::span<const double> values);
  /// The source has ended: the frames its last ones make become ready.
  void finish();
  /// The next ready frame at rate(): every avatar joint's world transform, into `out`
  /// (jointCount() of them). False when no frame is ready.
  bool next(std::span<RigidTransform> out);

  [[nodiscard]] double rate() const { return rate_; }              ///< frames per second out
  [[nodiscard]] double sourceRate() const { return sourceRate_; }  ///< frames per second in
  [[nodiscard]] std::size_t jointCount() const { return retargeter_.jointCount(); }
  [[nodiscard]] std::span<const int> drivingJoint() const { return retargeter_.drivingJoint(); }
  [[nodiscard]] const JointMap& jointMap() const { return map_; }
  [[nodiscard]] const ClipLoadReport& report() const { return report_; }
  [[nodiscard]] const formats::BvhFile& header() const { return header_; }
  [[nodiscard]] std::size_t sourceFrames() const { return pushed_; }  ///< frames pushed
  [[nodiscard]] bool referenceTPoseSkipped() const { return tposeSkipped_; }

 private:
  struct SourcePose {
    std::vector<Quat> local;
    Vec3 root = Vec3::Zero();
  };

  void accept(const SourcePose& pose);
  void acceptOpening(std::size_t from);
  void emitUpTo(double lastIndex, bool ending);
  void emit(const SourcePose& a, const SourcePose& b, double s);
  void ground(std::vector<RigidTransform>& world);

  formats::BvhFile header_;
  MotionOptions options_;
  ClipLoadReport report_;
  Clip opening_;  ///< the scaled skeleton, and the first frames while the T-pose test waits for three
  JointMap map_;
  Retargeter retargeter_;
  double scale_ = 1.0;
  double sourceRate_ = 30.0, rate_ = 30.0;
  bool resampling_ = false;
  bool opened_ = false;  ///< the T-pose test is done
  bool tposeSkipped_ = false;
  std::size_t pushed_ = 0;
  std::size_t accepted_ = 0;  ///< source frames taken after any T-pose skip
  std::size_t emitted_ = 0;   ///< frames made at rate()
  SourcePose previous_, current_, converted_;
  std::deque<double> lowest_, window_;  ///< the trailing windows of grounding
  std::deque<std::vector<RigidTransform>> ready_;
  // Scratch kept from frame to frame, so that a frame in steady state allocates nothing: the
  // resampled local rotations, and the frames next() handed out, for emit() to fill again.
  std::vector<Quat> local_;
  std::vector<std::vector<RigidTransform>> spare_;
};

}  // namespace drape::motion
