#include "scene_add.hpp"

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <utility>
#include <sstream>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "drape/cloth/fixture.hpp"
#include "drape/cloth/model.hpp"
#include "drape/cloth/solver.hpp"
#include "drape/core/error.hpp"
#include "drape/formats/vrml_read.hpp"
#include "drape/mesh/topology.hpp"
#include "drape/scene/humanoid.hpp"
#include "drape/scene/scene_build.hpp"
#include "drape/sim/garment_layers.hpp"

namespace drape::cli {
namespace {

std::string readWhole(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(fmt::format("--add-to {}: cannot be read", path));
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::vector<std::string> characterNames(const std::vector<sim::SceneCharacter>& characters) {
  std::vector<std::string> names;
  for (const sim::SceneCharacter& c : characters) names.push_back(c.name);
  return names;
}

/// The character called `name`, or the only one when `name` is "".
sim::SceneCharacter takeCharacter(std::vector<sim::SceneCharacter> characters, const std::string& name,
                                  const std::string& path) {
  if (characters.empty())
    throw Error(fmt::format("--add-to {}: the scene has no avatar to dress (an Avatar node or an H-Anim Humanoid); "
                            "make a scene with one first (drape make-skirt AVATAR --out DIR, or drape make-scene)",
                            path));
  if (name.empty()) {
    if (characters.size() > 1)
      throw Error(fmt::format("--add-to {}: the scene has {} characters ({}); say which wears the garment with "
                              "--character NAME",
                              path, characters.size(), fmt::join(characterNames(characters), ", ")));
    return std::move(characters.front());
  }
  for (sim::SceneCharacter& c : characters)
    if (c.name == name) return std::move(c);
  throw Error(fmt::format("--character {}: {} has no character of that name (it has: {})", name,
                          path, fmt::join(characterNames(characters), ", ")));
}

/// The DEF name of the character's node in the scene's own file, which a ClothSet appended
/// to the file can USE. An Avatar node is found by the line it was read from (a nameless one
/// is called by its file's avatar name), a Humanoid by its name.
std::string avatarDefOf(const formats::vrml::Document& document, const sim::SceneCharacter& character, int line,
                        const std::string& path) {
  const std::string type = character.external ? "Avatar" : "Humanoid";
  const auto isCharacter = [&](const formats::vrml::Node& n) {
    return n.type == type && (character.external ? n.line == line : n.nameOrDef() == character.name);
  };
  const auto node = std::find_if(document.nodes.begin(), document.nodes.end(), isCharacter);
  const std::string at = line > 0 ? fmt::format(" (line {})", line) : "";
  if (node == document.nodes.end() || node->def.empty())
    throw Error(fmt::format("--add-to {}: the {} node of '{}'{} has no DEF name for the new ClothSet to USE; write "
                            "DEF NAME before it",
                            path, type, character.name, at));
  if (std::filesystem::path(node->file) != std::filesystem::path(document.file))
    throw Error(fmt::format("--add-to {}: the {} node of '{}' is written in {}, which the scene inlines; a ClothSet "
                            "added to the scene cannot USE it",
                            path, type, character.name, node->file));
  const auto sameDef = [&](const formats::vrml::Node& other) { return other.def == node->def; };
  if (std::count_if(document.nodes.begin(), document.nodes.end(), sameDef) > 1)
    throw Error(fmt::format("--add-to {}: DEF {} names more than one node; give the {} node of '{}' a name of its own",
                            path, node->def, type, character.name));
  return node->def;
}

/// An Avatar node's first url that is a file, from the scene's directory.
std::string firstExistingFile(const scene::ExternalAvatar& ext, const std::string& scenePath) {
  for (const std::string& url : ext.urls) {
    const std::filesystem::path p(url);
    const std::filesystem::path file =
        p.is_absolute() ? p : (std::filesystem::path(scenePath).parent_path() / p).lexically_normal();
    if (std::filesystem::is_regular_file(file)) return file.string();
  }
  return "";
}

}  // namespace

void addAddToOptions(CLI::App& app, AddToOptions& o, const std::string& addToHelp, const std::string& ownColour) {
  app.add_option("--add-to", o.scene, addToHelp);
  app.add_option("--character", o.character,
                 "With --add-to: the character who wears it (its Avatar or Humanoid node's name; default: the "
                 "scene's only one)");
  app.add_option("--over", o.over,
                 "With --add-to: the character's garments it is worn over, written as its over (kept --over-gap "
                 "above them; docs/PHYSICS.md)")
      ->delimiter(',');
  app.add_option("--over-gap", o.overGap_m,
                 "With --over: how far above them it keeps, m, written as its overGap (by default, on a character "
                 "under 1 m tall, less by its height against a person's 1.7 m)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--colour", o.colour,
                 fmt::format("Its colour, R,G,B from 0 to 1 (default: {}; with --add-to, a colour no garment of the "
                             "scene has)",
                             ownColour))
      ->delimiter(',')
      ->expected(3)
      ->check(CLI::Range(0.0, 1.0));
}

bool addingToScene(const CLI::App& app, const AddToOptions& o, const std::string& command, const std::string& avatar,
                   const std::string& out, const std::vector<std::string>& sceneOptions) {
  if (o.scene.empty()) {
    if (avatar.empty()) throw Error(fmt::format("{}: give the avatar to fit it to, or --add-to SCENE", command));
    if (out.empty()) throw Error(fmt::format("{}: --out DIR is required (or --add-to SCENE)", command));
    for (const char* option : {"--character", "--over", "--over-gap"})
      if (app.count(option) > 0) throw Error(fmt::format("{} goes with --add-to SCENE", option));
    return false;
  }
  if (!avatar.empty())
    throw Error(fmt::format("{} --add-to {}: the garment goes on the scene's character; give no avatar ({})", command,
                            o.scene, avatar));
  for (const std::string& option : sceneOptions)
    if (app.count(option) > 0)
      throw Error(fmt::format("{} does not go with --add-to: {} is added to the scene as it is, its OBJs written "
                              "beside it (edit {} for the scene's own settings)",
                              option, command == "make-skirt" ? "the skirt" : "the garment", o.scene));
  if (app.count("--over-gap") > 0 && o.over.empty()) throw Error("--over-gap goes with --over NAME,...");
  return true;
}

std::string fitToASmallCharacter(AddToOptions& o, const SceneToDress& dress, const SceneScale& scale) {
  if (scale.factor() == 1.0) return "";
  const double voxel = dress.scene.simulation.voxelSize;
  if (voxel > 2.0 * scale.voxel_m)
    spdlog::warn("{}: the scene's distance-field voxel is {:.2f} mm, for a character {:.2f} m tall; {:.2f} mm (offsets "
                 "T0..T3 {:.2f} to {:.2f} mm) keeps the offset surfaces of its small parts apart: set voxelSize and "
                 "offsets in its Simulation node (drape make-skirt and make-scene write them so for a new scene)",
                 dress.path, 1e3 * voxel, scale.height_m, 1e3 * scale.voxel_m, 1e3 * scale.voxel_m, 6e3 * scale.voxel_m);
  if (o.over.empty() || o.overGapGiven) return "";
  o.overGap_m *= scale.factor();
  return fmt::format("{:.2f} mm above {} (a person's: {:g} mm)", 1e3 * o.overGap_m, fmt::join(o.over, ", "),
                     1e3 * AddToOptions{}.overGap_m);
}

void dressFor(ClothSetText& c, const SceneToDress& dress, const AddToOptions& o, const std::string& material) {
  c.over = o.over;
  c.overGap_m = o.overGap_m;
  c.colour = o.colour.empty() ? unusedColour(dress.scene) : Vec3(o.colour[0], o.colour[1], o.colour[2]);
  c.material = material;
  c.avatar = dress.avatarDef;
}

std::string addedComment(const std::string& command, const std::string& name, const SceneToDress& dress,
                         const AddToOptions& o) {
  return fmt::format("# {}: added by `drape {} --add-to`, worn by {}{}.\n", name, command, dress.character.name,
                     o.over.empty() ? "" : fmt::format(" over {}", fmt::join(o.over, ", ")));
}

std::string wornText(const SceneToDress& dress, const AddToOptions& o) {
  return fmt::format("worn by {}{}", dress.character.name,
                     o.over.empty() ? "" : fmt::format(" over {}, {:g} m above", fmt::join(o.over, ", "), o.overGap_m));
}

void printSceneSteps(const SceneToDress& dress, double addedMassFraction) {
  fmt::print("the scene's {} substeps per frame keep it stable{}\n", dress.scene.simulation.stepsPerFrame,
             addedMassFraction > 0.0 ? fmt::format(" (mass scaling adds {:.2f} % of its mass)", 100.0 * addedMassFraction)
                                     : "");
}

SceneToDress openSceneToDress(const std::string& path, const std::string& character) {
  SceneToDress d;
  d.path = path;
  d.text = readWhole(path);
  // The text read once: what is parsed is what the garment is appended to.
  const std::string dir = std::filesystem::path(path).parent_path().string();
  const formats::vrml::Document document = formats::vrml::readText(d.text, path, dir.empty() ? "." : dir);
  d.scene = scene::buildScene(document);
  // An avatar that wears nothing yet is dressed as well as one that does.
  d.character = takeCharacter(sim::sceneCharacters(d.scene, sim::Undressed::included), character, path);
  // A garment fitted to a character lying across gravity would fall across it, and stays
  // where it was fitted when the character is stood up: it is stood up first.
  if (const std::optional<scene::Upright> u = sim::lyingAcrossGravity(d.scene, *d.character.avatar))
    throw Error(fmt::format("--add-to {}: character '{}' stands along {}, not along +y as drape's scenes do, and a "
                            "garment would fall across it; {}, then dress it",
                            path, d.character.name, u->axis, u->standUpAdvice()));
  int line = 0;
  if (d.character.external) {
    for (const scene::ExternalAvatar& ext : d.scene.externalAvatars) {
      if ((ext.name.empty() ? d.character.avatar->name : ext.name) != d.character.name) continue;
      d.avatarFile = firstExistingFile(ext, path);
      d.placement = ext.placement;
      d.scale = ext.scale;
      line = ext.source.line;
    }
  }
  d.avatarDef = avatarDefOf(document, d.character, line, path);
  return d;
}

void checkNewGarment(const SceneToDress& dress, const std::string& name, const std::vector<std::string>& over) {
  for (const scene::Garment& g : dress.scene.garments)
    if (g.name == name)
      throw Error(fmt::format("--add-to {}: the scene has a garment called '{}' already; call this one something else "
                              "with --name",
                              dress.path, name));
  std::vector<std::string> own;
  for (const std::size_t g : dress.character.garments) own.push_back(dress.scene.garments[g].name);
  for (const std::string& below : over)
    if (std::find(own.begin(), own.end(), below) == own.end())
      throw Error(fmt::format("--over {}: not a garment of '{}' in {} (it wears: {})", below, dress.character.name,
                              dress.path, fmt::join(own, ", ")));
}

double checkSceneSteps(const SceneToDress& dress, const mesh::TriMesh& garment, const cloth::Material& material,
                       const std::string& name) {
  const scene::SimulationSettings& s = dress.scene.simulation;
  const cloth::StepSettings steps = sim::toStepSettings(s);
  const mesh::Topology topology = mesh::Topology::build(garment);
  // Backward Euler is stable at any substep with no mass added.
  const double added = steps.integrator == cloth::IntegratorKind::BackwardEuler
                           ? 0.0
                           : cloth::addedMassFractionAt(garment, topology, material, s.frameRate, s.stepsPerFrame,
                                                        steps.massScalingBound());
  if (added > s.maxAddedMass) {
    const int needed = cloth::fewestStableSubsteps(garment, topology, material, s.frameRate, s.maxAddedMass,
                                                   s.stepsPerFrame, steps.massScalingBound())
                           .substepsPerFrame;
    throw Error(fmt::format("--add-to {}: the scene steps {} substeps per frame, and '{}' needs {} to be stable (mass "
                            "scaling within the scene's maxAddedMass {:g}); set stepsPerFrame {} in its Simulation "
                            "node first",
                            dress.path, s.stepsPerFrame, name, needed, s.maxAddedMass, needed));
  }
  // Unscaled masses, as drape make-scene checks its own rhythm: scaling only slows bending.
  mesh::TriMesh named = garment;
  named.name = name;
  const auto model = cloth::ClothModel::build(named, topology, material);
  try {
    cloth::checkBendingStep(*model, steps);
  } catch (const Error& e) {
    throw Error(fmt::format("--add-to {}: the scene's bendEvery {} is too long for the new garment: {}", dress.path,
                            s.bendEvery, e.what()));
  }
  return added;
}

Vec3 unusedColour(const scene::Scene& scene) {
  // The two make-* commands' own colours first, then others that read apart from them.
  static const std::array<Vec3, 6> kColours{Vec3{0.7, 0.15, 0.2},  Vec3{0.15, 0.25, 0.55}, Vec3{0.92, 0.9, 0.84},
                                            Vec3{0.2, 0.5, 0.3},   Vec3{0.85, 0.6, 0.15},  Vec3{0.45, 0.25, 0.55}};
  for (const Vec3& c : kColours) {
    const auto taken = [&](const scene::Garment& g) { return g.colour && (*g.colour - c).norm() < 0.05; };
    if (std::none_of(scene.garments.begin(), scene.garments.end(), taken)) return c;
  }
  return kColours[scene.garments.size() % kColours.size()];
}

mesh::TriMesh inFileUnits(const SceneToDress& dress, mesh::TriMesh world) {
  world.scale(1.0 / dress.scene.simulation.unitScale);
  return world;
}

namespace {

/// What of garment g of `scene` (worn by `avatar`) starts under the garments it is worn over,
/// and what the set-up of a run moves out over them: the layer collider `drape run` makes for
/// it, on solvers at rest.
std::pair<cloth::StartUnder, cloth::LiftedOver> underAtStart(const scene::Scene& scene, const scene::Avatar& avatar,
                                                             std::size_t g) {
  const std::vector<sim::GarmentSpec> specs = sim::garmentSpecs(scene, &avatar);
  const std::vector<std::vector<std::size_t>> below = sim::garmentsBelow(specs);
  if (below[g].empty()) return {};
  const cloth::StepSettings settings = sim::toStepSettings(scene.simulation);
  std::vector<std::unique_ptr<cloth::ClothSolver>> solvers(specs.size());
  const auto solver = [&](std::size_t i) -> cloth::ClothSolver& {
    if (!solvers[i]) {
      const mesh::Topology topology = mesh::Topology::build(specs[i].mesh);
      const auto model = cloth::ClothModel::build(specs[i].mesh, topology, specs[i].material, settings.massScaling());
      // Held where drape run holds them (pinned, and bound by the mask): the solver's
      // damping check measures the membrane's frequency with them fixed, as the run's does.
      std::vector<std::uint32_t> held = specs[i].pinned;
      held.insert(held.end(), specs[i].bound.begin(), specs[i].bound.end());
      std::sort(held.begin(), held.end());
      held.erase(std::unique(held.begin(), held.end()), held.end());
      std::vector<cloth::PinGroup> pins;
      if (!held.empty()) pins.push_back(cloth::PinGroup::atRest(held, model->restX(), model->restY(), model->restZ()));
      solvers[i] = std::make_unique<cloth::ClothSolver>(model, settings, std::move(pins));
    }
    return *solvers[i];
  };
  const auto layers =
      sim::makeLayerCollider(specs, g, below[g], specs[g].bound, solver, 1.0 / settings.frameRate_hz, &avatar);
  return {layers->startUnder(), layers->liftedOver()};
}

}  // namespace

void appendToScene(const SceneToDress& dress, const std::string& clothSet) {
  std::string text = dress.text;
  if (!text.empty() && text.back() != '\n') text += '\n';
  text += "\n" + clothSet;
  const std::string dir = std::filesystem::path(dress.path).parent_path().string();
  scene::Scene added;
  try {
    added = scene::buildScene(formats::vrml::readText(text, dress.path, dir.empty() ? "." : dir));
    if (added.garments.size() != dress.scene.garments.size() + 1)
      throw Error(fmt::format("{} garments read back where {} were written", added.garments.size(),
                              dress.scene.garments.size() + 1));
  } catch (const Error& e) {
    throw Error(fmt::format("--add-to {}: the scene with the garment added would not load, so it is left as it was: {}",
                            dress.path, e.what()));
  }
  const scene::Garment& garment = added.garments.back();
  const auto [under, lifted] = underAtStart(added, *dress.character.avatar, added.garments.size() - 1);
  const std::string below = fmt::format("{}", fmt::join(garment.over, ", "));
  if (lifted.leftUnder > 0)
    throw Error(fmt::format("--add-to {}: {} of the vertices of '{}' lie under {} by more than {:.4g} mm (the deepest, "
                            "vertex {}, {:.1f} mm), too deep for drape run to move them out over {}: it would go "
                            "through {}. Make it wider or further out from the body (for a skirt, a larger "
                            "--clearance or --flare); the scene is left as it was",
                            dress.path, lifted.leftUnder, garment.name, below,
                            1e3 * cloth::LayerCollider::kLiftDepthGaps * garment.overGap, under.deepestVertex,
                            1e3 * under.deepest_m, garment.over.size() == 1 ? "it" : "them", below));
  if (lifted.vertices > 0)
    fmt::print("{} of its vertices lie under {} by up to {:.1f} mm: drape run moves them out over {}\n",
               lifted.vertices, below, 1e3 * under.deepest_m, garment.over.size() == 1 ? "it" : "them");
  // Written beside it and renamed over it: the scene is never left half written.
  const std::string temporary = dress.path + ".adding";
  {
    std::ofstream os(temporary, std::ios::binary);
    os << text;
    if (!os.flush()) throw Error(fmt::format("{}: cannot be written", temporary));
  }
  std::error_code ec;
  std::filesystem::rename(temporary, dress.path, ec);
  if (ec) {
    std::filesystem::remove(temporary, ec);
    throw Error(fmt::format("--add-to {}: cannot be replaced ({})", dress.path, ec.message()));
  }
}

}  // namespace drape::cli
