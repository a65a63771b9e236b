// Scene building from a VRML97 document: walks the node tree with the VRML97 transform
// rules, turns H-Anim Humanoids into segmented avatars (paper section 4.2: every joint
// frame reset to unit scale, aligned with the humanoid's root frame), ClothSets into
// garments with their masks matched (section 4.1), and collects materials, the simulation
// settings and the remaining geometry as scenery.

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/formats/vrml_transform.hpp"
#include "drape/scene/scene_build.hpp"

namespace drape::scene {
namespace {

using formats::vrml::Document;
using formats::vrml::Field;
using formats::vrml::FieldKind;
using formats::vrml::Node;
using formats::vrml::isTransformLike;
using Affine = Eigen::Affine3d;

// ---- Field access ------------------------------------------------------------------------

double number(const Node& n, const char* name, double fallback) {
  const Field* f = n.field(name);
  return f != nullptr && !f->numbers.empty() ? f->numbers[0] : fallback;
}

Vec3 vec3(const Node& n, const char* name, const Vec3& fallback) {
  const Field* f = n.field(name);
  return f != nullptr && f->numbers.size() >= 3 ? Vec3(f->numbers[0], f->numbers[1], f->numbers[2]) : fallback;
}

std::string string(const Node& n, const char* name) {
  const Field* f = n.field(name);
  return f != nullptr && !f->strings.empty() ? f->strings[0] : std::string();
}

std::vector<std::string> strings(const Node& n, const char* name) {
  const Field* f = n.field(name);
  return f != nullptr ? f->strings : std::vector<std::string>();
}

std::vector<std::int32_t> nodes(const Node& n, const char* name) {
  const Field* f = n.field(name);
  std::vector<std::int32_t> out;
  if (f != nullptr)
    for (std::int32_t i : f->nodes)
      if (i >= 0) out.push_back(i);
  return out;
}

std::int32_t node(const Node& n, const char* name) {
  const std::vector<std::int32_t> all = nodes(n, name);
  return all.empty() ? -1 : all[0];
}

SourcePos where(const Node& n, const char* field = nullptr) {
  int line = n.line;
  if (field != nullptr)
    if (const Field* f = n.field(field); f != nullptr && f->line > 0) line = f->line;
  return {n.file, line, 0};
}

Affine transformOf(const Node& n) { return formats::vrml::TransformFields::of(n).matrix(); }

mesh::TriMesh transformed(const Node& geometry, const Affine& world, const std::string& name) {
  mesh::TriMesh m;
  m.name = name;
  m.positions.reserve(geometry.positions.size());
  for (const Vec3& p : geometry.positions) m.positions.push_back(world * p);
  m.triangles = geometry.triangles;
  if (world.linear().determinant() < 0.0)  // a mirroring transform turns the winding over
    for (mesh::Triangle& t : m.triangles) std::swap(t[1], t[2]);
  return m;
}

void append(mesh::TriMesh& to, const mesh::TriMesh& from) {
  const auto offset = static_cast<std::uint32_t>(to.positions.size());
  to.positions.insert(to.positions.end(), from.positions.begin(), from.positions.end());
  for (const mesh::Triangle& t : from.triangles) to.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
}

// ---- The builder -------------------------------------------------------------------------

class Builder {
 public:
  explicit Builder(const Document& doc) : doc_(doc) { scene_.source = doc.file; }

  Scene build() {
    scene_.warnings = doc_.warnings;
    findSettings();
    const Affine root = Affine(Eigen::Scaling(scene_.simulation.unitScale));
    for (std::int32_t r : doc_.roots) walk(r, root);
    for (const PendingGarment& g : pending_) garment(g);
    checkLayers();
    return std::move(scene_);
  }

 private:
  struct PendingGarment {
    std::int32_t node;
    Affine world;
  };

  const Node& at(std::int32_t i) const { return doc_.nodes[static_cast<std::size_t>(i)]; }

  // Simulation settings first: unitScale applies to every position in the file.
  void findSettings() {
    const Node* found = nullptr;
    double worldInfoScale = 0.0;
    for (const Node& n : doc_.nodes) {
      if (n.type == "WorldInfo") {
        for (const std::string& info : strings(n, "info")) {
          if (info.rfind("unitScale", 0) != 0) continue;
          const std::string value = info.substr(9);
          const std::size_t start = value.find_first_not_of(" =:");
          try {
            worldInfoScale = std::stod(value.substr(start == std::string::npos ? value.size() : start));
          } catch (const std::exception&) {
            throw Error::at(where(n), fmt::format("WorldInfo: cannot read a number from info \"{}\"", info));
          }
        }
      }
      if (n.type != "Simulation") continue;
      if (found != nullptr && found->file == n.file) {
        throw Error::at(
            where(n), fmt::format("a second Simulation node (the first is at line {}); a scene has one", found->line));
      }
      if (found == nullptr) found = &n;
    }
    SimulationSettings& s = scene_.simulation;
    if (worldInfoScale != 0.0) s.unitScale = worldInfoScale;
    if (found != nullptr) {
      const Node& n = *found;
      scene_.hasSimulationNode = true;
      // Field by field, validating after each, so an error names the line of its value.
      const SourcePos nodePos = where(n);
      const auto take = [&](const char* field, auto assign) {
        if (n.field(field) == nullptr) return;
        assign();
        s.source = where(n, field);
        validate(s);
        s.source = nodePos;
      };
      take("gravity", [&] { s.gravity = vec3(n, "gravity", s.gravity); });
      take("frameRate", [&] { s.frameRate = number(n, "frameRate", s.frameRate); });
      take("stepsPerFrame", [&] { s.stepsPerFrame = static_cast<int>(number(n, "stepsPerFrame", s.stepsPerFrame)); });
      take("airViscosity", [&] { s.airViscosity = number(n, "airViscosity", s.airViscosity); });
      take("wind", [&] { s.wind = vec3(n, "wind", s.wind); });
      if (const Field* f = n.field("offsets"); f != nullptr && !f->isDefault)
        take("offsets", [&] { s.offsets = fourOffsets(n, "Simulation"); });
      take("voxelSize", [&] { s.voxelSize = number(n, "voxelSize", s.voxelSize); });
      take("integrator", [&] { s.integrator = string(n, "integrator"); });
      take("collisionEvery",
           [&] { s.collisionEvery = static_cast<int>(number(n, "collisionEvery", s.collisionEvery)); });
      take("bendEvery", [&] { s.bendEvery = static_cast<int>(number(n, "bendEvery", s.bendEvery)); });
      take("maxAddedMass", [&] { s.maxAddedMass = number(n, "maxAddedMass", s.maxAddedMass); });
      take("maxRefinement", [&] { s.maxRefinement = static_cast<int>(number(n, "maxRefinement", s.maxRefinement)); });
      take("strainLimit", [&] { s.strainLimit = number(n, "strainLimit", s.strainLimit); });
      take("rescueStrainLimit",
           [&] { s.rescueStrainLimit = number(n, "rescueStrainLimit", s.rescueStrainLimit); });
      take("implicitTolerance",
           [&] { s.implicitTolerance = number(n, "implicitTolerance", s.implicitTolerance); });
      take("keepApart", [&] { s.keepApart = strings(n, "keepApart"); });
      if (const Field* f = n.field("unitScale"); f != nullptr && !f->isDefault)
        take("unitScale", [&] { s.unitScale = number(n, "unitScale", 1.0); });
      s.source = nodePos;
    }
    validate(s);
  }

  // Depth-first walk of the world with each node's world transform.
  void walk(std::int32_t index, const Affine& world) {
    if (index < 0) return;
    const Node& n = at(index);
    if (++depth_ > 1000) throw Error::at(where(n), "scene graph nested deeper than 1000 levels");
    if (!n.def.empty()) names_.push_back(n.def);
    struct Leave {
      int& d;
      std::vector<std::string>& names;
      bool named;
      ~Leave() {
        --d;
        if (named) names.pop_back();
      }
    } leave{depth_, names_, !n.def.empty()};
    if (n.type == "Humanoid") return humanoid(index, world);
    if (n.type == "ClothSet") return pending_.push_back({index, world});
    if (n.type == "Avatar") return externalAvatar(n, world);
    if (n.type == "ClothMaterial" || n.type == "Simulation") return;
    if (isTransformLike(n.type)) {
      const Affine local = world * transformOf(n);
      for (std::int32_t c : nodes(n, "children")) walk(c, local);
      return;
    }
    if (n.type == "Shape") {
      const std::int32_t g = node(n, "geometry");
      if (g >= 0 && at(g).hasMesh && !at(g).triangles.empty()) {
        // Named after the nearest DEF: the geometry's, the Shape's or an enclosing node's.
        std::string name = !at(g).def.empty() ? at(g).def : (names_.empty() ? std::string() : names_.back());
        if (name.empty()) name = fmt::format("{} {}", at(g).type, scene_.scenery.size() + 1);
        scene_.scenery.push_back({name, transformed(at(g), world, name)});
      }
      return;
    }
    if (n.type == "Inline") return walk(n.inlined, world);
    if (n.type == "Switch") {
      const auto choice = nodes(n, "choice");
      const auto which = static_cast<std::int64_t>(number(n, "whichChoice", -1));
      if (which >= 0 && which < static_cast<std::int64_t>(choice.size()))
        walk(choice[static_cast<std::size_t>(which)], world);
      return;
    }
    if (n.type == "LOD") {
      const auto levels = nodes(n, "level");
      if (!levels.empty()) walk(levels[0], world);
      return;
    }
    if (n.proto && n.field("children") == nullptr && n.body >= 0) return walk(n.body, world);
    for (std::int32_t c : nodes(n, "children")) walk(c, world);  // Group, Segment, Anchor, Billboard, Collision, ...
  }

  // ---- Avatars (H-Anim) ----

  void humanoid(std::int32_t index, const Affine& world) {
    if (humanoidIndex_.contains(index)) return;
    const Node& n = at(index);
    Avatar avatar;
    avatar.name = n.nameOrDef();
    if (avatar.name.empty()) avatar.name = fmt::format("humanoid {}", scene_.avatars.size() + 1);
    avatar.source = n.file;
    const Affine rootWorld = world * transformOf(n);
    const Quat rootRotation(rootWorld.rotation());
    for (std::int32_t c : nodes(n, "humanoidBody")) joint(c, rootWorld, rootRotation, -1, avatar);
    if (avatar.joints.empty())
      scene_.warnings.push_back(fmt::format("{}: Humanoid {} has no Joint", where(n).str(), avatar.name));
    humanoidIndex_[index] = static_cast<int>(scene_.avatars.size());
    scene_.avatars.push_back(std::move(avatar));
  }

  /// Walks a humanoid's body below one node: Joints become joints, Segments become the
  /// segments of the nearest enclosing joint.
  void joint(std::int32_t index, const Affine& world, const Quat& rootRotation, int parent, Avatar& avatar) {
    if (index < 0) return;
    const Node& n = at(index);
    if (n.type == "Joint") {
      const Affine local = world * transformOf(n);
      Joint j;
      j.name = n.nameOrDef();
      if (j.name.empty()) j.name = fmt::format("joint {}", avatar.joints.size() + 1);
      j.parent = parent;
      j.restCenter = local * vec3(n, "center", Vec3::Zero());
      j.restOrientation = rootRotation;
      const int self = static_cast<int>(avatar.joints.size());
      avatar.joints.push_back(j);
      for (std::int32_t c : nodes(n, "children")) joint(c, local, rootRotation, self, avatar);
      return;
    }
    if (n.type == "Segment") {
      Segment s;
      s.name = n.nameOrDef();
      if (s.name.empty()) s.name = fmt::format("segment {}", avatar.segments.size() + 1);
      s.joint = parent;
      s.mesh.name = s.name;
      for (std::int32_t c : nodes(n, "children")) collectGeometry(c, world, s.mesh);
      if (parent < 0) {
        scene_.warnings.push_back(
            fmt::format("{}: Segment {} is not inside a Joint (ignored)", where(n).str(), s.name));
        return;
      }
      // Into the joint's frame: unit scale, aligned with the humanoid's root frame.
      const RigidTransform toJoint = avatar.joints[static_cast<std::size_t>(parent)].restWorld().inverse();
      for (Vec3& p : s.mesh.positions) p = toJoint.apply(p);
      avatar.segments.push_back(std::move(s));
      return;
    }
    if (isTransformLike(n.type)) {
      const Affine local = world * transformOf(n);
      for (std::int32_t c : nodes(n, "children")) joint(c, local, rootRotation, parent, avatar);
      return;
    }
    if (n.proto && n.field("children") == nullptr) return;  // sensors and the like
    for (std::int32_t c : nodes(n, "children")) joint(c, world, rootRotation, parent, avatar);
  }

  /// All triangles below a node, in world coordinates, appended to `out`.
  void collectGeometry(std::int32_t index, const Affine& world, mesh::TriMesh& out) {
    if (index < 0) return;
    const Node& n = at(index);
    if (n.type == "Shape") {
      const std::int32_t g = node(n, "geometry");
      if (g >= 0 && at(g).hasMesh) append(out, transformed(at(g), world, out.name));
      return;
    }
    if (n.hasMesh) return append(out, transformed(n, world, out.name));
    if (n.type == "Inline") return collectGeometry(n.inlined, world, out);
    if (n.type == "Joint" || n.type == "Segment") return;  // belong to their own joint
    const Affine local = isTransformLike(n.type) ? Affine(world * transformOf(n)) : world;
    if (n.proto && n.field("children") == nullptr && n.body >= 0) return collectGeometry(n.body, world, out);
    for (std::int32_t c : nodes(n, "children")) collectGeometry(c, local, out);
  }

  void externalAvatar(const Node& n, const Affine& world) {
    ExternalAvatar a;
    a.name = n.nameOrDef();
    a.urls = strings(n, "url");
    a.jointMap = strings(n, "jointMap");
    a.cutAtJoints = strings(n, "cutAtJoints");
    a.meshes = strings(n, "meshes");
    a.drawnMeshes = strings(n, "drawnMeshes");
    a.motion = strings(n, "motion");
    a.source = where(n);
    if (a.urls.empty())
      throw Error::at(where(n),
                      fmt::format("Avatar {}: url is empty (a glTF, FBX, Collada or MakeHuman file)", a.name));
    const Affine local = world * transformOf(n);
    a.placement.rotation = Quat(local.rotation()).normalized();
    a.placement.translation = local.translation();
    a.scale = number(n, "scale", 1.0) * std::cbrt(std::abs(local.linear().determinant()));
    externalIndex_[&n] = static_cast<int>(scene_.externalAvatars.size());
    scene_.externalAvatars.push_back(std::move(a));
  }

  // ---- Garments ----

  int material(std::int32_t index) {
    if (const auto it = materialIndex_.find(index); it != materialIndex_.end()) return it->second;
    ClothMaterial m;
    if (index >= 0) {
      const Node& n = at(index);
      if (n.type != "ClothMaterial")
        throw Error::at(where(n), fmt::format("ClothSet material must be a ClothMaterial, not {}", n.type));
      m.name = n.nameOrDef();
      m.source = where(n);
      const auto get = [&](const char* field, double& value) {
        value = number(n, field, value);
        if (const Field* f = n.field(field); f != nullptr && f->line > 0) m.source.line = f->line;
      };
      // Validate field by field so an error points at the line of the value at fault.
      const SourcePos nodePos = m.source;
      for (const char* field : {"density", "thickness", "youngsModulus", "poissonRatio", "bendingStiffness", "damping",
                                "staticFriction", "dynamicFriction", "compressionScale"}) {
        double* target = fieldTarget(m, field);
        get(field, *target);
        validate(m);
        m.source = nodePos;
      }
    } else {
      m.name = "default";
    }
    const int i = static_cast<int>(scene_.materials.size());
    scene_.materials.push_back(m);
    materialIndex_[index] = i;
    return i;
  }

  static double* fieldTarget(ClothMaterial& m, std::string_view field) {
    if (field == "density") return &m.density;
    if (field == "thickness") return &m.thickness;
    if (field == "youngsModulus") return &m.youngsModulus;
    if (field == "poissonRatio") return &m.poissonRatio;
    if (field == "bendingStiffness") return &m.bendingStiffness;
    if (field == "damping") return &m.damping;
    if (field == "staticFriction") return &m.staticFriction;
    if (field == "dynamicFriction") return &m.dynamicFriction;
    return &m.compressionScale;
  }

  /// The diffuse colour of a Shape's Material (VRML97's default where the Material gives
  /// none); none for a Shape without one, or a bare IndexedFaceSet.
  std::optional<Vec3> shapeColour(std::int32_t index) const {
    const Node& shape = at(index);
    if (shape.type != "Shape") return std::nullopt;
    const std::int32_t appearance = node(shape, "appearance");
    if (appearance < 0) return std::nullopt;
    const std::int32_t material = node(at(appearance), "material");
    if (material < 0 || at(material).type != "Material") return std::nullopt;
    const Vec3 c = vec3(at(material), "diffuseColor", Vec3(0.8, 0.8, 0.8));
    // The reader holds floats: 0.7 comes as 0.69999999; four decimals are colour enough.
    const auto channel = [](double v) { return std::round(std::clamp(v, 0.0, 1.0) * 1e4) / 1e4; };
    return Vec3(channel(c.x()), channel(c.y()), channel(c.z()));
  }

  /// The IndexedFaceSet of a cloth or mask entry (itself, or a Shape's geometry).
  const Node& faceSet(std::int32_t index, const Node& clothSet, const char* field) const {
    const Node* n = &at(index);
    if (n->type == "Shape" && node(*n, "geometry") >= 0) n = &at(node(*n, "geometry"));
    if (n->type != "IndexedFaceSet")
      throw Error::at(where(clothSet, field),
                      fmt::format("ClothSet {}: {} must be an IndexedFaceSet or a Shape holding one, not {}",
                                  clothSet.nameOrDef(), field, n->type));
    return *n;
  }

  void garment(const PendingGarment& pending) {
    const Node& n = at(pending.node);
    Garment g;
    g.name = n.nameOrDef();
    if (g.name.empty()) g.name = fmt::format("garment {}", scene_.garments.size() + 1);
    g.source = where(n);
    g.mesh.name = g.name;
    const auto cloth = nodes(n, "cloth");
    if (cloth.empty())
      throw Error::at(where(n),
                      fmt::format("ClothSet {} has no cloth (an IndexedFaceSet or a Shape holding one)", g.name));
    for (std::int32_t c : cloth) {
      append(g.mesh, transformed(faceSet(c, n, "cloth"), pending.world, g.name));
      if (!g.colour) g.colour = shapeColour(c);
    }
    if (g.mesh.triangles.empty())
      throw Error::at(where(n, "cloth"), fmt::format("ClothSet {}: the cloth has no faces", g.name));
    g.material = material(node(n, "material"));
    g.maskTolerance = number(n, "maskTolerance", g.maskTolerance);
    g.bindThreshold = number(n, "bindThreshold", g.bindThreshold);
    if (!(g.maskTolerance >= 0.0))
      throw Error::at(where(n, "maskTolerance"),
                      fmt::format("ClothSet {}: maskTolerance {:g} m is negative", g.name, g.maskTolerance));
    if (!(g.bindThreshold >= 0.0))
      throw Error::at(where(n, "bindThreshold"),
                      fmt::format("ClothSet {}: bindThreshold {:g} m is negative", g.name, g.bindThreshold));
    g.selfCollision = number(n, "selfCollision", g.selfCollision);
    if (!(g.selfCollision >= 0.0) || !std::isfinite(g.selfCollision))
      throw Error::at(where(n, "selfCollision"),
                      fmt::format("ClothSet {}: selfCollision {:g} m: expected a thickness, 0 (none) or more", g.name,
                                  g.selfCollision));
    g.over = strings(n, "over");
    g.overGap = number(n, "overGap", g.overGap);
    if (!(g.overGap > 0.0) || !std::isfinite(g.overGap))
      throw Error::at(where(n, "overGap"),
                      fmt::format("ClothSet {}: overGap {:g} m: expected a gap above the garments it is worn over, more "
                                  "than 0",
                                  g.name, g.overGap));
    g.offsets = garmentOffsets(n, g.name);
    g.collidesWith = strings(n, "collidesWith");
    g.faceSamplesWith = strings(n, "faceSamplesWith");
    for (const std::string& s : g.faceSamplesWith)
      if (!g.collidesWith.empty() && std::find(g.collidesWith.begin(), g.collidesWith.end(), s) == g.collidesWith.end())
        throw Error::at(where(n, "faceSamplesWith"),
                        fmt::format("ClothSet {}: faceSamplesWith names '{}', which is not in its collidesWith",
                                    g.name, s));
    g.stitches = stitches(n, g);
    avatarOf(n, g);
    if (const std::int32_t mask = node(n, "constraintMask"); mask >= 0)
      g.maskVertices = matchMask(transformed(faceSet(mask, n, "constraintMask"), pending.world, g.name), g, n);
    scene_.garments.push_back(std::move(g));
  }

  /// The node's `offsets`, T0..T3 in m (four values, as offsetsProblem wants them); `label`
  /// names the node in the error at the field's line.
  static std::array<double, 4> fourOffsets(const Node& n, const std::string& label) {
    const std::vector<double>& v = n.field("offsets")->numbers;
    if (v.size() != 4)
      throw Error::at(where(n, "offsets"),
                      fmt::format("{}: offsets needs 4 values (T0 T1 T2 T3 in m), found {}", label, v.size()));
    const std::array<double, 4> t{v[0], v[1], v[2], v[3]};
    if (const std::string problem = offsetsProblem(t); !problem.empty())
      throw Error::at(where(n, "offsets"), fmt::format("{}: {}", label, problem));
    return t;
  }

  /// The ClothSet's own `offsets`, or none when it gives none (the Simulation node's hold).
  static std::optional<std::array<double, 4>> garmentOffsets(const Node& n, const std::string& name) {
    const Field* f = n.field("offsets");
    if (f == nullptr || f->numbers.empty()) return std::nullopt;
    return fourOffsets(n, "ClothSet " + name);
  }

  /// The ClothSet's `stitches`: pairs of cloth vertex indices.
  static std::vector<std::array<std::uint32_t, 2>> stitches(const Node& n, const Garment& g) {
    const Field* f = n.field("stitches");
    if (f == nullptr || f->numbers.empty()) return {};
    const std::vector<double>& v = f->numbers;
    if (v.size() % 2 != 0)
      throw Error::at(where(n, "stitches"),
                      fmt::format("ClothSet {}: stitches holds {} vertex indices; expected pairs (an even count)",
                                  g.name, v.size()));
    const std::size_t count = g.mesh.positions.size();
    std::vector<std::array<std::uint32_t, 2>> out;
    for (std::size_t i = 0; i < v.size(); i += 2) {
      for (std::size_t k = i; k < i + 2; ++k)
        if (!(v[k] >= 0.0 && v[k] < static_cast<double>(count)))
          throw Error::at(where(n, "stitches"),
                          fmt::format("ClothSet {}: stitch {} names vertex {}; expected a cloth vertex, 0 to {}",
                                      g.name, i / 2 + 1, v[k], count - 1));
      if (v[i] == v[i + 1])
        throw Error::at(where(n, "stitches"),
                        fmt::format("ClothSet {}: stitch {} joins vertex {} to itself; expected two vertices", g.name,
                                    i / 2 + 1, v[i]));
      out.push_back({static_cast<std::uint32_t>(v[i]), static_cast<std::uint32_t>(v[i + 1])});
    }
    return out;
  }

  /// Every garment's `over`: garments of the scene, worn by the same character, neither
  /// itself nor, through others, over itself (garments are stepped from the innermost out).
  void checkLayers() const {
    const std::vector<Garment>& all = scene_.garments;
    const auto indexOf = [&](const std::string& name) {
      for (std::size_t i = 0; i < all.size(); ++i)
        if (all[i].name == name) return static_cast<int>(i);
      return -1;
    };
    std::vector<std::vector<std::size_t>> below(all.size());  // per garment, those it is worn over
    for (std::size_t i = 0; i < all.size(); ++i) {
      const Garment& g = all[i];
      const Node& n = at(pending_[i].node);
      for (const std::string& name : g.over) {
        const int under = indexOf(name);
        if (under < 0) {
          std::vector<std::string> names;
          for (const Garment& other : all) names.push_back(other.name);
          throw Error::at(where(n, "over"), fmt::format("ClothSet {}: over names '{}', which is no garment of the "
                                                        "scene (it has: {})",
                                                        g.name, name, fmt::join(names, ", ")));
        }
        if (static_cast<std::size_t>(under) == i)
          throw Error::at(where(n, "over"), fmt::format("ClothSet {}: over names itself", g.name));
        const Garment& b = all[static_cast<std::size_t>(under)];
        if (b.avatar != g.avatar || b.externalAvatar != g.externalAvatar)
          throw Error::at(where(n, "over"),
                          fmt::format("ClothSet {}: over names '{}', which another character wears (or none): a "
                                      "garment is kept over its own character's garments only",
                                      g.name, name));
        below[i].push_back(static_cast<std::size_t>(under));
      }
    }
    // The names must not go round: garments step from the innermost out.
    const std::vector<std::size_t> round = roundOfLayers(below, layersOf(below));
    if (!round.empty()) {
      std::vector<std::string> names;
      for (const std::size_t g : round) names.push_back(all[g].name);
      throw Error::at(where(at(pending_[round.front()].node), "over"),
                      fmt::format("ClothSet {}: worn over itself through {}: the garments' over names must not go round",
                                  names.front(), fmt::join(names, " over ")));
    }
  }

  void avatarOf(const Node& n, Garment& g) {
    const std::int32_t a = node(n, "avatar");
    if (a < 0) return;
    const Node& target = at(a);
    if (target.type == "Humanoid") {
      if (!humanoidIndex_.contains(a)) humanoid(a, Affine(Eigen::Scaling(scene_.simulation.unitScale)));
      g.avatar = humanoidIndex_.at(a);
      const Avatar& avatar = scene_.avatars[static_cast<std::size_t>(g.avatar)];
      for (const std::string& s : g.collidesWith)
        if (avatar.findSegment(s) < 0)
          throw Error::at(where(n, "collidesWith"),
                          fmt::format("ClothSet {}: collidesWith names '{}', which avatar {} has no segment called",
                                      g.name, s, avatar.name));
      for (const std::string& s : g.faceSamplesWith)
        if (avatar.findSegment(s) < 0)
          throw Error::at(where(n, "faceSamplesWith"),
                          fmt::format("ClothSet {}: faceSamplesWith names '{}', which avatar {} has no segment called",
                                      g.name, s, avatar.name));
      return;
    }
    if (target.type == "Avatar") {
      if (!externalIndex_.contains(&target))
        externalAvatar(target, Affine(Eigen::Scaling(scene_.simulation.unitScale)));
      g.externalAvatar = externalIndex_.at(&target);
      return;
    }
    throw Error::at(where(n, "avatar"),
                    fmt::format("ClothSet {}: avatar must be a Humanoid or an Avatar, not {}", g.name, target.type));
  }

  /// Every garment vertex within maskTolerance of a mask vertex (paper 4.1: the mask is a
  /// subset of the cloth model); a mask vertex that matches none is an error. A uniform
  /// grid of cell size = tolerance makes this linear in the vertex counts.
  std::vector<std::uint32_t> matchMask(const mesh::TriMesh& mask, const Garment& g, const Node& n) const {
    const double tol = std::max(g.maskTolerance, 1e-9);
    const auto cellOf = [tol](const Vec3& p) {
      return std::array<long long, 3>{static_cast<long long>(std::floor(p.x() / tol)),
                                      static_cast<long long>(std::floor(p.y() / tol)),
                                      static_cast<long long>(std::floor(p.z() / tol))};
    };
    std::map<std::array<long long, 3>, std::vector<std::uint32_t>> grid;
    for (std::uint32_t i = 0; i < g.mesh.positions.size(); ++i) grid[cellOf(g.mesh.positions[i])].push_back(i);
    std::set<std::uint32_t> matched;
    for (std::size_t m = 0; m < mask.positions.size(); ++m) {
      const Vec3& p = mask.positions[m];
      const auto c = cellOf(p);
      bool any = false;
      for (long long dx = -1; dx <= 1; ++dx)
        for (long long dy = -1; dy <= 1; ++dy)
          for (long long dz = -1; dz <= 1; ++dz) {
            const auto it = grid.find({c[0] + dx, c[1] + dy, c[2] + dz});
            if (it == grid.end()) continue;
            for (std::uint32_t v : it->second)
              if ((g.mesh.positions[v] - p).norm() <= g.maskTolerance) {
                matched.insert(v);
                any = true;
              }
          }
      if (!any) {
        double nearest = std::numeric_limits<double>::infinity();
        for (const Vec3& q : g.mesh.positions) nearest = std::min(nearest, (q - p).norm());
        throw Error::at(where(n, "constraintMask"),
                        fmt::format("ClothSet {}: constraintMask vertex {} at ({:.4g} {:.4g} {:.4g}) m matches no "
                                    "cloth vertex within maskTolerance {:g} m (the nearest is {:.3g} m away)",
                                    g.name, m, p.x(), p.y(), p.z(), g.maskTolerance, nearest));
      }
    }
    return {matched.begin(), matched.end()};
  }

  const Document& doc_;
  Scene scene_;
  int depth_ = 0;
  std::vector<std::string> names_;  ///< DEF names of the nodes the walk is inside
  std::vector<PendingGarment> pending_;
  std::map<std::int32_t, int> humanoidIndex_;
  std::map<const Node*, int> externalIndex_;
  std::map<std::int32_t, int> materialIndex_;
};

}  // namespace

Scene buildScene(const formats::vrml::Document& document) { return Builder(document).build(); }

}  // namespace drape::scene
