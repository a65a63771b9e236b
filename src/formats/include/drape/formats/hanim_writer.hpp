#pragma once
// Segmented humanoids as H-Anim 1.1 VRML97 text: a Humanoid whose humanoidBody holds the
// Joint tree, each Joint carrying its Segments (IndexedFaceSet shapes), with the joints
// and segments also listed in the Humanoid's `joints` and `segments` fields. As H-Anim 1.1
// prescribes for the default pose, every Joint has identity rotation and translation, its
// `center` is the joint centre in humanoid coordinates, and segment points are in humanoid
// coordinates too. The PROTO declarations (Humanoid, Joint, Segment with the H-Anim 1.1
// interfaces) are written at the top, so the file stands alone in any VRML97 browser. A
// motion, when given, follows the Humanoid as interpolators routed into the Joints.

#include <optional>
#include <string>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/mesh/trimesh.hpp"

namespace drape::formats {

struct HanimSegmentData {
  std::string name;
  std::vector<Vec3> points;              ///< m, humanoid coordinates (rest pose)
  std::vector<mesh::Triangle> triangles;
};

struct HanimJointData {
  std::string name;
  int parent = -1;                       ///< index into joints; parents come first
  Vec3 center = Vec3::Zero();            ///< m, humanoid coordinates
  std::vector<HanimSegmentData> segments;
};

/// A motion of the humanoid: one OrientationInterpolator per Joint into its `rotation`, and
/// a PositionInterpolator into its `translation` for the joints that move away from their
/// place (the root, as a rule), keyed per frame from one looping TimeSensor. The Joints keep
/// the default pose (identity rotation and translation) in their fields, so a reader that
/// takes the file as a humanoid at rest, drape's own among them, sees the same body.
struct HanimMotion {
  std::string name;                      ///< the motion's name, for the file's comment and `info`
  double frameRate = 30.0;               ///< frames per second
  /// [frame][joint], joints as in HanimHumanoidData::joints: the values of the Joint's
  /// `rotation` and `translation` fields in that frame (rotation about the Joint's `center`,
  /// in its parent Joint's coordinates).
  std::vector<std::vector<RigidTransform>> frames;
};

struct HanimHumanoidData {
  std::string name;
  std::vector<std::string> info;         ///< "key=value" strings for the `info` field
  std::vector<HanimJointData> joints;
  std::optional<HanimMotion> motion;     ///< none: the humanoid at rest
};

/// The whole file as text. Throws drape::Error on a motion that does not fit the joints
/// (a frame with another number of joints, no frames, a rate that is not positive).
[[nodiscard]] std::string hanimText(const HanimHumanoidData& humanoid);
/// Writes hanimText() to `path`; throws drape::Error if it cannot be written.
void writeHanim(const std::string& path, const HanimHumanoidData& humanoid);

/// A VRML97 identifier made from `name` (invalid characters become '_').
[[nodiscard]] std::string vrmlIdentifier(const std::string& name);

}  // namespace drape::formats
