#pragma once
// Writing animated results as VRML97 (result.wrl): each garment an IndexedFaceSet whose
// Coordinate is driven by a CoordinateInterpolator, each avatar joint a Transform driven by
// a PositionInterpolator and an OrientationInterpolator, all from one looping TimeSensor.
// Plain VRML97 that any browser plays, and that drape's own reader reads back.

#include <string>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/formats/vrml_tree.hpp"
#include "drape/mesh/trimesh.hpp"

namespace drape::formats::vrml {

struct GarmentTrack {
  std::string name;  ///< becomes a DEF name (sanitised)
  std::vector<mesh::Triangle> triangles;
  std::vector<std::vector<Vec3>> frames;  ///< m, world positions per frame (same count each)
  Vec3 color{0.8, 0.25, 0.2};             ///< diffuse colour, 0..1
};

struct JointTrack {
  std::string name;
  std::vector<mesh::TriMesh> segments;  ///< m, in the joint's frame
  std::vector<RigidTransform> frames;   ///< joint world transform per frame
};

struct Animation {
  double frameRate = 30.0;  ///< frames per second
  std::vector<GarmentTrack> garments;
  std::vector<JointTrack> joints;  ///< optional: the avatar
};

/// `text` as a VRML97 string: in double quotes, its quotes and backslashes escaped.
[[nodiscard]] std::string quotedString(const std::string& text);

/// Writes `animation` to `path`. Throws drape::Error on inconsistent tracks (frame counts
/// differ, a frame with the wrong number of vertices) or when the file cannot be written.
void writeAnimation(const std::string& path, const Animation& animation);

/// The values a ROUTE from an interpolator gives field `field` of node `node` at `time`
/// seconds (the interpolator driven by a TimeSensor's fraction_changed; linear between
/// keys, an OrientationInterpolator's along the shortest arc). Empty when the field is not
/// animated. Numbers as in Field::numbers.
[[nodiscard]] std::vector<double> sampleAnimatedField(const Document& document, std::int32_t node,
                                                      const std::string& field, double time);

}  // namespace drape::formats::vrml
