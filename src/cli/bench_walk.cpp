// `drape bench walk --json`: the collision trace's voxel walk (paper section 4.3.3), the 3D
// Bresenham line side by side with the lookup-table walk the paper names as potentially
// faster, on random walks of each length through a 64^3 grid whose bytes the walk reads (as
// the collider reads its voxels). One thread; per length the median of --runs timings of the
// same walks. Both walks must visit the same voxels: the checksums are compared.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "bench_machine.hpp"
#include "command.hpp"
#include "measure.hpp"
#include "drape/cloth/voxel_walk.hpp"
#include "drape/core/error.hpp"

namespace drape::cli {
namespace {

constexpr int kSide = 64;
constexpr int kWalks = 200000;

struct Walk {
  Vec3i from, to;
};

/// Walks whose longest axis moves exactly `length` voxels, inside the grid.
std::vector<Walk> walksOfLength(int length, std::mt19937& rng) {
  std::uniform_int_distribution<int> coord(length, kSide - 1 - length);
  std::uniform_int_distribution<int> off(-length, length);
  std::uniform_int_distribution<int> axis(0, 2);
  std::vector<Walk> walks;
  walks.reserve(kWalks);
  while (walks.size() < kWalks) {
    const Vec3i from(coord(rng), coord(rng), coord(rng));
    Vec3i d(off(rng), off(rng), off(rng));
    d[axis(rng)] = (rng() & 1) ? length : -length;  // the longest axis
    walks.push_back({from, from + d});
  }
  return walks;
}

/// Times all walks with `walk`, reading the grid byte of every voxel visited; returns ns per
/// walk and the checksum of the bytes read.
template <typename WalkFn>
std::pair<double, std::uint64_t> timeWalks(const std::vector<Walk>& walks, const std::vector<std::uint8_t>& grid,
                                           WalkFn&& walk) {
  std::uint64_t sum = 0;
  const auto start = std::chrono::steady_clock::now();
  for (const Walk& w : walks)
    sum += static_cast<std::uint64_t>(walk(w.from, w.to, [&](const Vec3i& p) {
      sum += grid[(static_cast<std::size_t>(p.z()) * kSide + static_cast<std::size_t>(p.y())) * kSide +
                  static_cast<std::size_t>(p.x())];
      return true;
    }));
  const double ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count();
  return {ns / static_cast<double>(walks.size()), sum};
}

RunFunction setupBenchWalk(CLI::App& app) {
  struct Options {
    bool json = true;
    int runs = 5;
    int longest = 8;
  };
  auto o = std::make_shared<Options>();
  app.add_flag("--json", o->json, "Print JSON (the only output format)");
  app.add_option("--runs", o->runs, "Timings per length and walk (the median is reported)")
      ->capture_default_str()
      ->check(CLI::Range(1, 100));
  app.add_option("--longest", o->longest, "Longest walk measured, voxels along its longest axis")
      ->capture_default_str()
      ->check(CLI::Range(1, 30));
  return [o] {
    std::mt19937 rng(7);
    std::vector<std::uint8_t> grid(static_cast<std::size_t>(kSide) * kSide * kSide);
    for (std::uint8_t& b : grid) b = static_cast<std::uint8_t>(rng());
    (void)cloth::walkTable();  // built before the timing
    nlohmann::json lengths = nlohmann::json::array();
    for (int length = 0; length <= o->longest; ++length) {
      const std::vector<Walk> walks = walksOfLength(length, rng);
      std::vector<double> bresenham, table;
      std::uint64_t sumB = 0, sumT = 0;
      for (int k = 0; k < o->runs; ++k) {
        const auto b = timeWalks(walks, grid, [](const Vec3i& a, const Vec3i& z, auto&& v) {
          return cloth::walkVoxels(a, z, v);
        });
        const auto t = timeWalks(walks, grid, [](const Vec3i& a, const Vec3i& z, auto&& v) {
          return cloth::walkVoxelsByTable(a, z, v);
        });
        bresenham.push_back(b.first);
        table.push_back(t.first);
        sumB = b.second;
        sumT = t.second;
      }
      if (sumB != sumT)
        throw Error(fmt::format("bench walk: the table walk visited other voxels than Bresenham at length {}", length),
                    ExitCode::Internal);
      const double nsB = median(bresenham), nsT = median(table);
      lengths.push_back({{"voxels", length},
                         {"in_table", length <= cloth::kWalkTableReach},
                         {"bresenham_ns_per_walk", nsB},
                         {"table_ns_per_walk", nsT},
                         {"table_speedup", nsB / nsT}});
    }
    const nlohmann::json out = {{"benchmark", "walk"},
                                {"machine", benchMachine()},
                                {"grid", {kSide, kSide, kSide}},
                                {"walks_per_length", kWalks},
                                {"runs", o->runs},
                                {"table_reach_voxels", cloth::kWalkTableReach},
                                {"table_bytes", sizeof(cloth::WalkTableEntry) * (2 * cloth::kWalkTableReach + 1) *
                                                    (2 * cloth::kWalkTableReach + 1) * (2 * cloth::kWalkTableReach + 1)},
                                {"lengths", lengths}};
    std::printf("%s\n", out.dump(2).c_str());
    return 0;
  };
}

const bool registered_bench_walk = registerCommand(
    {"walk", "The collision trace's voxel walk: 3D Bresenham vs the paper's lookup table", "bench", 110,
     &setupBenchWalk});

}  // namespace
}  // namespace drape::cli
