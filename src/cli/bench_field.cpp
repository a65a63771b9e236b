// `drape bench field --json`: distance-field generation on the paper's Table 2 grids (hips,
// thigh, shin), DVDP side by side with the exact separable transform, one thread, median of
// five runs, from a closed body-part-like mesh (a tapered rounded tube) that fills each box
// inside an 8-voxel border.

#include <cstdio>

#include "bench_machine.hpp"
#include "command.hpp"
#include "drape/field/shapes.hpp"
#include "field_measure.hpp"

namespace drape::cli {
namespace {

struct PaperGrid {
  const char* part;
  std::array<int, 3> dims;
  double paperFieldSeconds;     // Table 2, "distance field (6)"
  double paperDistanceSeconds;  // Table 2, "distance field (0)"
};

// Table 2 prints the thigh as 75x190x73, but its voxel count 1,467,750 is 75x190x103.
constexpr PaperGrid kGrids[] = {
    {"hips", {109, 99, 107}, 2.765, 2.422},
    {"thigh", {75, 190, 103}, 3.641, 2.797},
    {"shin", {57, 177, 61}, 3.422, 1.656},
};

RunFunction setupBenchField(CLI::App& app) {
  struct Options {
    bool json = true;
    int runs = 5;
  };
  auto options = std::make_shared<Options>();
  app.add_flag("--json", options->json, "Print JSON (the only output format)");
  app.add_option("--runs", options->runs, "Runs per measurement (the median is reported)")->check(CLI::Range(1, 100));
  return [options] {
    nlohmann::json grids = nlohmann::json::array();
    for (const PaperGrid& g : kGrids) {
      const int border = 8;
      // A limb-like tube (thicker at one end) fitted into the inner box: y is the long axis
      // of the thigh and shin; the hips use the same shape.
      mesh::TriMesh tube = field::makeRoundedTube(1.0, 0.7, 4.0, 64, 48);
      const double h = 0.005;  // m per voxel: a 5 mm grid, as a body part of about 0.5-1 m
      Aabb box;
      box.min = Vec3::Zero();
      box.max = Vec3(g.dims[0] - 2 * border, g.dims[1] - 2 * border, g.dims[2] - 2 * border) * h;
      field::fitToBox(tube, box);
      std::fprintf(stderr, "bench field: %s %dx%dx%d\n", g.part, g.dims[0], g.dims[1], g.dims[2]);
      FieldMeasurement m = measureField(tube, g.dims, border, 6, options->runs);
      nlohmann::json j = toJson(m);
      j["part"] = g.part;
      j["triangles"] = tube.triangleCount();
      j["paper_field6_ms"] = g.paperFieldSeconds * 1000;
      j["paper_field0_ms"] = g.paperDistanceSeconds * 1000;
      grids.push_back(j);
    }
    nlohmann::json out = {{"benchmark", "field"},
                          {"machine", benchMachine()},
                          {"threads", 1},
                          {"runs", options->runs},
                          {"statistic", "median"},
                          {"shell_voxels_T3", 6},
                          {"grids", grids}};
    std::printf("%s\n", out.dump(2).c_str());
    return 0;
  };
}

const bool registered_bench_field = registerCommand(
    {"field", "Distance fields on the paper's Table 2 grids: DVDP vs the exact transform", "bench", 100,
     &setupBenchField});

}  // namespace
}  // namespace drape::cli
