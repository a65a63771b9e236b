#pragma once
// Segmented humanoids as H-Anim 1.1 VRML97 text: a Humanoid whose humanoidBody holds the
// Joint tree, each Joint carrying its Segments (IndexedFaceSet shapes), with the joints
// and segments also listed in the Humanoid's `joints` and `segments` fields. As H-Anim 1.1
// prescribes for the default pose, every Joint has identity rotation and translation, its
// `center` is the joint centre in humanoid coordinates, and segment points are in humanoid
// coordinates too. The PROTO declarations (Humanoid, Joint, Segment with the H-Anim 1.1
// interfaces) are written at the top, so the file stands alone in any VRML97 browser.

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

struct HanimHumanoidData {
  std::string name;
  std::vector<std::string> info;         ///< "key=value" strings for the `info` field
  std::vector<HanimJointData> joints;
};

/// The whole file as text.
[[nodiscard]] std::string hanimText(const HanimHumanoidData& humanoid);
/// Writes hanimText() to `path`; throws drape::Error if it cannot be written.
void writeHanim(const std::string& path, const HanimHumanoidData& humanoid);

/// A VRML97 identifier made from `name` (invalid characters become '_').
[[nodiscard]] std::string vrmlIdentifier(const std::string& name);

}  // namespace drape::formats
