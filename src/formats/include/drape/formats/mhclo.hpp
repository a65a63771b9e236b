#pragma once
// MakeHuman clothes fitting files (.mhclo, text): how each vertex of a garment's OBJ sits on
// the hm08 base mesh, so that the garment can be refitted to the body it will be worn on
// (the body MakeHuman's own OBJ was exported on may have another shape). Syntax only; the
// fit itself is scene/garment_fit.hpp.
//   obj_file NAME                  the garment's mesh, beside the .mhclo
//   x_scale A B D                  offsets along x scale with |base[A].x - base[B].x| / D
//   y_scale, z_scale               likewise
//   verts 0                        then one line per garment vertex, in the OBJ's order:
//     A B C wa wb wc ox oy oz      barycentric weights on base vertices A, B, C + offset
//     A                            exactly at base vertex A
//   delete_verts ...               ends the vertex list (the body vertices the garment hides)
// Other keywords (uuid, tag, material, z_depth, ...) are skipped.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "drape/core/math.hpp"

namespace drape::formats {

struct MhcloScale {
  std::uint32_t a = 0, b = 0;  ///< base vertices whose distance along the axis is measured
  double reference = 1.0;      ///< that distance on the body the offsets were made for (base units)
};

struct MhcloVertex {
  std::array<std::uint32_t, 3> base{};      ///< base-mesh vertex indices (0-based, `v` line order)
  std::array<double, 3> weight{1, 0, 0};    ///< barycentric weights
  Vec3 offset = Vec3::Zero();               ///< base units, scaled per axis by MhcloScale
};

struct Mhclo {
  std::string source;
  std::string name;
  std::string objFile;      ///< as written in the file; may be empty
  std::string baseMesh;     ///< e.g. "hm08"
  std::array<MhcloScale, 3> scale{};  ///< x, y, z
  bool hasScale[3] = {false, false, false};
  std::vector<MhcloVertex> vertices;
  std::uint32_t largestBaseIndex = 0;
};

/// Parses .mhclo text; errors are drape::Error "name:line:column: what was expected".
[[nodiscard]] Mhclo parseMhclo(std::string_view text, const std::string& name);
/// Reads and parses a .mhclo file.
[[nodiscard]] Mhclo readMhclo(const std::string& path);

}  // namespace drape::formats
