#include "inspect_run.hpp"

#include <algorithm>
#include <array>
#include <filesystem>
#include <limits>
#include <optional>
#include <vector>

#include <fmt/format.h>
#include <fmt/ostream.h>
#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>

#include "drape/core/error.hpp"
#include "drape/core/files.hpp"
#include "drape/core/progress.hpp"
#include "drape/core/timecode.hpp"
#include "drape/formats/json_text.hpp"
#include "drape/formats/obj.hpp"
#include "drape/formats/run_manifest.hpp"
#include "drape/mesh/surface_distance.hpp"
#include "drape/mesh/topology.hpp"
#include "drape/render/run_replay.hpp"
#include "frame_range.hpp"

namespace drape::cli {
namespace {

using render::MeshRole;

/// DIR/stats.json, or null when the run has none (runs cut short by a failed write).
nlohmann::json readStats(const std::filesystem::path& directory) {
  const std::filesystem::path path = directory / "stats.json";
  const std::optional<std::string> text = readFileText(path);
  if (!text) return nullptr;
  nlohmann::json stats = formats::parseJsonText(*text, path.string());
  if (!stats.is_object()) throw Error(fmt::format("{}: expected a JSON object", path.string()));
  return stats;
}

std::vector<std::size_t> meshesWithRole(const render::RunReplay& run, MeshRole role) {
  std::vector<std::size_t> found;
  for (std::size_t m = 0; m < run.meshes().size(); ++m)
    if (run.meshes()[m].role == role) found.push_back(m);
  return found;
}

/// The segments the garments collided with: those stats.json lists a distance field for,
/// or every segment when it lists none.
std::vector<std::size_t> collidableSegments(const render::RunReplay& run, const nlohmann::json& stats) {
  std::vector<std::string> names;
  if (stats.is_object() && stats.contains("distance_fields") && stats["distance_fields"].is_array())
    for (const nlohmann::json& f : stats["distance_fields"])
      if (f.is_object() && f.contains("segment") && f["segment"].is_string()) names.push_back(f["segment"]);
  std::vector<std::size_t> segments = meshesWithRole(run, MeshRole::Segment);
  if (names.empty()) return segments;
  std::erase_if(segments, [&](std::size_t m) {
    return std::find(names.begin(), names.end(), run.meshes()[m].name) == names.end();
  });
  return segments;
}

std::string stateText(std::span<const std::uint8_t> states, std::size_t vertex) {
  if (states.empty()) return "-";
  namespace vs = render::vertex_state;
  const std::uint8_t s = states[vertex];
  std::string text = (s & vs::kPinned) ? "pinned" : (s & vs::kBound) ? "bound" : "";
  if (!text.empty()) return text;
  switch (s & vs::kCollisionMask) {
    case vs::kInsideVolume: return "inside a volume";
    case vs::kOnSurface: return "on the surface";
    case vs::kPenaltyZone: return "below T1";
    default: return "outside";
  }
}

std::string millimetres(double distance_m) {
  return std::isinf(distance_m) ? "-" : fmt::format("{:+.1f}", distance_m * 1000.0);
}

/// The meshes of the body a garment is worn by: its character's skin and collidable
/// segments (in a run of several characters, the manifest names each mesh's).
struct BodyMeshes {
  std::string character;
  std::optional<std::size_t> skin;
  std::vector<std::size_t> collidable;
};

BodyMeshes bodyOf(const render::RunReplay& run, std::size_t garment, const std::vector<std::size_t>& collidable) {
  BodyMeshes body;
  body.character = run.meshes()[garment].character;
  for (const std::size_t m : meshesWithRole(run, MeshRole::Skin))
    if (run.meshes()[m].character == body.character && !body.skin) body.skin = m;
  for (const std::size_t m : collidable)
    if (run.meshes()[m].character == body.character) body.collidable.push_back(m);
  return body;
}

/// What garment vertices are measured against in one frame: the skin as players draw it
/// and each collidable segment, as the run recorded them.
struct BodyAtFrame {
  std::optional<mesh::SurfaceDistance> skin;
  std::vector<std::pair<std::size_t, mesh::SurfaceDistance>> parts;  ///< (mesh, distance)
};

BodyAtFrame bodyAt(const render::RunReplay& run, std::int64_t f, std::optional<std::size_t> skin,
                   const std::vector<std::size_t>& parts) {
  BodyAtFrame body;
  if (skin) body.skin.emplace(run.positions(*skin, f), run.meshes()[*skin].triangles);
  for (const std::size_t m : parts) body.parts.emplace_back(m, mesh::SurfaceDistance(run.positions(m, f), run.meshes()[m].triangles));
  return body;
}

BodyAtFrame bodyAt(const render::RunReplay& run, std::int64_t f, const BodyMeshes& body) {
  return bodyAt(run, f, body.skin, body.collidable);
}

/// The signed distance to the skin, and which segment of its character (collidable or not:
/// a hand, the head) the skin's nearest point belongs to, the one it is nearest to:
/// "-15.6 RightHand".
std::string skinText(const render::RunReplay& run, std::int64_t f, const BodyAtFrame& body, const Vec3& p,
                     const std::string& character) {
  if (!body.skin) return "-";
  const mesh::SurfacePoint onSkin = body.skin->at(p);
  std::vector<std::size_t> segments = meshesWithRole(run, MeshRole::Segment);
  std::erase_if(segments, [&](std::size_t m) { return run.meshes()[m].character != character; });
  const BodyAtFrame all = bodyAt(run, f, std::nullopt, segments);
  std::string part;
  double nearest = std::numeric_limits<double>::infinity();
  for (const auto& [m, distance] : all.parts)
    if (const double d = std::abs(distance.at(onSkin.point).distance_m); d < nearest) {
      nearest = d;
      part = run.meshes()[m].name;
    }
  return part.empty() ? millimetres(onSkin.distance_m) : fmt::format("{} {}", millimetres(onSkin.distance_m), part);
}

struct PartDistance {
  std::size_t mesh = 0;
  double distance_m = std::numeric_limits<double>::infinity();
};

/// The collidable parts by signed distance from p, nearest first.
std::vector<PartDistance> nearestParts(const BodyAtFrame& body, const Vec3& p) {
  std::vector<PartDistance> found;
  for (const auto& [m, distance] : body.parts) found.push_back({m, distance.at(p).distance_m});
  std::sort(found.begin(), found.end(), [](const PartDistance& a, const PartDistance& b) { return a.distance_m < b.distance_m; });
  return found;
}

std::string partText(const render::RunReplay& run, const std::vector<PartDistance>& parts, std::size_t i) {
  if (i >= parts.size()) return "-";
  return fmt::format("{} {}", run.meshes()[parts[i].mesh].name, millimetres(parts[i].distance_m));
}

struct Frames {
  std::int64_t first = 0, last = 0;
};

Frames framesOf(const render::RunReplay& run, const std::string& text) {
  const std::int64_t count = *run.frameCount();
  FrameRange range;
  if (!text.empty()) range = parseFrameRange(text);
  const Frames frames{range.first, range.last < 0 ? count - 1 : range.last};
  if (frames.first > frames.last || frames.last >= count)
    throw Error(fmt::format("--range {}: the run has frames 0 to {}", text, count - 1));
  return frames;
}

std::string timeCode(const render::RunReplay& run, std::int64_t f) {
  return TimeCode{run.startFrame() + f, run.frameRate()}.smpte();
}

/// The frame whose simulation stages took longest (stats.json's frame_ms_per_stage, which
/// RunReplay has checked: a number per frame), and what each stage took in it: where a run's
/// time went when some frames cost more than the rest (a frame computed again, a pinch).
void printSlowestFrame(const render::RunReplay& run, const nlohmann::json& stats, std::ostream& out) {
  if (!stats.contains("frame_ms_per_stage") || !stats["frame_ms_per_stage"].is_object()) return;
  const nlohmann::json& byFrame = stats["frame_ms_per_stage"];
  const auto simulated = [&](std::size_t f) {
    double ms = 0.0;
    for (const auto& [stage, column] : byFrame.items())
      if (stage != "output") ms += column[f].get<double>();
    return ms;
  };
  const auto frames = static_cast<std::size_t>(*run.frameCount());
  std::size_t slowest = 0;
  for (std::size_t f = 1; f < frames; ++f)
    if (simulated(f) > simulated(slowest)) slowest = f;
  if (!(simulated(slowest) > 0.0)) return;
  std::vector<std::pair<std::string, double>> stages;
  for (const auto& [stage, column] : byFrame.items())
    if (stage != "output" && column[slowest].get<double>() > 0.0) stages.emplace_back(stage, column[slowest].get<double>());
  std::sort(stages.begin(), stages.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
  std::vector<std::string> parts;
  for (const auto& [stage, ms] : stages) parts.push_back(fmt::format("{} {:.3f}", stage, ms));
  fmt::print(out, "  slowest frame {} ({}): {:.3f} ms in the simulation's stages ({})\n", slowest,
             timeCode(run, static_cast<std::int64_t>(slowest)), simulated(slowest), fmt::join(parts, ", "));
}

/// What each garment's layer collision did, from stats.json: its own layers kept apart
/// (self_collision) and the garments it is worn over (worn_over). A crossing is a vertex found
/// through a layer at a test and put back on its side.
void printLayers(const nlohmann::json& stats, std::ostream& out) {
  if (!stats.contains("garments") || !stats["garments"].is_array()) return;
  const auto count = [](const nlohmann::json& o, const char* key) {
    return o.contains(key) && o[key].is_number() ? o[key].get<double>() : 0.0;
  };
  for (const nlohmann::json& g : stats["garments"]) {
    if (!g.is_object() || !g.contains("name") || !g["name"].is_string()) continue;
    const std::string name = g["name"].get<std::string>();
    const auto print = [&](const nlohmann::json& layer, const std::string& what, const char* size) {
      fmt::print(out, "  {:<14} {} {:.4g} mm: {:.0f} contacts at {:.0f} tests, {:.0f} of them crossed through and put back\n",
                 name, what, 1e3 * count(layer, size), count(layer, "contacts"), count(layer, "tests"),
                 count(layer, "crossings"));
    };
    if (g.contains("self_collision") && g["self_collision"].is_object())
      print(g["self_collision"], "its own layers kept apart by", "thickness_m");
    if (g.contains("worn_over") && g["worn_over"].is_object()) {
      const nlohmann::json& over = g["worn_over"];
      std::vector<std::string> below;
      if (over.contains("garments") && over["garments"].is_array())
        for (const nlohmann::json& b : over["garments"])
          if (b.is_string()) below.push_back(b.get<std::string>());
      print(over, fmt::format("worn over {}, kept above by", fmt::join(below, ", ")), "gap_m");
    }
  }
}

void printSummary(const std::string& directory, const render::RunReplay& run, const nlohmann::json& stats,
                  const std::vector<std::size_t>& collidable, std::ostream& out) {
  const std::int64_t frames = *run.frameCount();
  fmt::print(out, "{}: a drape run, {} frames at {:g} fps ({} to {})\n", directory, frames, run.frameRate(),
             timeCode(run, 0), timeCode(run, frames - 1));
  for (const std::size_t m : meshesWithRole(run, MeshRole::Garment)) {
    const render::MeshInfo& info = run.meshes()[m];
    fmt::print(out, "  garment  {:<14} {} vertices, {} triangles{}{}\n", info.name, info.vertexCount,
               info.triangles.size(), run.states(m, 0).empty() ? "" : ", collision states recorded",
               info.character.empty() ? "" : ", worn by " + info.character);
  }
  for (const MeshRole role : {MeshRole::Skin, MeshRole::Drawn})
    for (const std::size_t m : meshesWithRole(run, role))
      fmt::print(out, "  {:<8} {:<14} {} vertices, {} triangles{}{}\n", role == MeshRole::Skin ? "skin" : "drawn",
                 run.meshes()[m].name, run.meshes()[m].vertexCount, run.meshes()[m].triangles.size(),
                 run.meshes()[m].character.empty() ? "" : ", " + run.meshes()[m].character + "'s",
                 role == MeshRole::Drawn ? " (skinned with the body, not collided with)" : "");
  const std::size_t segments = meshesWithRole(run, MeshRole::Segment).size();
  if (segments > 0) {
    std::vector<std::string> names;
    for (const std::size_t m : collidable) names.push_back(run.meshes()[m].name);
    fmt::print(out, "  segments {}, {} collidable: {}\n", segments, collidable.size(), fmt::join(names, ", "));
  }
  if (!stats.is_object()) return;
  const auto number = [&](const char* key) {
    return stats.contains(key) && stats[key].is_number() ? stats[key].get<double>() : 0.0;
  };
  const bool unstable = stats.contains("unstable") && stats["unstable"].is_boolean() && stats["unstable"].get<bool>();
  // Runs written before stats.json told stretch from compression have max_strain alone.
  const std::string strain =
      stats.contains("max_stretch")
          ? fmt::format("edges at most {:.1f} % longer and {:.1f} % shorter than at rest", 100.0 * number("max_stretch"),
                        100.0 * number("max_compression"))
          : fmt::format("largest edge strain {:.1f} % (stretched or compressed)", 100.0 * number("max_strain"));
  // `format` takes the count of those pinched, from runs whose stats.json tells them apart.
  const auto pinched = [&](const char* total, const char* key, const char* format) {
    return number(total) > 0.0 && stats.contains(key) ? fmt::format(fmt::runtime(format), number(key)) : std::string();
  };
  fmt::print(out,
             "  stats.json: {:.0f} frames simulated, {:.3f} ms per frame; vertex-substeps inside the body {:.0f} of {:.0f} "
             "(deepest {:.3g} mm{}), below T1 {:.0f}{}; {} (at the end of a frame); {}\n",
             number("frames"), number("ms_per_frame"), number("vertex_substeps_inside_body"), number("vertex_substeps"),
             number("max_penetration_m") * 1000.0,
             pinched("vertex_substeps_inside_body", "vertex_substeps_inside_body_pinched",
                     "; {:.0f} pinched between parts"),
             number("vertex_substeps_below_T1"),
             pinched("vertex_substeps_below_T1", "vertex_substeps_below_T1_pinched", " ({:.0f} pinched between parts)"),
             strain,
             unstable ? "went unstable (see its \"instability\")" : "stable");
  printLayers(stats, out);
  printSlowestFrame(run, stats, out);
}

/// The garments a query looks at: the one --garment names, or all of them.
std::vector<std::size_t> selectedGarments(const render::RunReplay& run, const std::string& name) {
  const std::vector<std::size_t> garments = meshesWithRole(run, MeshRole::Garment);
  if (garments.empty()) throw Error("the run has no garment");
  if (name.empty()) return garments;
  std::vector<std::string> names;
  for (const std::size_t m : garments) {
    if (run.meshes()[m].name == name) return {m};
    names.push_back(run.meshes()[m].name);
  }
  throw Error(fmt::format("--garment {}: the run's garments are {}", name, fmt::join(names, ", ")));
}

std::size_t garmentToFollow(const render::RunReplay& run, const std::string& name) {
  const std::vector<std::size_t> garments = selectedGarments(run, name);
  if (garments.size() > 1) {
    std::vector<std::string> names;
    for (const std::size_t m : garments) names.push_back(run.meshes()[m].name);
    throw Error(fmt::format("--vertex: the run has {} garments; say which with --garment ({})", garments.size(),
                            fmt::join(names, ", ")));
  }
  return garments.front();
}

void printVertexTrack(const render::RunReplay& run, const RunQuery& query, const Frames& frames,
                      const std::vector<std::size_t>& collidable, std::ostream& out) {
  const std::size_t g = garmentToFollow(run, query.garment);
  const BodyMeshes worn = bodyOf(run, g, collidable);
  const render::MeshInfo& garment = run.meshes()[g];
  if (static_cast<std::size_t>(query.vertex) >= garment.vertexCount)
    throw Error(fmt::format("--vertex {}: {} has vertices 0 to {}", query.vertex, garment.name, garment.vertexCount - 1));
  const auto v = static_cast<std::size_t>(query.vertex);
  fmt::print(out, "\n{} vertex {}, frames {} to {} (distances in mm, signed: negative is inside)\n", garment.name, v,
             frames.first, frames.last);
  fmt::print(out, "{:>6}  {:<11}  {:<15}  {:<22}  {:<24}  {}\n", "frame", "time code", "state", "skin (there)",
             "nearest collidable part", "next");
  for (std::int64_t f = frames.first; f <= frames.last; ++f) {
    const BodyAtFrame body = bodyAt(run, f, worn);
    const Vec3& p = run.positions(g, f)[v];
    const std::vector<PartDistance> parts = nearestParts(body, p);
    fmt::print(out, "{:>6}  {:<11}  {:<15}  {:<22}  {:<24}  {}\n", f, timeCode(run, f), stateText(run.states(g, f), v),
               skinText(run, f, body, p, worn.character), partText(run, parts, 0), partText(run, parts, 1));
  }
}

struct Deepest {
  std::size_t garment = 0, vertex = 0;
  std::int64_t frame = 0;
  double distance_m = std::numeric_limits<double>::infinity();
};

/// Per garment vertex, the frame it is deepest in (or nearest to) the body that wears it: its
/// skin when the run has one, else its nearest collidable segment.
std::vector<Deepest> deepestVertices(const render::RunReplay& run, const std::vector<std::size_t>& garments,
                                     const Frames& frames, const std::vector<std::size_t>& collidable) {
  std::vector<Deepest> deepest;
  std::vector<BodyMeshes> bodies;  // the bodies that wear the garments, once each
  std::vector<std::size_t> bodyOfVertex;
  for (const std::size_t g : garments) {
    BodyMeshes worn = bodyOf(run, g, collidable);
    auto it = std::find_if(bodies.begin(), bodies.end(), [&](const BodyMeshes& b) { return b.character == worn.character; });
    if (it == bodies.end()) it = bodies.insert(bodies.end(), std::move(worn));
    for (std::size_t v = 0; v < run.meshes()[g].vertexCount; ++v) {
      deepest.push_back({g, v, frames.first});
      bodyOfVertex.push_back(static_cast<std::size_t>(it - bodies.begin()));
    }
  }
  Progress progress("drape inspect", frames.last - frames.first + 1);
  for (std::int64_t f = frames.first; f <= frames.last; ++f) {
    std::vector<BodyAtFrame> atFrame;
    for (const BodyMeshes& b : bodies) atFrame.push_back(bodyAt(run, f, b));
    tbb::parallel_for(std::size_t{0}, deepest.size(), [&](std::size_t i) {
      Deepest& d = deepest[i];
      const BodyAtFrame& body = atFrame[bodyOfVertex[i]];
      const Vec3& p = run.positions(d.garment, f)[d.vertex];
      const double distance = body.skin ? body.skin->at(p).distance_m : nearestParts(body, p).front().distance_m;
      if (distance < d.distance_m) {
        d.distance_m = distance;
        d.frame = f;
      }
    });
    progress.update(f - frames.first + 1);
  }
  std::stable_sort(deepest.begin(), deepest.end(), [](const Deepest& a, const Deepest& b) { return a.distance_m < b.distance_m; });
  return deepest;
}

void printDeepest(const render::RunReplay& run, const RunQuery& query, const Frames& frames, bool skin,
                  const std::vector<std::size_t>& collidable, std::ostream& out) {
  if (!skin && collidable.empty()) throw Error("--deepest: the run has no body (neither a skin nor segments) to measure against");
  const std::vector<std::size_t> garments = selectedGarments(run, query.garment);
  const std::vector<Deepest> deepest = deepestVertices(run, garments, frames, collidable);
  const auto inside = std::count_if(deepest.begin(), deepest.end(), [](const Deepest& d) { return d.distance_m < 0; });
  const char* against = skin ? "skin" : "nearest segment";
  fmt::print(out, "\ngarment vertices deepest in the body over frames {} to {}: {} of {} are inside the {} in some frame\n",
             frames.first, frames.last, inside, deepest.size(), against);
  fmt::print(out, "{:<14}  {:>6}  {:>6}  {:<11}  {:<15}  {:<22}  {:<24}  {}\n", "garment", "vertex", "frame",
             "time code", "state", skin ? "skin (there)" : "", "nearest collidable part", "next");
  const std::size_t shown = std::min(deepest.size(), static_cast<std::size_t>(query.deepest));
  for (std::size_t i = 0; i < shown; ++i) {
    const Deepest& d = deepest[i];
    const BodyMeshes worn = bodyOf(run, d.garment, collidable);
    const BodyAtFrame body = bodyAt(run, d.frame, worn);
    const Vec3& p = run.positions(d.garment, d.frame)[d.vertex];
    const std::vector<PartDistance> parts = nearestParts(body, p);
    fmt::print(out, "{:<14}  {:>6}  {:>6}  {:<11}  {:<15}  {:<22}  {:<24}  {}\n", run.meshes()[d.garment].name,
               d.vertex, d.frame, timeCode(run, d.frame), stateText(run.states(d.garment, d.frame), d.vertex),
               skin ? skinText(run, d.frame, body, p, worn.character) : "", partText(run, parts, 0),
               partText(run, parts, 1));
  }
  if (shown > 0)
    fmt::print(out, "follow one: drape inspect RUN --vertex V{} --range FIRST:LAST\n",
               garments.size() > 1 ? " --garment NAME" : "");
}

struct Stretched {
  std::size_t garment = 0;
  std::array<std::uint32_t, 2> vertices{};
  double rest_m = 0.0;
  std::int64_t frame = 0;
  double ratio = 0.0;  ///< its longest over its rest length
};

/// The garment at rest: its OBJ in the run directory, as the scene models it.
mesh::TriMesh restMesh(const std::string& directory, const render::RunReplay& run, std::size_t g) {
  const render::MeshInfo& info = run.meshes()[g];
  for (const formats::RunMesh& m : formats::readRunManifest(directory).meshes) {
    if (m.role != "garment" || m.name != info.name || m.character != info.character) continue;
    const std::string path = (std::filesystem::path(directory) / m.topology).string();
    mesh::TriMesh rest = formats::readObj(path);
    if (rest.vertexCount() != info.vertexCount)
      throw Error(fmt::format("{}: {} vertices, where the run's cache has {}", path, rest.vertexCount(), info.vertexCount));
    return rest;
  }
  throw Error(fmt::format("{}: the manifest lists no garment {}", directory, info.name));
}

/// Every edge of the selected garments, each in the frame where it is longest against its
/// length at rest, longest first.
std::vector<Stretched> stretchedEdges(const std::string& directory, const render::RunReplay& run,
                                      const std::vector<std::size_t>& garments, const Frames& frames) {
  std::vector<Stretched> edges;
  for (const std::size_t g : garments) {
    const mesh::TriMesh rest = restMesh(directory, run, g);
    for (const mesh::Edge& e : mesh::Topology::build(rest).edges) {
      const double length = (rest.positions[e.v0] - rest.positions[e.v1]).norm();
      if (length > 0.0) edges.push_back({g, {e.v0, e.v1}, length, frames.first, 0.0});
    }
  }
  for (std::int64_t f = frames.first; f <= frames.last; ++f)
    for (Stretched& e : edges) {
      const std::vector<Vec3>& p = run.positions(e.garment, f);
      const double ratio = (p[e.vertices[0]] - p[e.vertices[1]]).norm() / e.rest_m;
      if (ratio > e.ratio) {
        e.ratio = ratio;
        e.frame = f;
      }
    }
  std::stable_sort(edges.begin(), edges.end(), [](const Stretched& a, const Stretched& b) { return a.ratio > b.ratio; });
  return edges;
}

void printStretched(const std::string& directory, const render::RunReplay& run, const RunQuery& query,
                    const Frames& frames, const std::vector<std::size_t>& collidable, std::ostream& out) {
  const std::vector<std::size_t> garments = selectedGarments(run, query.garment);
  const std::vector<Stretched> edges = stretchedEdges(directory, run, garments, frames);
  constexpr double kNoted = 1.1;  // a knit stretches a few per cent as it hangs; a tenth more is a pull
  const auto over = std::count_if(edges.begin(), edges.end(), [](const Stretched& e) { return e.ratio > kNoted; });
  fmt::print(out, "\ngarment edges stretched most over frames {} to {}: {} of {} are more than {:.0f} % longer than at "
                  "rest in some frame\n",
             frames.first, frames.last, over, edges.size(), 100.0 * (kNoted - 1.0));
  fmt::print(out, "{:<14}  {:>11}  {:>6}  {:<11}  {:>8}  {:<32}  {:<24}  {}\n", "garment", "vertices", "frame", "time code",
             "stretch", "states", "nearest collidable part", "next");
  const std::size_t shown = std::min(edges.size(), static_cast<std::size_t>(query.stretched));
  for (std::size_t i = 0; i < shown; ++i) {
    const Stretched& e = edges[i];
    const std::vector<Vec3>& p = run.positions(e.garment, e.frame);
    const Vec3 middle = 0.5 * (p[e.vertices[0]] + p[e.vertices[1]]);
    const std::vector<PartDistance> parts = nearestParts(bodyAt(run, e.frame, bodyOf(run, e.garment, collidable)), middle);
    const std::span<const std::uint8_t> states = run.states(e.garment, e.frame);
    fmt::print(out, "{:<14}  {:>11}  {:>6}  {:<11}  {:>8}  {:<32}  {:<24}  {}\n", run.meshes()[e.garment].name,
               fmt::format("{} {}", e.vertices[0], e.vertices[1]), e.frame, timeCode(run, e.frame),
               fmt::format("{:+.1f} %", 100.0 * (e.ratio - 1.0)),
               fmt::format("{}, {}", stateText(states, e.vertices[0]), stateText(states, e.vertices[1])),
               partText(run, parts, 0), partText(run, parts, 1));
  }
}

}  // namespace

void inspectRun(const std::string& directory, const RunQuery& query, std::ostream& out) {
  const render::RunReplay run(directory);
  const nlohmann::json stats = readStats(directory);
  const std::vector<std::size_t> collidable = collidableSegments(run, stats);
  const bool skin = !meshesWithRole(run, MeshRole::Skin).empty();
  printSummary(directory, run, stats, collidable, out);
  if (query.vertex < 0 && query.deepest <= 0 && query.stretched <= 0) {
    if (query.any()) throw Error("--range and --garment go with --vertex V, --deepest N or --stretched N");
    fmt::print(out, "look closer: --deepest N (the garment vertices deepest in the body), --stretched N (the edges "
                    "stretched most), --vertex V --range FIRST:LAST (one vertex frame by frame)\n");
    return;
  }
  const Frames frames = framesOf(run, query.range);
  if (query.deepest > 0) printDeepest(run, query, frames, skin, collidable, out);
  if (query.stretched > 0) printStretched(directory, run, query, frames, collidable, out);
  if (query.vertex >= 0) printVertexTrack(run, query, frames, collidable, out);
}

}  // namespace drape::cli
