#include "drape/formats/hanim_motion.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string_view>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/core/files.hpp"
#include "drape/formats/vrml_read.hpp"
#include "drape/formats/vrml_transform.hpp"
#include "drape/formats/vrml_write.hpp"

namespace drape::formats {
namespace {

using vrml::Document;
using vrml::Field;
using vrml::Node;
using vrml::TransformFields;
using Affine = Eigen::Affine3d;

/// The Transform fields an interpolator may drive, in TransformFields' terms.
constexpr std::array<const char*, 5> kTransformFieldNames{"translation", "rotation", "scale", "center",
                                                          "scaleOrientation"};

const Node* nodeAt(const Document& d, std::int32_t i) {
  return i >= 0 && static_cast<std::size_t>(i) < d.nodes.size() ? &d.nodes[static_cast<std::size_t>(i)] : nullptr;
}

std::vector<std::int32_t> childrenOf(const Node& n, const char* field = "children") {
  std::vector<std::int32_t> out;
  if (const Field* f = n.field(field))
    for (const std::int32_t c : f->nodes)
      if (c >= 0) out.push_back(c);
  return out;
}

/// The TimeSensor's cycle that drives field `name` of `n` through an interpolator, in
/// seconds; 0 when no interpolator with keys, fed by an enabled TimeSensor, drives it.
double drivingCycle(const Document& d, const Node& n, const char* name) {
  const Field* f = n.field(name);
  const Node* interpolator = f != nullptr ? nodeAt(d, f->routeFromNode) : nullptr;
  if (interpolator == nullptr) return 0.0;
  const Field* key = interpolator->field("key");
  const Field* keyValue = interpolator->field("keyValue");
  const Field* fraction = interpolator->field("set_fraction");
  if (key == nullptr || keyValue == nullptr || key->numbers.empty() || keyValue->numbers.empty() || fraction == nullptr)
    return 0.0;
  const Node* sensor = nodeAt(d, fraction->routeFromNode);
  if (sensor == nullptr || sensor->type != "TimeSensor") return 0.0;
  // A disabled sensor sends no fraction: the field keeps its written value, as in a browser.
  if (const Field* enabled = sensor->field("enabled"); enabled != nullptr && !enabled->numbers.empty() &&
                                                      enabled->numbers[0] == 0.0)
    return 0.0;
  const Field* cycle = sensor->field("cycleInterval");
  const double seconds = cycle != nullptr && !cycle->numbers.empty() ? cycle->numbers[0] : 1.0;  // VRML97's default
  return std::isfinite(seconds) && seconds > 0.0 ? seconds : 0.0;
}

/// A node with Transform's fields in the humanoid, and which of them interpolators drive.
struct Frame {
  std::int32_t node = -1;
  int parent = -1;  ///< index into Rig::frames; -1: the humanoid's own frame
  TransformFields rest;
  std::vector<const char*> animated;
};

/// A Humanoid's Joints and the transforms above them, walked as the scene reader walks them.
struct Rig {
  Rig(const Document& document, std::string fileName) : d(document), file(std::move(fileName)) {}

  const Document& d;
  std::string file;
  std::vector<Frame> frames;
  std::vector<std::string> jointNames;
  std::vector<int> jointParents;
  std::vector<int> jointFrame;  ///< each joint's index into frames
  double lowest = std::numeric_limits<double>::infinity();  ///< the segments' lowest point at rest
  double cycle_s = 0.0;                                     ///< the longest driving TimeSensor cycle

  int addFrame(std::int32_t index, int parent) {
    const Node& n = *nodeAt(d, index);
    Frame f{index, parent, TransformFields::of(n), {}};
    for (const char* name : kTransformFieldNames)
      if (const double c = drivingCycle(d, n, name); c > 0.0) {
        f.animated.push_back(name);
        cycle_s = std::max(cycle_s, c);
      }
    frames.push_back(std::move(f));
    return static_cast<int>(frames.size()) - 1;
  }

  /// Mirrors the scene reader's Humanoid walk: Joints become joints, Segments the geometry
  /// of the nearest enclosing one, other transforms compose.
  void walk(std::int32_t index, int parentFrame, int parentJoint, const Affine& world, int depth) {
    const Node* n = nodeAt(d, index);
    if (n == nullptr) return;
    if (depth > 1000) throw Error(fmt::format("{}: the humanoid's body is nested deeper than 1000 levels", file));
    if (n->type == "Joint" || vrml::isTransformLike(n->type)) {
      const int self = addFrame(index, parentFrame);
      const Affine local = world * frames.back().rest.matrix();
      int joint = parentJoint;
      if (n->type == "Joint") {
        joint = static_cast<int>(jointNames.size());
        const std::string name = n->nameOrDef();
        jointNames.push_back(name.empty() ? fmt::format("joint {}", jointNames.size() + 1) : name);
        jointParents.push_back(parentJoint);
        jointFrame.push_back(self);
      }
      for (const std::int32_t c : childrenOf(*n)) walk(c, self, joint, local, depth + 1);
      return;
    }
    if (n->type == "Segment") {
      if (parentJoint >= 0)
        for (const std::int32_t c : childrenOf(*n)) lowestPoint(c, world, depth + 1);
      return;
    }
    if (n->proto && n->field("children") == nullptr) return;  // sensors and the like
    for (const std::int32_t c : childrenOf(*n)) walk(c, parentFrame, parentJoint, world, depth + 1);
  }

  /// The segment geometry below a node, as the scene reader collects it, for the floor.
  void lowestPoint(std::int32_t index, const Affine& world, int depth) {
    const Node* n = nodeAt(d, index);
    if (n == nullptr || depth > 1000) return;
    const auto take = [&](const Node& g) {
      for (const Vec3& p : g.positions) lowest = std::min(lowest, (world * p).y());
    };
    if (n->type == "Shape") {
      const std::vector<std::int32_t> g = childrenOf(*n, "geometry");
      if (!g.empty() && nodeAt(d, g[0])->hasMesh) take(*nodeAt(d, g[0]));
      return;
    }
    if (n->hasMesh) return take(*n);
    if (n->type == "Inline") return lowestPoint(n->inlined, world, depth + 1);
    if (n->type == "Joint" || n->type == "Segment") return;
    const Affine local = vrml::isTransformLike(n->type) ? Affine(world * TransformFields::of(*n).matrix()) : world;
    if (n->proto && n->field("children") == nullptr && n->body >= 0) return lowestPoint(n->body, world, depth + 1);
    for (const std::int32_t c : childrenOf(*n)) lowestPoint(c, local, depth + 1);
  }
};

/// The node's Transform fields at `time`: as written, with the animated ones as their
/// interpolators give them.
TransformFields fieldsAt(const Document& d, std::int32_t node, const TransformFields& rest,
                         const std::vector<const char*>& animated, double time) {
  TransformFields t = rest;
  for (const char* name : animated) {
    const std::vector<double> v = vrml::sampleAnimatedField(d, node, name, time);
    const std::string_view field(name);
    if (field == "rotation" || field == "scaleOrientation") {
      if (v.size() < 4) continue;
      (field == "rotation" ? t.rotation : t.scaleOrientation) = vrml::rotationOf(v.data(), v.size());
    } else if (v.size() >= 3) {
      const Vec3 value(v[0], v[1], v[2]);
      if (field == "translation") t.translation = value;
      else if (field == "scale") t.scale = value;
      else t.center = value;
    }
  }
  return t;
}

/// The joint's frame at its centre: the node's matrix followed by a shift to its centre, so
/// that its origin is where the joint is (what SkinnedJointMotion's positions are).
Eigen::Matrix4d atCentre(const Affine& world, const Vec3& centre) { return (world * Eigen::Translation3d(centre)).matrix(); }

SkinnedJointMotion sample(const Rig& rig, const Node& humanoid, std::int32_t humanoidIndex,
                          const std::vector<const char*>& humanoidAnimated, std::string name, double rate) {
  const Document& d = rig.d;
  const std::size_t joints = rig.jointNames.size();
  SkinnedJointMotion m;
  m.animation = std::move(name);
  m.rate = rate;
  m.start_s = 0.0;
  m.end_s = rig.cycle_s;
  m.joints = rig.jointNames;
  m.parents = rig.jointParents;

  // The rest pose: every field as written.
  std::vector<Affine> world(rig.frames.size());
  std::vector<TransformFields> fields(rig.frames.size());
  const auto pose = [&](double time, bool rest) {
    for (std::size_t k = 0; k < rig.frames.size(); ++k) {
      const Frame& f = rig.frames[k];
      fields[k] = rest || f.animated.empty() ? f.rest : fieldsAt(d, f.node, f.rest, f.animated, time);
      const Affine parent = f.parent >= 0 ? world[static_cast<std::size_t>(f.parent)] : Affine::Identity();
      world[k] = parent * fields[k].matrix();
    }
  };
  pose(0.0, true);
  std::vector<Eigen::Matrix4d> restInverse(joints);
  std::vector<Vec3> restCentres(joints);
  for (std::size_t j = 0; j < joints; ++j) {
    const auto k = static_cast<std::size_t>(rig.jointFrame[j]);
    restCentres[j] = world[k] * fields[k].center;
    restInverse[j] = atCentre(world[k], fields[k].center).inverse();
  }
  m.restCenters = restCentres;
  m.floor_m = std::isfinite(rig.lowest) ? rig.lowest : detail::lowestOf({}, restCentres);

  // A Humanoid whose own fields move carries its body: the change from its written pose.
  const TransformFields humanoidRest = TransformFields::of(humanoid);
  const Affine humanoidRestInverse = humanoidRest.matrix().inverse();

  const std::size_t frames = detail::motionFrameCount(0.0, rig.cycle_s, rate, joints, m.animation, d.file);
  m.frames.reserve(frames * joints);
  for (std::size_t f = 0; f < frames; ++f) {
    const double time = std::min(static_cast<double>(f) / rate, rig.cycle_s);
    pose(time, false);
    const Affine carried =
        humanoidAnimated.empty()
            ? Affine::Identity()
            : Affine(humanoidRestInverse * fieldsAt(d, humanoidIndex, humanoidRest, humanoidAnimated, time).matrix());
    for (std::size_t j = 0; j < joints; ++j) {
      const auto k = static_cast<std::size_t>(rig.jointFrame[j]);
      m.frames.push_back(detail::jointMotionOf(atCentre(carried * world[k], fields[k].center), restInverse[j]));
    }
  }
  return m;
}

}  // namespace

bool isVrmlPath(const std::string& path) {
  const std::string ext = lowerExtension(path);
  return ext == ".wrl" || ext == ".vrml";
}

std::vector<SkinnedJointMotion> hanimMotions(const vrml::Document& document, double rate, const std::string& file) {
  std::vector<SkinnedJointMotion> motions;
  for (std::size_t i = 0; i < document.nodes.size(); ++i) {
    const Node& humanoid = document.nodes[i];
    if (humanoid.type != "Humanoid") continue;
    Rig rig(document, file);
    for (const std::int32_t c : childrenOf(humanoid, "humanoidBody")) rig.walk(c, -1, -1, Affine::Identity(), 1);
    std::vector<const char*> humanoidAnimated;
    for (const char* name : kTransformFieldNames)
      if (const double c = drivingCycle(document, humanoid, name); c > 0.0) {
        humanoidAnimated.push_back(name);
        rig.cycle_s = std::max(rig.cycle_s, c);
      }
    if (rig.jointNames.empty() || rig.cycle_s <= 0.0) continue;
    const std::string name = detail::animationName(humanoid.nameOrDef(), motions.size());
    detail::appendWithinCap(
        motions, sample(rig, humanoid, static_cast<std::int32_t>(i), humanoidAnimated, name, rate), file);
  }
  std::vector<std::string> names;
  for (const SkinnedJointMotion& m : motions) names.push_back(m.animation);
  for (SkinnedJointMotion& m : motions) m.animationNames = names;
  return motions;
}

std::vector<SkinnedJointMotion> readHanimMotions(const std::string& path, double rate) {
  return hanimMotions(vrml::readFile(path), rate, path);
}

SkinnedJointMotion readHanimMotion(const std::string& path, double rate, const std::string& animation) {
  const vrml::Document document = vrml::readFile(path);
  std::vector<SkinnedJointMotion> motions = hanimMotions(document, rate, path);
  if (motions.empty()) {
    std::vector<std::string> humanoids;
    for (const Node& n : document.nodes)
      if (n.type == "Humanoid") humanoids.push_back(fmt::format("'{}'", n.nameOrDef()));
    if (humanoids.empty()) throw Error(fmt::format("{}: has no H-Anim Humanoid to take a motion from", path));
    const bool several = humanoids.size() > 1;
    throw Error(fmt::format("{}: {} {} {} no motion: no interpolator that an enabled TimeSensor drives is routed into {} "
                            "Joints (ROUTE an OrientationInterpolator's value_changed TO a Joint's set_rotation)",
                            path, several ? "Humanoids" : "Humanoid", fmt::join(humanoids, ", "),
                            several ? "have" : "has", several ? "their" : "its"));
  }
  std::vector<std::string> names;
  for (const SkinnedJointMotion& m : motions) names.push_back(m.animation);
  return std::move(motions[detail::chooseAnimation(names, animation, path)]);
}

}  // namespace drape::formats
