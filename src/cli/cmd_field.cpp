// `drape field INPUT --voxel SIZE --out DIR`: builds the distance field of each body part of
// INPUT (an OBJ mesh now; any input that yields named parts can feed buildAndReport), prints
// its figures and writes PNG slices through three axes: the signed distance as a heat map
// with the surface, and the Voronoi normals as colours.
// `drape field MESH --dims NX NY NZ --border B --json`: one field of exactly those
// dimensions, DVDP measured against the exact transform, as JSON.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <fmt/core.h>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#include <stb/stb_image_write.h>

#include "command.hpp"
#include "drape/core/error.hpp"
#include "drape/core/files.hpp"
#include "drape/field/distance_field.hpp"
#include "drape/formats/obj.hpp"
#include "drape/formats/units.hpp"
#include "field_measure.hpp"

namespace drape::cli {
namespace {

/// A body part to build a field for: its name and its mesh in its local frame (m).
struct NamedPart {
  std::string name;
  mesh::TriMesh mesh;
};

std::vector<NamedPart> loadParts(const std::string& path, const std::string& units, const std::string& part) {
  const std::string ext = lowerExtension(path);
  if (ext != ".obj") throw Error(path + ": drape field reads OBJ meshes (.obj)");
  formats::ObjReadOptions options;
  options.metresPerUnit = formats::metresPerUnit(units);
  if (!part.empty()) options.groups = {part};
  NamedPart p;
  p.name = part.empty() ? std::filesystem::path(path).stem().string() : part;
  p.mesh = formats::readObj(path, options);
  if (p.mesh.triangles.empty()) throw Error(path + ": no triangles" + (part.empty() ? "" : " in part " + part));
  std::vector<NamedPart> parts;
  parts.push_back(std::move(p));
  return parts;
}

// --- PNG slices ------------------------------------------------------------------------------

struct Rgb {
  unsigned char r, g, b;
};

Rgb lerp(Rgb a, Rgb b, double t) {
  t = std::clamp(t, 0.0, 1.0);
  return {static_cast<unsigned char>(a.r + t * (b.r - a.r)), static_cast<unsigned char>(a.g + t * (b.g - a.g)),
          static_cast<unsigned char>(a.b + t * (b.b - a.b))};
}

// Outside: dark red -> orange -> pale yellow with distance; inside: light -> dark blue with
// depth; thin darker bands every shell width so distances can be read off.
Rgb heat(double d, double shell, double maxOut, double maxIn) {
  Rgb c;
  if (d >= 0) {
    const double t = d / std::max(maxOut, 1e-9);
    c = t < 0.5 ? lerp({120, 10, 10}, {240, 130, 20}, 2 * t) : lerp({240, 130, 20}, {255, 245, 200}, 2 * t - 1);
  } else {
    c = lerp({170, 200, 255}, {10, 30, 110}, -d / std::max(maxIn, 1e-9));
  }
  const double bands = std::abs(d) / shell;
  if (bands - std::floor(bands) < 0.08 && std::abs(d) > 0.5 * shell) c = lerp(c, {0, 0, 0}, 0.35);
  return c;
}

// One slice through voxel `at` across axis `axis`, each voxel `scale` pixels, the second
// image axis pointing up.
void writeSlices(const field::DistanceField& f, int axis, int at, int scale, const std::string& stem,
                 std::vector<std::string>& written) {
  const field::GridDims& d = f.dims();
  const int n[3] = {d.nx, d.ny, d.nz};
  // Image axes: x-slice shows (z, y), y-slice shows (x, z), z-slice shows (x, y).
  const int u = axis == 0 ? 2 : 0, v = axis == 1 ? 2 : 1;
  const int w = n[u] * scale, h = n[v] * scale;
  double maxOut = 0, maxIn = 0;
  for (std::uint32_t i = 0; i < f.voxelCount(); ++i) {
    maxOut = std::max(maxOut, f.distanceVoxels(i));
    maxIn = std::max(maxIn, -f.distanceVoxels(i));
  }
  const double shell = f.shell_m() / f.voxelSize();
  std::vector<unsigned char> dist(static_cast<std::size_t>(w) * h * 3), normals(dist.size());
  for (int py = 0; py < h; ++py)
    for (int px = 0; px < w; ++px) {
      int c[3];
      c[axis] = at;
      c[u] = px / scale;
      c[v] = n[v] - 1 - py / scale;
      const std::uint32_t voxel = d.index(c[0], c[1], c[2]);
      Rgb a = heat(f.distanceVoxels(voxel), shell, maxOut, maxIn);
      Rgb b{60, 60, 60};
      if (f.inShell(voxel)) {
        const Vec3 nn = f.normal(voxel);
        b = {static_cast<unsigned char>(127.5 * (nn.x() + 1)), static_cast<unsigned char>(127.5 * (nn.y() + 1)),
             static_cast<unsigned char>(127.5 * (nn.z() + 1))};
      } else if (f.inside(voxel)) {
        b = {25, 25, 25};
      }
      if (f.isSurface(voxel)) a = {0, 0, 0};
      if (f.isBorder(voxel)) a = b = {128, 128, 128};
      const std::size_t o = (static_cast<std::size_t>(py) * w + px) * 3;
      dist[o] = a.r, dist[o + 1] = a.g, dist[o + 2] = a.b;
      normals[o] = b.r, normals[o + 1] = b.g, normals[o + 2] = b.b;
    }
  const char names[3] = {'x', 'y', 'z'};
  for (int k = 0; k < 2; ++k) {
    const std::string path = fmt::format("{}_{}{}_{}.png", stem, names[axis], at, k == 0 ? "distance" : "normals");
    if (!stbi_write_png(path.c_str(), w, h, 3, (k == 0 ? dist : normals).data(), w * 3))
      throw Error(path + ": cannot write the PNG file");
    written.push_back(path);
  }
}

void buildAndReport(const NamedPart& part, const field::FieldSettings& settings, const std::string& outDir) {
  const field::DistanceField f = field::DistanceField::build(part.mesh, settings);
  const field::FieldStats& s = f.stats();
  const field::GridDims& d = f.dims();
  fmt::print("part {}: {} triangles\n", part.name, part.mesh.triangleCount());
  fmt::print("  grid        {}x{}x{} = {} voxels of {:.4g} m (shell T3 {:.4g} m = {:.3g} voxels, border {} voxels)\n",
             d.nx, d.ny, d.nz, s.voxels, f.voxelSize(), f.shell_m(), f.shell_m() / f.voxelSize(),
             static_cast<int>(std::lround((f.bounds().size().x() - f.bodyBounds().size().x()) / f.voxelSize() / 2)));
  fmt::print("  voxels      surface {}, inside {}, shell {} (references {})\n", s.surfaceVoxels, s.insideVoxels,
             s.shellVoxels, s.references);
  fmt::print("  build       voxelize {:.1f} ms, {} {:.1f} ms, normals and storage {:.1f} ms\n", s.voxelizeMs,
             f.method() == field::FieldMethod::Exact ? "exact transform" : "DVDP", s.propagateMs, s.finishMs);
  fmt::print("  memory      {:.2f} MB ({:.2f} bytes per voxel)\n", s.bytes / 1e6,
             static_cast<double>(s.bytes) / static_cast<double>(s.voxels));
  if (outDir.empty()) return;
  std::filesystem::create_directories(outDir);
  // Slices through the middle of the body, each voxel at least 3 pixels, about 600 pixels wide.
  const Vec3i mid = f.coordinates(f.voxelAt(f.bodyBounds().center()));
  const int longest = std::max({d.nx, d.ny, d.nz});
  const int scale = std::clamp(600 / longest, 3, 12);
  std::vector<std::string> written;
  for (int axis = 0; axis < 3; ++axis)
    writeSlices(f, axis, mid[axis], scale, (std::filesystem::path(outDir) / part.name).string(), written);
  for (const std::string& path : written) fmt::print("  wrote       {}\n", path);
}

RunFunction setupField(CLI::App& app) {
  struct Options {
    std::string input, out, part, units = "m", method = "dvdp";
    double voxel = 0, shell = 0.06;
    std::vector<int> dims;
    int border = 8;
    bool json = false;
  };
  auto o = std::make_shared<Options>();
  app.add_option("INPUT", o->input, "Body part mesh (.obj)")->required();
  app.add_option("--voxel", o->voxel, "Voxel size in metres");
  app.add_option("--out", o->out, "Directory for the PNG slices");
  app.add_option("--part", o->part, "Only this OBJ group/object, named NAME in the output");
  app.add_option("--units", o->units, "Length unit of the OBJ file: m, dm, cm, mm, in, ft")->capture_default_str();
  app.add_option("--shell", o->shell, "Outer offset surface T3 in metres (Voronoi references kept within it)")
      ->capture_default_str();
  app.add_option("--field-method", o->method, "dvdp (the paper's DVDP) or exact (separable feature transform)")
      ->check(CLI::IsMember({"dvdp", "exact"}))
      ->capture_default_str();
  app.add_option("--dims", o->dims, "With --json: build exactly NX NY NZ voxels (voxel size from the bounding box)")
      ->expected(3);
  app.add_option("--border", o->border, "With --dims: border voxels around the bounding box")->capture_default_str();
  app.add_flag("--json", o->json, "With --dims: measure DVDP against the exact transform, print JSON (T3 = 6 voxels)");
  return [o] {
    const std::vector<NamedPart> parts = loadParts(o->input, o->units, o->part);
    if (o->json || !o->dims.empty()) {
      if (o->dims.size() != 3 || !o->json) throw Error("--dims NX NY NZ goes with --json");
      for (int n : o->dims)
        if (n < 1 || n > field::kMaxGridSide)
          throw Error("--dims: each side must be 1.." + std::to_string(field::kMaxGridSide));
      if (o->border < 2) throw Error("--border must be at least 2 voxels");
      const FieldMeasurement m = measureField(parts.front().mesh, {o->dims[0], o->dims[1], o->dims[2]}, o->border, 6, 1);
      std::printf("%s\n", toJson(m).dump(2).c_str());
      return 0;
    }
    if (!(o->voxel > 0)) throw Error("--voxel SIZE (metres, positive) is required");
    field::FieldSettings settings;
    settings.voxelSize_m = o->voxel;
    settings.shell_m = o->shell;
    settings.method = o->method == "exact" ? field::FieldMethod::Exact : field::FieldMethod::Dvdp;
    for (const NamedPart& part : parts) buildAndReport(part, settings, o->out);
    return 0;
  };
}

const bool registered_cmd_field =
    registerCommand({"field", "Build body-part distance fields, print their figures, write PNG slices", "", 40,
                     &setupField});

}  // namespace
}  // namespace drape::cli
