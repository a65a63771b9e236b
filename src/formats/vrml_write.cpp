// VRML97 writer for animated results and the sampler that reads such animation back
// (see vrml_write.hpp).

#include "drape/formats/vrml_write.hpp"

#include <cmath>
#include <cstdio>
#include <memory>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/formats/vrml_transform.hpp"

namespace drape::formats::vrml {
namespace {

/// A VRML97 identifier from any name: letters, digits and '_' kept, the rest '_', never a
/// leading digit, made unique with a suffix.
std::string defName(const std::string& name, const std::string& fallback, std::vector<std::string>& used) {
  std::string s;
  for (char c : name) s += (std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_') ? c : '_';
  if (s.empty()) s = fallback;
  if (std::isdigit(static_cast<unsigned char>(s[0])) != 0) s = "_" + s;
  std::string unique = s;
  for (int i = 2; std::find(used.begin(), used.end(), unique) != used.end(); ++i) unique = fmt::format("{}_{}", s, i);
  used.push_back(unique);
  return unique;
}

struct File {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f;
  std::string path;
  template <typename... Args>
  void print(fmt::format_string<Args...> format, Args&&... args) {
    fmt::print(f.get(), format, std::forward<Args>(args)...);
  }
};

void keys(File& out, std::size_t frames) {
  out.print("    key [");
  for (std::size_t i = 0; i < frames; ++i)
    out.print(" {:.7g}", frames == 1 ? 0.0 : static_cast<double>(i) / static_cast<double>(frames - 1));
  out.print(" ]\n");
}

void triangles(File& out, const std::vector<mesh::Triangle>& tris, const char* indent) {
  out.print("{}coordIndex [\n", indent);
  for (const mesh::Triangle& t : tris) out.print("{}  {} {} {} -1\n", indent, t[0], t[1], t[2]);
  out.print("{}]\n", indent);
}

void garment(File& out, const GarmentTrack& g, const std::string& def) {
  const std::size_t n = g.frames.front().size();
  out.print(
      "DEF {} Shape {{\n  appearance Appearance {{ material Material {{ diffuseColor {:.3g} {:.3g} {:.3g} }} }}\n", def,
      g.color.x(), g.color.y(), g.color.z());
  out.print(
      "  geometry IndexedFaceSet {{\n    solid FALSE\n    creaseAngle 1.0\n    coord DEF {}_coord Coordinate {{\n      "
      "point [\n",
      def);
  for (const Vec3& p : g.frames.front()) out.print("        {:.7g} {:.7g} {:.7g}\n", p.x(), p.y(), p.z());
  out.print("      ]\n    }}\n");
  triangles(out, g.triangles, "    ");
  out.print("  }}\n}}\n");
  out.print("DEF {}_motion CoordinateInterpolator {{\n", def);
  keys(out, g.frames.size());
  out.print("    keyValue [\n");
  for (const auto& frame : g.frames) {
    if (frame.size() != n)
      throw Error(fmt::format("{}: garment {}: frames have different vertex counts ({} and {})", out.path, g.name, n,
                              frame.size()));
    for (const Vec3& p : frame) out.print("      {:.7g} {:.7g} {:.7g}\n", p.x(), p.y(), p.z());
  }
  out.print("    ]\n}}\n");
}

void joint(File& out, const JointTrack& j, const std::string& def) {
  const RigidTransform& first = j.frames.front();
  const Eigen::AngleAxisd r0(first.rotation);
  out.print(
      "DEF {} Transform {{\n  translation {:.7g} {:.7g} {:.7g}\n  rotation {:.7g} {:.7g} {:.7g} {:.7g}\n  children [\n",
      def, first.translation.x(), first.translation.y(), first.translation.z(), r0.axis().x(), r0.axis().y(),
      r0.axis().z(), r0.angle());
  for (const mesh::TriMesh& m : j.segments) {
    out.print("    Shape {{\n      appearance Appearance {{ material Material {{ diffuseColor 0.75 0.7 0.65 }} }}\n");
    out.print("      geometry IndexedFaceSet {{\n        coord Coordinate {{\n          point [\n");
    for (const Vec3& p : m.positions) out.print("            {:.7g} {:.7g} {:.7g}\n", p.x(), p.y(), p.z());
    out.print("          ]\n        }}\n");
    triangles(out, m.triangles, "        ");
    out.print("      }}\n    }}\n");
  }
  out.print("  ]\n}}\n");
  out.print("DEF {}_position PositionInterpolator {{\n", def);
  keys(out, j.frames.size());
  out.print("    keyValue [\n");
  for (const RigidTransform& t : j.frames)
    out.print("      {:.7g} {:.7g} {:.7g}\n", t.translation.x(), t.translation.y(), t.translation.z());
  out.print("    ]\n}}\n");
  out.print("DEF {}_orientation OrientationInterpolator {{\n", def);
  keys(out, j.frames.size());
  out.print("    keyValue [\n");
  for (const RigidTransform& t : j.frames) {
    const Eigen::AngleAxisd r(t.rotation.normalized());
    out.print("      {:.7g} {:.7g} {:.7g} {:.7g}\n", r.axis().x(), r.axis().y(), r.axis().z(), r.angle());
  }
  out.print("    ]\n}}\n");
}

}  // namespace

std::string quotedString(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

void writeAnimation(const std::string& path, const Animation& animation) {
  std::size_t frames = 0;
  for (const GarmentTrack& g : animation.garments) frames = std::max(frames, g.frames.size());
  for (const JointTrack& j : animation.joints) frames = std::max(frames, j.frames.size());
  if (frames == 0) throw Error(fmt::format("{}: nothing to write (no frames)", path));
  for (const GarmentTrack& g : animation.garments)
    if (g.frames.size() != frames)
      throw Error(fmt::format("{}: garment {} has {} frames, others {}", path, g.name, g.frames.size(), frames));
  for (const JointTrack& j : animation.joints)
    if (j.frames.size() != frames)
      throw Error(fmt::format("{}: joint {} has {} frames, others {}", path, j.name, j.frames.size(), frames));
  if (!(animation.frameRate > 0.0))
    throw Error(fmt::format("{}: frame rate {:g} must be positive", path, animation.frameRate));

  File out{{std::fopen(path.c_str(), "w"), &std::fclose}, path};
  if (!out.f) throw Error(fmt::format("{}: cannot write", path));
  const double cycle = frames > 1 ? static_cast<double>(frames - 1) / animation.frameRate : 1.0 / animation.frameRate;
  out.print("#VRML V2.0 utf8\n# Written by drape: {} frames at {:g} frames/s. Positions in metres.\n\n", frames,
            animation.frameRate);
  out.print("WorldInfo {{ title \"drape result\" info [ \"frames {}\" \"frameRate {:g}\" ] }}\n", frames,
            animation.frameRate);
  out.print("NavigationInfo {{ type [ \"EXAMINE\" \"ANY\" ] }}\n");
  out.print("DEF Clock TimeSensor {{ cycleInterval {:.9g} loop TRUE }}\n\n", cycle);
  std::vector<std::string> used{"Clock"};
  std::vector<std::string> routes;
  for (std::size_t i = 0; i < animation.garments.size(); ++i) {
    const GarmentTrack& g = animation.garments[i];
    const std::string def = defName(g.name, fmt::format("garment_{}", i + 1), used);
    garment(out, g, def);
    routes.push_back(fmt::format("ROUTE Clock.fraction_changed TO {}_motion.set_fraction", def));
    routes.push_back(fmt::format("ROUTE {}_motion.value_changed TO {}_coord.set_point", def, def));
  }
  for (std::size_t i = 0; i < animation.joints.size(); ++i) {
    const JointTrack& j = animation.joints[i];
    const std::string def = defName(j.name, fmt::format("joint_{}", i + 1), used);
    joint(out, j, def);
    for (const char* kind : {"position", "orientation"}) {
      routes.push_back(fmt::format("ROUTE Clock.fraction_changed TO {}_{}.set_fraction", def, kind));
      routes.push_back(fmt::format("ROUTE {}_{}.value_changed TO {}.set_{}", def, kind, def,
                                   kind[0] == 'p' ? "translation" : "rotation"));
    }
  }
  out.print("\n");
  for (const std::string& r : routes) out.print("{}\n", r);
  if (std::fflush(out.f.get()) != 0 || std::ferror(out.f.get()) != 0)
    throw Error(fmt::format("{}: write failed", path));
}

std::vector<double> sampleAnimatedField(const Document& document, std::int32_t node, const std::string& field,
                                        double time) {
  const auto at = [&](std::int32_t i) -> const Node* {
    return i >= 0 && static_cast<std::size_t>(i) < document.nodes.size() ? &document.nodes[static_cast<std::size_t>(i)]
                                                                         : nullptr;
  };
  const Node* target = at(node);
  const Field* f = target != nullptr ? target->field(field) : nullptr;
  const Node* interpolator = f != nullptr ? at(f->routeFromNode) : nullptr;
  if (interpolator == nullptr) return {};
  const Field* key = interpolator->field("key");
  const Field* keyValue = interpolator->field("keyValue");
  const Field* fraction = interpolator->field("set_fraction");
  if (key == nullptr || keyValue == nullptr || key->numbers.empty()) return {};
  const std::size_t stride = keyValue->numbers.size() / key->numbers.size();
  if (stride == 0) return {};

  // Time -> fraction through the TimeSensor (looping or not); no sensor: time is the fraction.
  double t = time;
  if (const Node* sensor = fraction != nullptr ? at(fraction->routeFromNode) : nullptr) {
    const double cycle =
        sensor->field("cycleInterval") != nullptr ? sensor->field("cycleInterval")->numbers.at(0) : 1.0;
    const bool loop = sensor->field("loop") != nullptr && sensor->field("loop")->numbers.at(0) != 0.0;
    t = cycle > 0 ? time / cycle : 0.0;
    if (loop && t > 1.0) t -= std::floor(t);
  }
  const std::vector<double>& k = key->numbers;
  t = std::clamp(t, k.front(), k.back());
  std::size_t i = 0;
  while (i + 2 < k.size() && t > k[i + 1]) ++i;
  const std::size_t j = std::min(i + 1, k.size() - 1);
  const double span = k[j] - k[i];
  const double w = span > 0 ? (t - k[i]) / span : 0.0;
  const double* a = keyValue->numbers.data() + i * stride;
  const double* b = keyValue->numbers.data() + j * stride;
  if (interpolator->type == "OrientationInterpolator" && stride == 4) {
    // VRML97: along the shortest arc between the two orientations, at constant speed.
    const Quat qa(rotationOf(a, 4)), qb(rotationOf(b, 4));
    const Eigen::AngleAxisd r(qa.slerp(w, qb));
    return {r.axis().x(), r.axis().y(), r.axis().z(), r.angle()};
  }
  std::vector<double> out(stride);
  for (std::size_t c = 0; c < stride; ++c) out[c] = (1.0 - w) * a[c] + w * b[c];
  return out;
}

}  // namespace drape::formats::vrml
