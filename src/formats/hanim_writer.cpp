#include "drape/formats/hanim_writer.hpp"

#include <cmath>
#include <fstream>
#include <functional>
#include <set>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/formats/vrml_write.hpp"

namespace drape::formats {
namespace {

// H-Anim 1.1 interfaces (ISO/IEC 19774 Annex: VRML97 PROTOs), with simple bodies.
constexpr const char* kProtos = R"(PROTO Joint [
  exposedField SFVec3f center 0 0 0
  exposedField MFNode children []
  exposedField MFFloat llimit []
  exposedField SFRotation limitOrientation 0 0 1 0
  exposedField SFString name ""
  exposedField SFRotation rotation 0 0 1 0
  exposedField SFVec3f scale 1 1 1
  exposedField SFRotation scaleOrientation 0 0 1 0
  exposedField MFFloat stiffness [0 0 0]
  exposedField SFVec3f translation 0 0 0
  exposedField MFFloat ulimit []
] {
  Transform {
    children IS children
    translation IS translation
    rotation IS rotation
    scale IS scale
    scaleOrientation IS scaleOrientation
    center IS center
  }
}

PROTO Segment [
  field SFVec3f bboxCenter 0 0 0
  field SFVec3f bboxSize -1 -1 -1
  exposedField SFVec3f centerOfMass 0 0 0
  exposedField MFNode children []
  exposedField SFNode coord NULL
  exposedField MFNode displacers []
  exposedField SFFloat mass 0
  exposedField MFFloat momentsOfInertia [0 0 0 0 0 0 0 0 0]
  exposedField SFString name ""
  eventIn MFNode addChildren
  eventIn MFNode removeChildren
] {
  Group {
    addChildren IS addChildren
    bboxCenter IS bboxCenter
    bboxSize IS bboxSize
    children IS children
    removeChildren IS removeChildren
  }
}

PROTO Humanoid [
  field SFVec3f bboxCenter 0 0 0
  field SFVec3f bboxSize -1 -1 -1
  exposedField SFVec3f center 0 0 0
  exposedField MFNode humanoidBody []
  exposedField MFString info []
  exposedField MFNode joints []
  exposedField SFString name ""
  exposedField SFRotation rotation 0 0 1 0
  exposedField SFVec3f scale 1 1 1
  exposedField SFRotation scaleOrientation 0 0 1 0
  exposedField MFNode segments []
  exposedField MFNode sites []
  exposedField SFVec3f translation 0 0 0
  exposedField SFString version "1.1"
  exposedField MFNode viewpoints []
] {
  Transform {
    bboxCenter IS bboxCenter
    bboxSize IS bboxSize
    center IS center
    rotation IS rotation
    scale IS scale
    scaleOrientation IS scaleOrientation
    translation IS translation
    children [
      Group { children IS viewpoints }
      Group { children IS humanoidBody }
    ]
  }
}
)";

void writeSegment(std::string& out, const HanimSegmentData& s, const std::string& def, const std::string& indent) {
  out += fmt::format("{}DEF {} Segment {{\n{}  name {}\n{}  children [\n", indent, def, indent, vrml::quotedString(s.name), indent);
  out += fmt::format("{}    Shape {{\n{}      appearance Appearance {{ material Material {{ diffuseColor 0.8 0.7 0.6 }} }}\n", indent, indent);
  out += fmt::format("{}      geometry IndexedFaceSet {{\n{}        solid TRUE\n{}        coord Coordinate {{\n{}          point [\n",
                     indent, indent, indent, indent);
  for (const Vec3& p : s.points) out += fmt::format("{}            {:.6g} {:.6g} {:.6g},\n", indent, p.x(), p.y(), p.z());
  out += fmt::format("{}          ]\n{}        }}\n{}        coordIndex [\n", indent, indent, indent);
  for (const mesh::Triangle& t : s.triangles) out += fmt::format("{}          {} {} {} -1,\n", indent, t[0], t[1], t[2]);
  out += fmt::format("{}        ]\n{}      }}\n{}    }}\n{}  ]\n{}}}\n", indent, indent, indent, indent, indent);
}

// The motion's nodes and ROUTEs after the Humanoid: a joint whose translation stays within a
// micrometre of zero in every frame gets no PositionInterpolator (its field keeps 0 0 0).
// `unique` makes a DEF name no other node has.
std::string motionText(const HanimMotion& m, const std::vector<std::string>& jointDefs,
                       const std::function<std::string(const std::string&)>& unique) {
  const std::size_t frames = m.frames.size();
  if (frames == 0) throw Error(fmt::format("H-Anim motion '{}': no frames", m.name));
  if (!(m.frameRate > 0.0) || !std::isfinite(m.frameRate))
    throw Error(fmt::format("H-Anim motion '{}': frame rate {:g} must be positive", m.name, m.frameRate));
  for (std::size_t f = 0; f < frames; ++f)
    if (m.frames[f].size() != jointDefs.size())
      throw Error(fmt::format("H-Anim motion '{}': frame {} has {} joints, the humanoid {}", m.name, f,
                              m.frames[f].size(), jointDefs.size()));
  const double cycle = frames > 1 ? static_cast<double>(frames - 1) / m.frameRate : 1.0 / m.frameRate;
  std::string keys = "    key [";
  for (std::size_t f = 0; f < frames; ++f)
    keys += fmt::format(" {:.9g}", frames > 1 ? static_cast<double>(f) / static_cast<double>(frames - 1) : 0.0);
  keys += " ]\n";
  const std::string clock = unique("hanim_clock");
  std::string out = fmt::format("\n# motion {}: {} frames at {:g} frames/s\nDEF {} TimeSensor {{ cycleInterval {:.9g} loop TRUE }}\n",
                                vrml::quotedString(m.name), frames, m.frameRate, clock, cycle);
  std::string routes;
  for (std::size_t j = 0; j < jointDefs.size(); ++j) {
    const std::string& def = jointDefs[j];
    const std::string rotation = unique(def + "_rotation");
    out += fmt::format("DEF {} OrientationInterpolator {{\n{}    keyValue [\n", rotation, keys);
    for (std::size_t f = 0; f < frames; ++f) {
      const Eigen::AngleAxisd r(m.frames[f][j].rotation.normalized());
      out += fmt::format("      {:.7g} {:.7g} {:.7g} {:.7g}\n", r.axis().x(), r.axis().y(), r.axis().z(), r.angle());
    }
    out += "    ]\n}\n";
    routes += fmt::format("ROUTE {}.fraction_changed TO {}.set_fraction\n", clock, rotation);
    routes += fmt::format("ROUTE {}.value_changed TO {}.set_rotation\n", rotation, def);
    bool moves = false;
    for (std::size_t f = 0; f < frames && !moves; ++f) moves = m.frames[f][j].translation.norm() > 1e-6;
    if (!moves) continue;
    const std::string translation = unique(def + "_translation");
    out += fmt::format("DEF {} PositionInterpolator {{\n{}    keyValue [\n", translation, keys);
    for (std::size_t f = 0; f < frames; ++f) {
      const Vec3& t = m.frames[f][j].translation;
      out += fmt::format("      {:.7g} {:.7g} {:.7g}\n", t.x(), t.y(), t.z());
    }
    out += "    ]\n}\n";
    routes += fmt::format("ROUTE {}.fraction_changed TO {}.set_fraction\n", clock, translation);
    routes += fmt::format("ROUTE {}.value_changed TO {}.set_translation\n", translation, def);
  }
  return out + "\n" + routes;
}

}  // namespace

std::string vrmlIdentifier(const std::string& name) {
  // VRML97 IdFirstChar excludes digits, '+', '-'; IdRestChars exclude control characters,
  // space, quotes, '#', ',', '.', '[', ']', '\\', '{', '}'.
  std::string id;
  for (char c : name) {
    const auto u = static_cast<unsigned char>(c);
    const bool bad = u <= 0x20 || u == 0x7f || c == '"' || c == '\'' || c == '#' || c == ',' || c == '.' || c == '[' ||
                     c == ']' || c == '\\' || c == '{' || c == '}';
    id += bad ? '_' : c;
  }
  if (id.empty() || std::isdigit(static_cast<unsigned char>(id[0])) || id[0] == '+' || id[0] == '-') id = "_" + id;
  return id;
}

std::string hanimText(const HanimHumanoidData& h) {
  std::string out = "#VRML V2.0 utf8\n# H-Anim 1.1 humanoid written by drape\n\n";
  out += kProtos;
  const std::size_t n = h.joints.size();
  std::vector<std::vector<std::size_t>> children(n);
  std::vector<std::size_t> roots;
  for (std::size_t j = 0; j < n; ++j) {
    const int p = h.joints[j].parent;
    if (p >= 0 && static_cast<std::size_t>(p) < j) children[static_cast<std::size_t>(p)].push_back(j);
    else roots.push_back(j);
  }
  // DEF names must be unique: the humanoid and its joints are hanim_<name>, segments
  // hanim_<name>_segment, a motion's nodes hanim_clock and hanim_<joint>_rotation and
  // _translation, with a number appended where sanitised names collide.
  std::set<std::string> taken;
  auto unique = [&](std::string id) {
    std::string candidate = id;
    for (int k = 2; !taken.insert(candidate).second; ++k) candidate = fmt::format("{}_{}", id, k);
    return candidate;
  };
  const std::string humanoidDef = unique("hanim_" + vrmlIdentifier(h.name));
  std::vector<std::string> jointDefs(n);
  std::vector<std::vector<std::string>> segmentDefs(n);
  for (std::size_t j = 0; j < n; ++j) jointDefs[j] = unique("hanim_" + vrmlIdentifier(h.joints[j].name));
  for (std::size_t j = 0; j < n; ++j)
    for (const HanimSegmentData& s : h.joints[j].segments) segmentDefs[j].push_back(unique("hanim_" + vrmlIdentifier(s.name) + "_segment"));
  auto jointDef = [&](std::size_t j) { return jointDefs[j]; };
  auto segmentDef = [&](std::size_t j, std::size_t s) { return segmentDefs[j][s]; };
  std::vector<std::string> jointUses, segmentUses;
  // Depth-first with an explicit stack: open each joint, write its segments, then its children.
  std::string body;
  struct Item {
    std::size_t joint;
    bool close;
    int depth;
  };
  std::vector<Item> stack;
  for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back({*it, false, 2});
  while (!stack.empty()) {
    const Item item = stack.back();
    stack.pop_back();
    const std::string indent(static_cast<std::size_t>(item.depth) * 2, ' ');
    if (item.close) {
      body += fmt::format("{}  ]\n{}}}\n", indent, indent);
      continue;
    }
    const HanimJointData& j = h.joints[item.joint];
    jointUses.push_back(jointDef(item.joint));
    body += fmt::format("{}DEF {} Joint {{\n{}  name {}\n{}  center {:.7g} {:.7g} {:.7g}\n{}  children [\n", indent,
                        jointDef(item.joint), indent, vrml::quotedString(j.name), indent, j.center.x(), j.center.y(), j.center.z(), indent);
    for (std::size_t s = 0; s < j.segments.size(); ++s) {
      segmentUses.push_back(segmentDef(item.joint, s));
      writeSegment(body, j.segments[s], segmentDef(item.joint, s), indent + "    ");
    }
    stack.push_back({item.joint, true, item.depth});
    for (auto c = children[item.joint].rbegin(); c != children[item.joint].rend(); ++c) stack.push_back({*c, false, item.depth + 2});
  }
  out += fmt::format("\nDEF {} Humanoid {{\n  name {}\n  version \"1.1\"\n  info [", humanoidDef, vrml::quotedString(h.name));
  for (std::size_t i = 0; i < h.info.size(); ++i) out += (i ? ", " : " ") + vrml::quotedString(h.info[i]);
  out += " ]\n  humanoidBody [\n" + body + "  ]\n  joints [\n";
  for (const std::string& u : jointUses) out += "    USE " + u + "\n";
  out += "  ]\n  segments [\n";
  for (const std::string& u : segmentUses) out += "    USE " + u + "\n";
  out += "  ]\n}\n";
  if (h.motion) out += motionText(*h.motion, jointDefs, unique);
  return out;
}

void writeHanim(const std::string& path, const HanimHumanoidData& humanoid) {
  std::ofstream file(path, std::ios::binary);
  if (!file) throw Error(fmt::format("{}: cannot be written", path));
  file << hanimText(humanoid);
  if (!file) throw Error(fmt::format("{}: writing failed", path));
}

}  // namespace drape::formats
