#pragma once
// Pieces of the VRML97 scene files that `drape make-skirt` and `drape make-scene` write.

#include <array>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ostream.h>
#include <fmt/ranges.h>

#include "drape/cloth/material.hpp"
#include "drape/core/error.hpp"
#include "drape/formats/vrml_write.hpp"
#include "drape/mesh/trimesh.hpp"
#include "stitch_gaps.hpp"

namespace drape::cli {

/// An MFString field's line of an Avatar node (`  NAME [ "A", "B" ]`), or "" for none.
inline std::string stringsField(const std::string& name, const std::vector<std::string>& values) {
  if (values.empty()) return "";
  std::vector<std::string> quoted;
  for (const std::string& v : values) quoted.push_back(formats::vrml::quotedString(v));
  return fmt::format("  {} [ {} ]\n", name, fmt::join(quoted, ", "));
}

/// The integrator a written scene's Simulation node names (`--integrator`,
/// `--implicit-tolerance` of make-skirt and make-scene).
struct SceneIntegrator {
  cloth::IntegratorKind kind = cloth::IntegratorKind::SymplecticEuler;
  double implicitTolerance = 1e-3;

  [[nodiscard]] bool implicit() const { return kind == cloth::IntegratorKind::BackwardEuler; }
  /// The node's lines: the integrator's name and, for backward Euler, its solves' tolerance.
  [[nodiscard]] std::string fields() const {
    std::string text = fmt::format("  integrator \"{}\"\n", cloth::integratorName(kind));
    if (implicit()) text += fmt::format("  implicitTolerance {:g}\n", implicitTolerance);
    return text;
  }
  /// Adds the two options to `app`; `implicitSubsteps` says what backward Euler's substeps
  /// default to.
  void addOptions(CLI::App& app, const std::string& implicitSubsteps) {
    app.add_option_function<std::string>(
        "--integrator", [this](const std::string& name) { kind = cloth::parseIntegrator(name); },
        "The scene's integrator: symplectic-euler (default), forward-euler, backward-euler (implicit: no mass "
        "added, bending every substep, " + implicitSubsteps + ") or runge-kutta-4 (four force evaluations per "
        "substep, bending in each, as few substeps as its stability bound allows, with mass scaling aimed at "
        "that bound)");
    app.add_option("--implicit-tolerance", implicitTolerance,
                   "backward-euler: the residual at which each substep's solve stops, written as the scene's "
                   "implicitTolerance")
        ->capture_default_str()
        ->check(CLI::Range(1e-12, 0.999));
  }
  /// Throws drape::Error when `app` was given a tolerance for an integrator that solves nothing.
  void check(const CLI::App& app) const {
    if (app.count("--implicit-tolerance") > 0 && !implicit())
      throw Error(fmt::format("--implicit-tolerance applies to --integrator backward-euler, not {}",
                              cloth::integratorName(kind)));
  }
};

/// The coord and coordIndex fields of an IndexedFaceSet, one vertex or triangle per line.
inline void writeIndexedFaceSet(std::ostream& os, const mesh::TriMesh& m, const std::string& indent) {
  fmt::print(os, "{}coord Coordinate {{ point [\n", indent);
  for (const Vec3& p : m.positions) fmt::print(os, "{}  {:.5f} {:.5f} {:.5f},\n", indent, p.x(), p.y(), p.z());
  fmt::print(os, "{}] }}\n{}coordIndex [\n", indent, indent);
  for (const auto& t : m.triangles) fmt::print(os, "{}  {} {} {} -1,\n", indent, t[0], t[1], t[2]);
  fmt::print(os, "{}]\n", indent);
}

/// A ClothMaterial node with the material's values (and `name`, unless ""), its fields
/// indented by `indent` and two spaces, its closing brace by `indent` (no newline after it).
inline std::string materialNode(const cloth::Material& m, const std::string& indent, const std::string& name = "") {
  return fmt::format("ClothMaterial {{\n{9}{0}  density {1:g}\n{0}  thickness {2:g}\n{0}  youngsModulus {3:g}\n"
                     "{0}  poissonRatio {4:g}\n{0}  damping {5:g}\n{0}  staticFriction {6:g}\n{0}  dynamicFriction {7:g}\n"
                     "{0}  compressionScale {8:g}\n{0}}}",
                     indent, m.density_kg_m3, m.thickness_m, m.youngsModulus_Pa, m.poissonRatio, m.damping_s,
                     m.staticFriction, m.dynamicFriction, m.compressionScale,
                     name.empty() ? "" : fmt::format("{}  name \"{}\"\n", indent, name));
}

/// A ClothMaterial node named Knit with the material's values.
inline void writeMaterial(std::ostream& os, const cloth::Material& m) {
  fmt::print(os, "DEF Knit {}\n\n", materialNode(m, ""));
}

/// What a ClothSet node says: the garment, its mask and its fields as `drape make-skirt` and
/// `drape make-scene` write them.
struct ClothSetText {
  std::string def;                       ///< its DEF name, or "" for none
  std::string name;                      ///< its name field, or "" (its DEF name names it)
  Vec3 colour{0.7, 0.15, 0.2};           ///< its Shape's diffuse colour
  std::string meshDef;                   ///< the DEF name of its IndexedFaceSet, or ""
  const mesh::TriMesh* cloth = nullptr;  ///< in the scene's file units
  const mesh::TriMesh* mask = nullptr;   ///< in the scene's file units
  std::string material = "USE Knit";     ///< the material field's value
  std::string avatar = "Body";           ///< the DEF name of the avatar that wears it
  std::vector<std::string> collidesWith;
  std::vector<std::string> faceSamplesWith;
  StitchPairs stitches;
  double selfCollision_m = 0.0;  ///< 0: not written
  std::vector<std::string> over;  ///< the garments it is worn over; none: not written
  double overGap_m = 0.004;       ///< written with `over`
  std::optional<std::array<double, 4>> offsets;  ///< its own T0..T3, m; none: not written
  double bindThreshold_m = 0.04;
};

inline void writeClothSet(std::ostream& os, const ClothSetText& c) {
  fmt::print(os, "{}ClothSet {{\n", c.def.empty() ? "" : "DEF " + c.def + " ");
  if (!c.name.empty()) fmt::print(os, "  name \"{}\"\n", c.name);
  fmt::print(os,
             "  cloth Shape {{\n    appearance Appearance {{ material Material {{ diffuseColor {:g} {:g} {:g} }} }}\n"
             "    geometry {}IndexedFaceSet {{\n      solid FALSE\n",
             c.colour.x(), c.colour.y(), c.colour.z(), c.meshDef.empty() ? "" : "DEF " + c.meshDef + " ");
  writeIndexedFaceSet(os, *c.cloth, "      ");
  fmt::print(os, "    }}\n  }}\n  constraintMask IndexedFaceSet {{\n");
  writeIndexedFaceSet(os, *c.mask, "    ");
  fmt::print(os, "  }}\n  material {}\n  avatar USE {}\n", c.material, c.avatar);
  fmt::print(os, "  collidesWith [ \"{}\" ]\n", fmt::join(c.collidesWith, "\", \""));
  if (!c.faceSamplesWith.empty())
    fmt::print(os, "  faceSamplesWith [ \"{}\" ]\n", fmt::join(c.faceSamplesWith, "\", \""));
  if (!c.stitches.empty()) {
    fmt::print(os, "  stitches [");
    for (std::size_t i = 0; i < c.stitches.size(); ++i)
      fmt::print(os, "{}{} {}{}", i % 8 == 0 ? "\n    " : " ", c.stitches[i][0], c.stitches[i][1],
                 i + 1 < c.stitches.size() ? "," : "");
    fmt::print(os, "\n  ]\n");
  }
  if (c.selfCollision_m > 0) fmt::print(os, "  selfCollision {:g}\n", c.selfCollision_m);
  if (!c.over.empty()) fmt::print(os, "  over [ \"{}\" ]\n  overGap {:g}\n", fmt::join(c.over, "\", \""), c.overGap_m);
  if (c.offsets) {
    const auto& t = *c.offsets;
    fmt::print(os, "  offsets [ {:g} {:g} {:g} {:g} ]\n", t[0], t[1], t[2], t[3]);
  }
  fmt::print(os, "  maskTolerance 0.0005\n  bindThreshold {:.3f}\n}}\n", c.bindThreshold_m);
}

/// Creates the scene's directory (`--out`) and returns the Avatar url to write: `avatarUrl`
/// if given, else the avatar's path relative to that directory.
inline std::string prepareSceneDir(const std::string& out, const std::string& avatar, const std::string& avatarUrl) {
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) throw Error(fmt::format("--out {}: cannot create the directory ({})", out, ec.message()));
  if (!avatarUrl.empty()) return avatarUrl;
  return std::filesystem::relative(std::filesystem::absolute(avatar), std::filesystem::absolute(out)).string();
}

}  // namespace drape::cli
