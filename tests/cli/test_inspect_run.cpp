// `drape inspect RUN_DIR` on a real run of the bundled walking skirt (the first 60 frames,
// in which the right hand, which is not collidable, swings into the skirt): the summary,
// the deepest vertices against the skin measured here from the run's own files (brute-force
// distance, winding number), a vertex followed frame by frame agreeing with the list, and
// the errors.

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "cli_runner.hpp"
#include "drape/formats/obj.hpp"
#include "drape/formats/pc2.hpp"
#include "drape/mesh/closest_point.hpp"
#include "drape/mesh/surface_distance.hpp"

namespace drape {
namespace {

using testing::CliResult;
using testing::runDrape;
using testing::ScratchDir;

using testing::kSkirtDir;

struct Row {
  long vertex = 0, frame = 0;
  double skin_mm = 0;
  std::string there;  // the body part of the skin's nearest point
};

/// A table row's words (split on spaces).
std::vector<std::string> wordsOf(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

bool allDigits(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c) != 0; });
}

/// HH:MM:SS:FF.
bool isTimeCode(const std::string& text) {
  const std::string s = !text.empty() && text[0] == '-' ? text.substr(1) : text;  // the lead-in's, before 0
  return s.size() == 11 && s[2] == ':' && s[5] == ':' && s[8] == ':' &&
         allDigits(s.substr(0, 2) + s.substr(3, 2) + s.substr(6, 2) + s.substr(9, 2));
}

/// The state's lower-case words from w[from], then "+D.D PART" and more: the signed skin
/// distance (mm) and the part there; nothing if the row is not so.
std::optional<std::pair<double, std::string>> skinAfterState(const std::vector<std::string>& w, std::size_t from) {
  const auto lower = [](const std::string& s) {
    return std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::islower(c) != 0; });
  };
  std::size_t i = from;
  while (i < w.size() && lower(w[i])) ++i;
  if (i == from || i + 2 >= w.size()) return std::nullopt;  // a state, the distance, the part, and more
  const std::string& d = w[i];
  if (d.size() < 2 || (d[0] != '+' && d[0] != '-') || d.find_first_not_of("0123456789.", 1) != std::string::npos)
    return std::nullopt;
  return std::pair{std::stod(d), w[i + 1]};
}

/// The rows of `--deepest`: "Skirt  VERTEX  FRAME  TIMECODE  STATE  SKIN PART  ...".
std::vector<Row> deepestRows(const std::string& out) {
  std::vector<Row> rows;
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    const std::vector<std::string> w = wordsOf(line);
    if (line.rfind("Skirt ", 0) != 0 || w.size() < 4 || !allDigits(w[1]) || !allDigits(w[2]) || !isTimeCode(w[3]))
      continue;
    if (const auto skin = skinAfterState(w, 4))
      rows.push_back({std::stol(w[1]), std::stol(w[2]), skin->first, skin->second});
  }
  return rows;
}

/// The skin column of `--vertex` rows, by frame: "FRAME  TIMECODE  STATE  SKIN PART  ...".
std::map<long, double> trackedSkin(const std::string& out) {
  std::map<long, double> skin;
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    const std::vector<std::string> w = wordsOf(line);
    if (line.rfind(" ", 0) != 0 || w.size() < 2 || !allDigits(w[0]) || !isTimeCode(w[1])) continue;
    if (const auto s = skinAfterState(w, 2)) skin[std::stol(w[0])] = s->first;
  }
  return skin;
}

class InspectRun : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scratch_ = new ScratchDir("inspect-run");
    run_ = testing::runInto(*scratch_, "skirt",
                            "'" + kSkirtDir + "/scene.wrl' --motion '" + kSkirtDir + "/walk.bvh' --frames 60");
  }
  static void TearDownTestSuite() { delete scratch_; }
  static CliResult inspect(const std::string& args) { return runDrape("inspect '" + run_ + "' " + args, *scratch_); }

  static inline ScratchDir* scratch_ = nullptr;
  static inline std::string run_;
};

TEST_F(InspectRun, SummarisesTheRun) {
  const CliResult r = inspect("");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("a drape run, 61 frames at 30 fps (-00:00:01:00 to 00:00:01:00)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("garment  Skirt          264 vertices, 480 triangles, collision states recorded"),
            std::string::npos) << r.out;
  EXPECT_NE(r.out.find("6 collidable: Hips, LowerBack, LeftUpLeg, RightUpLeg, LeftLeg, RightLeg"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("stats.json: 60 frames simulated"), std::string::npos) << r.out;
  // The slowest frame is one of those simulated, its stages add up to what it says, and no
  // frame's stages took longer.
  const std::size_t at = r.out.find("  slowest frame ");
  ASSERT_NE(at, std::string::npos) << r.out;
  const nlohmann::json stats = testing::statsOf(run_);
  const auto simulated = [&](int f) {
    double ms = 0.0;
    for (const char* stage : {"forces", "integrate", "collide", "fixtures", "strain_limit"})
      ms += stats["frame_ms_per_stage"][stage][f].get<double>();
    return ms;
  };
  const int frame = std::stoi(r.out.substr(at + 16));
  ASSERT_GE(frame, 1);
  ASSERT_LE(frame, 60);
  EXPECT_NE(r.out.find(fmt::format("{:.3f} ms in the simulation's stages (", simulated(frame)), at), std::string::npos)
      << r.out;
  for (int f = 0; f <= 60; ++f) EXPECT_LE(simulated(f), simulated(frame)) << "frame " << f;
  EXPECT_NE(r.out.find("look closer: --deepest N"), std::string::npos) << r.out;
}

TEST_F(InspectRun, TheDeepestVerticesAreInsideTheSkinAsTheRunsFilesSay) {
  const CliResult r = inspect("--deepest 6");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<Row> rows = deepestRows(r.out);
  ASSERT_EQ(rows.size(), 6u) << r.out;
  // Measured here from the files the run wrote: the skin at that frame, the vertex there.
  const mesh::TriMesh body = formats::readObj(run_ + "/body.obj");
  const formats::Pc2Cache skin = formats::readPc2(run_ + "/body.pc2");
  const formats::Pc2Cache garment = formats::readPc2(run_ + "/garment.pc2");
  int inside = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Row& row = rows[i];
    if (i > 0) {
      EXPECT_LE(rows[i - 1].skin_mm, row.skin_mm) << "sorted, deepest first";
    }
    const std::vector<Vec3>& x = skin.frames.at(static_cast<std::size_t>(row.frame));
    const Vec3 p = garment.frames.at(static_cast<std::size_t>(row.frame)).at(static_cast<std::size_t>(row.vertex));
    double nearest = std::numeric_limits<double>::infinity();
    for (const mesh::Triangle& t : body.triangles)
      nearest = std::min(nearest, (p - mesh::closestOnTriangle(p, x[t[0]], x[t[1]], x[t[2]])).norm());
    EXPECT_NEAR(std::abs(row.skin_mm), nearest * 1000.0, 0.051) << "vertex " << row.vertex;
    const bool in = mesh::windingNumber(x, body.triangles, p) > 0.5;
    EXPECT_EQ(row.skin_mm < 0, in) << "vertex " << row.vertex << " frame " << row.frame;
    inside += in;
  }
  // The right hand swings into the skirt in these frames; the hips and legs, which the skirt
  // collides with, do not.
  EXPECT_GT(inside, 0) << r.out;
  EXPECT_NE(r.out.find("are inside the skin in some frame"), std::string::npos) << r.out;
  const std::string& there = rows.front().there;
  EXPECT_TRUE(there.starts_with("R") && there != "RightUpLeg" && there != "RightLeg") << r.out;
}

TEST_F(InspectRun, AVertexFollowedFrameByFrameAgreesWithTheDeepestList) {
  const std::vector<Row> rows = deepestRows(inspect("--deepest 1").out);
  ASSERT_EQ(rows.size(), 1u);
  const CliResult r = inspect("--vertex " + std::to_string(rows[0].vertex));
  ASSERT_EQ(r.code, 0) << r.err;
  const std::map<long, double> track = trackedSkin(r.out);
  ASSERT_EQ(track.size(), 61u) << r.out;
  const auto deepest = std::min_element(track.begin(), track.end(),
                                        [](const auto& a, const auto& b) { return a.second < b.second; });
  EXPECT_EQ(deepest->first, rows[0].frame);
  EXPECT_DOUBLE_EQ(deepest->second, rows[0].skin_mm);
  // One frame, by --range.
  const CliResult one = inspect("--vertex " + std::to_string(rows[0].vertex) + " --range " + std::to_string(rows[0].frame));
  ASSERT_EQ(one.code, 0) << one.err;
  const std::map<long, double> single = trackedSkin(one.out);
  ASSERT_EQ(single.size(), 1u) << one.out;
  EXPECT_DOUBLE_EQ(single.begin()->second, rows[0].skin_mm);
}

/// The rows of `--stretched`: "Skirt  A B  FRAME  TIMECODE  +S.S %  ...".
struct EdgeRow {
  long a = 0, b = 0, frame = 0;
  double stretch_percent = 0;
};

std::vector<EdgeRow> stretchedRows(const std::string& out) {
  std::vector<EdgeRow> rows;
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    const std::vector<std::string> w = wordsOf(line);
    if (line.rfind("Skirt ", 0) != 0 || w.size() < 7 || !allDigits(w[1]) || !allDigits(w[2]) || !allDigits(w[3]) ||
        !isTimeCode(w[4]) || w[6] != "%")
      continue;
    rows.push_back({std::stol(w[1]), std::stol(w[2]), std::stol(w[3]), std::stod(w[5])});
  }
  return rows;
}

TEST_F(InspectRun, TheStretchedEdgesAreTheLongestAgainstRestAsTheRunsFilesSay) {
  const CliResult r = inspect("--stretched 5");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<EdgeRow> rows = stretchedRows(r.out);
  ASSERT_EQ(rows.size(), 5u) << r.out;
  // Measured here by brute force from the run's files: every edge of the rest mesh, in every
  // frame of the cache; and the deepest compression over the simulated frames (from 1).
  const mesh::TriMesh rest = formats::readObj(run_ + "/garment.obj");
  const formats::Pc2Cache cache = formats::readPc2(run_ + "/garment.pc2");
  std::map<std::pair<long, long>, std::pair<double, long>> longest;  // edge -> (ratio, frame)
  double compressed = 0.0;
  for (const mesh::Triangle& t : rest.triangles)
    for (int k = 0; k < 3; ++k) {
      const long a = std::min(t[k], t[(k + 1) % 3]), b = std::max(t[k], t[(k + 1) % 3]);
      auto& [ratio, frame] = longest[{a, b}];
      const double length = (rest.positions[a] - rest.positions[b]).norm();
      for (std::size_t f = 0; f < cache.frames.size(); ++f) {
        const double r2 = (cache.frames[f][a] - cache.frames[f][b]).norm() / length;
        if (r2 > ratio) {
          ratio = r2;
          frame = static_cast<long>(f);
        }
        if (f >= 1) compressed = std::max(compressed, 1.0 - r2);
      }
    }
  std::vector<std::pair<double, std::pair<long, long>>> order;
  for (const auto& [edge, found] : longest) order.push_back({found.first, edge});
  std::sort(order.rbegin(), order.rend());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& [ratio, frame] = longest.at({rows[i].a, rows[i].b});
    EXPECT_EQ(rows[i].frame, frame) << "edge " << rows[i].a << "-" << rows[i].b;
    EXPECT_NEAR(rows[i].stretch_percent, 100.0 * (ratio - 1.0), 0.051) << "edge " << rows[i].a << "-" << rows[i].b;
    EXPECT_NEAR(rows[i].stretch_percent, 100.0 * (order[i].first - 1.0), 0.051) << "the " << i << "th longest";
  }
  EXPECT_GT(rows.front().stretch_percent, 0.0);
  // The simulation's own figures (stats.json's, measured on its rest lengths at the end of
  // each frame) are the longest stretch and the deepest compression found here, max_strain
  // the larger of the two, and the summary says them.
  const nlohmann::json stats = testing::statsOf(run_);
  const double stretch = stats["max_stretch"].get<double>(), compression = stats["max_compression"].get<double>();
  EXPECT_NEAR(100.0 * stretch, 100.0 * (order.front().first - 1.0), 0.051);
  EXPECT_NEAR(100.0 * compression, 100.0 * compressed, 0.051);
  EXPECT_DOUBLE_EQ(stats["max_strain"].get<double>(), std::max(stretch, compression));
  EXPECT_NE(r.out.find(fmt::format("edges at most {:.1f} % longer and {:.1f} % shorter than at rest (at the end of a frame)",
                                   100.0 * stretch, 100.0 * compression)),
            std::string::npos)
      << r.out;
  const auto over = std::count_if(order.begin(), order.end(), [](const auto& o) { return o.first > 1.1; });
  EXPECT_NE(r.out.find(fmt::format(": {} of {} are more than 10 % longer than at rest in some frame", over, order.size())),
            std::string::npos)
      << r.out;
  // Within a range, each edge's longest frame lies in it.
  const CliResult late = inspect("--stretched 3 --range 40:50");
  ASSERT_EQ(late.code, 0) << late.err;
  for (const EdgeRow& row : stretchedRows(late.out)) {
    EXPECT_GE(row.frame, 40);
    EXPECT_LE(row.frame, 50);
  }
}

TEST_F(InspectRun, WhatTheRunDoesNotHaveIsAnErrorThatSaysSo) {
  const struct {
    std::string args, says;
  } cases[] = {
      {"--vertex 264", "--vertex 264: Skirt has vertices 0 to 263"},
      {"--vertex 3 --range 50:61", "--range 50:61: the run has frames 0 to 60"},
      {"--vertex 3 --range 9:4", "--range 9:4: the run has frames 0 to 60"},
      {"--vertex 3 --range x", "--range x is not a range"},
      {"--deepest 2 --garment Cape", "--garment Cape: the run's garments are Skirt"},
      {"--range 3", "--range and --garment go with --vertex V, --deepest N or --stretched N"},
      {"--deepest 0", "--deepest"},
      {"--motion '" + kSkirtDir + "/walk.bvh'", "--motion and --keep-apart go with a scene, not a run"},
  };
  for (const auto& c : cases) {
    const CliResult r = inspect(c.args);
    EXPECT_EQ(r.code, 2) << c.args;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << c.args << ": " << r.err;
  }
  const CliResult file = runDrape("inspect '" + kSkirtDir + "/walk.bvh' --deepest 3", *scratch_);
  EXPECT_EQ(file.code, 2);
  EXPECT_NE(file.err.find("go with a run directory"), std::string::npos) << file.err;
  const CliResult notRun = runDrape("inspect '" + kSkirtDir + "'", *scratch_);
  EXPECT_EQ(notRun.code, 2);
  EXPECT_NE(notRun.err.find("manifest.json"), std::string::npos) << notRun.err;
}

}  // namespace
}  // namespace drape
