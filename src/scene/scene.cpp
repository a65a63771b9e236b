#include "drape/scene/scene.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "drape/formats/vrml_read.hpp"
#include "drape/scene/scene_build.hpp"

namespace drape::scene {
namespace {

[[noreturn]] void bad(const SourcePos& at, const std::string& node, const std::string& what) {
  throw Error::at(at, fmt::format("{}: {}", node, what));
}

std::string label(const char* type, const std::string& name) {
  return name.empty() ? type : fmt::format("{} {}", type, name);
}

}  // namespace

double ClothMaterial::bendingStiffnessOrDerived() const {
  if (bendingStiffness >= 0.0) return bendingStiffness;
  return youngsModulus * thickness * thickness * thickness / (12.0 * (1.0 - poissonRatio * poissonRatio));
}

void validate(const ClothMaterial& m) {
  const std::string node = label("ClothMaterial", m.name);
  const auto positive = [&](double v, const char* field, const char* unit) {
    if (!std::isfinite(v) || v <= 0.0)
      bad(m.source, node,
          fmt::format("{} {:g} {} is {} (it must be greater than 0)", field, v, unit,
                      v < 0 ? "negative" : "not positive"));
  };
  positive(m.density, "density", "kg/m^3");
  positive(m.thickness, "thickness", "m");
  positive(m.youngsModulus, "youngsModulus", "Pa");
  if (!std::isfinite(m.poissonRatio) || m.poissonRatio < 0.0 || m.poissonRatio >= 0.5)
    bad(m.source, node, fmt::format("poissonRatio {:g} is outside [0, 0.5)", m.poissonRatio));
  const auto nonNegative = [&](double v, const char* field) {
    if (!std::isfinite(v) || v < 0.0)
      bad(m.source, node, fmt::format("{} {:g} is negative (it must be >= 0)", field, v));
  };
  if (!std::isfinite(m.bendingStiffness)) bad(m.source, node, "bendingStiffness is not a number");
  nonNegative(m.damping, "damping");
  nonNegative(m.staticFriction, "staticFriction");
  nonNegative(m.dynamicFriction, "dynamicFriction");
  if (!std::isfinite(m.compressionScale) || m.compressionScale < 0.0 || m.compressionScale > 1.0)
    bad(m.source, node, fmt::format("compressionScale {:g} is outside [0, 1]", m.compressionScale));
}

std::string offsetsProblem(const std::array<double, 4>& t) {
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (!std::isfinite(t[i]) || t[i] < 0.0) return fmt::format("offsets: T{} = {:g} m is negative", i, t[i]);
    if (i > 0 && t[i] < t[i - 1])
      return fmt::format("offsets must not decrease (T{} = {:g} m < T{} = {:g} m)", i, t[i], i - 1, t[i - 1]);
  }
  return "";
}

std::vector<int> layersOf(const std::vector<std::vector<std::size_t>>& below) {
  // By rounds: a garment whose garments below all have their layers takes one more than the
  // highest. A round that places none leaves only garments that go round or lie over them.
  std::vector<int> layer(below.size(), -1);
  for (bool placed = true; placed;) {
    placed = false;
    for (std::size_t g = 0; g < below.size(); ++g) {
      if (layer[g] >= 0) continue;
      int highest = -1;
      bool ready = true;
      for (const std::size_t b : below[g]) {
        ready = ready && layer[b] >= 0;
        highest = std::max(highest, layer[b]);
      }
      if (!ready) continue;
      layer[g] = highest + 1;
      placed = true;
    }
  }
  return layer;
}

std::vector<std::size_t> roundOfLayers(const std::vector<std::vector<std::size_t>>& below,
                                       const std::vector<int>& layers) {
  // A garment left at -1 is worn over one left at -1 too (else it would have a layer): going
  // down from one, a garment comes again, and what lies between is the round.
  const auto unplaced = std::find(layers.begin(), layers.end(), -1);
  if (unplaced == layers.end()) return {};
  std::vector<std::size_t> path{static_cast<std::size_t>(unplaced - layers.begin())};
  for (;;) {
    const std::vector<std::size_t>& under = below[path.back()];
    const std::size_t next = *std::find_if(under.begin(), under.end(), [&](std::size_t b) { return layers[b] < 0; });
    if (const auto again = std::find(path.begin(), path.end(), next); again != path.end()) {
      path.erase(path.begin(), again);
      path.push_back(next);
      return path;
    }
    path.push_back(next);
  }
}

void validate(const SimulationSettings& s) {
  const std::string node = "Simulation";
  const auto positive = [&](double v, const char* field) {
    if (!std::isfinite(v) || v <= 0.0) bad(s.source, node, fmt::format("{} {:g} must be greater than 0", field, v));
  };
  positive(s.frameRate, "frameRate");
  positive(s.voxelSize, "voxelSize");
  positive(s.unitScale, "unitScale");
  if (s.stepsPerFrame < 1) bad(s.source, node, fmt::format("stepsPerFrame {} must be at least 1", s.stepsPerFrame));
  if (s.collisionEvery < 1) bad(s.source, node, fmt::format("collisionEvery {} must be at least 1", s.collisionEvery));
  if (s.bendEvery < 1 || s.bendEvery > s.stepsPerFrame)
    bad(s.source, node, fmt::format("bendEvery {} must be in [1, stepsPerFrame {}]", s.bendEvery, s.stepsPerFrame));
  if (!std::isfinite(s.maxAddedMass) || s.maxAddedMass < 0.0 || s.maxAddedMass > 10.0)
    bad(s.source, node, fmt::format("maxAddedMass {:g} must be a fraction in [0, 10]", s.maxAddedMass));
  if (s.maxRefinement < 1 || s.maxRefinement > 64)
    bad(s.source, node, fmt::format("maxRefinement {} must be in [1, 64]", s.maxRefinement));
  const auto stretch = [&](double v, const char* field) {
    if (!std::isfinite(v) || v < 0.0 || v > 10.0)
      bad(s.source, node,
          fmt::format("{} {:g} must be a stretch beyond the rest length in [0, 10] (0.5: edges at most 1.5 times "
                      "as long; 0: none)",
                      field, v));
  };
  stretch(s.strainLimit, "strainLimit");
  stretch(s.rescueStrainLimit, "rescueStrainLimit");
  if (!(s.implicitTolerance > 0.0 && s.implicitTolerance < 1.0))
    bad(s.source, node,
        fmt::format("implicitTolerance {:g} must be a fraction in (0, 1) (the residual at which a backward-Euler "
                    "solve stops, against its start's; default 0.001)",
                    s.implicitTolerance));
  if (!std::isfinite(s.airViscosity) || s.airViscosity < 0.0)
    bad(s.source, node, fmt::format("airViscosity {:g} is negative", s.airViscosity));
  if (!s.gravity.allFinite() || !s.wind.allFinite()) bad(s.source, node, "gravity and wind must be finite");
  if (s.offsets)
    if (const std::string problem = offsetsProblem(*s.offsets); !problem.empty()) bad(s.source, node, problem);
  if (s.integrator.empty()) bad(s.source, node, "integrator is empty");
}

Scene loadScene(const std::string& path) { return buildScene(formats::vrml::readFile(path)); }

}  // namespace drape::scene
