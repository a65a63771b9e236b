#include "run_setup.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <array>
#include <limits>
#include <optional>
#include <span>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "drape/cloth/forces.hpp"
#include "drape/cloth/model.hpp"
#include "drape/cloth/layer_collider.hpp"
#include "drape/cloth/solver.hpp"
#include "drape/core/error.hpp"
#include "drape/core/files.hpp"
#include "drape/core/log.hpp"
#include "drape/core/progress.hpp"
#include "drape/studio/takes.hpp"
#include "drape/events/runtime.hpp"
#include "drape/formats/hanim_motion.hpp"
#include "drape/mesh/topology.hpp"
#include "drape/render/frame.hpp"
#include "drape/scene/scene.hpp"
#include "drape/sim/body_overlap.hpp"
#include "drape/sim/garment_layers.hpp"
#include "drape/sim/scene_setup.hpp"
#include "frames_ahead.hpp"
#include "measure.hpp"
#include "run_writer.hpp"
#include "stage_laps.hpp"

namespace drape::cli {
namespace {

/// Where the garment starts inside the offset surfaces (eased out onto T2 rather than thrown
/// there): a garment tighter than the offsets, which a user may want to loosen or offset less.
void logEasedPairs(const std::string& garment, const cloth::FieldCollider& collider) {
  const std::vector<std::size_t> counts = collider.easedPairsPerPart();
  std::vector<std::pair<std::size_t, std::string>> parts;
  std::size_t total = 0;
  for (std::size_t k = 0; k < counts.size(); ++k) {
    total += counts[k];
    if (counts[k] > 0) parts.push_back({counts[k], collider.parts()[k].name});
  }
  if (total == 0) return;
  std::sort(parts.begin(), parts.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<std::string> most;
  for (std::size_t j = 0; j < parts.size() && j < 4; ++j) most.push_back(fmt::format("{} {}", parts[j].second, parts[j].first));
  if (parts.size() > 4) most.push_back(fmt::format("{} more parts", parts.size() - 4));
  spdlog::info("{}: {} (vertex, part) pairs start below T2 ({:g} mm), the garment tighter than the offset surfaces "
               "there; they are eased out onto T2: {}",
               garment, total, 1e3 * collider.offsets().t2_m, fmt::join(most, ", "));
}

/// How much of what the substep allows the internal damping takes (the solver has refused
/// more): near 100 %, a little more damping, or fewer substeps, will diverge. Forward Euler:
/// where in its window the damping lies.
void logDamping(const std::string& garment, const cloth::ClothSolver& solver) {
  const double omega = solver.dampedMembraneFrequency_rad_s();
  if (!(omega > 0.0)) return;  // undamped symplectic Euler
  if (solver.settings().integrator == cloth::IntegratorKind::RungeKutta4) return;  // its own line
  const double beta = solver.model().material().damping_s;
  const double dt = solver.settings().substep_s();
  if (solver.settings().integrator == cloth::IntegratorKind::ForwardEuler) {
    const cloth::ForwardEulerDampingWindow window = cloth::forwardEulerDampingWindow(omega, dt);
    spdlog::info("{}: forward Euler with internal damping {:.3g} ms, within the {:.3g} to {:.3g} ms the {:.3g} ms "
                 "substep allows",
                 garment, 1e3 * beta, 1e3 * window.least_s, 1e3 * window.most_s, 1e3 * dt);
    return;
  }
  const double most = cloth::largestStableDamping_s(omega, dt);
  if (most > 0.0)
    spdlog::info("{}: internal damping {:.3g} ms, {:.0f} % of the most the {:.3g} ms substep allows ({:.3g} ms)",
                 garment, 1e3 * beta, 100.0 * beta / most, 1e3 * dt, 1e3 * most);
}

using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

/// Triangles smaller than this (m^2) are degenerate for the membrane model.
constexpr double kMinTriangleArea_m2 = 1e-12;

/// What of a garment was modelled under the garments it is worn over, and what the set-up
/// did with it (cloth::LayerCollider::liftOver).
void logStartUnder(const std::string& name, const cloth::LayerCollider& layers) {
  const cloth::StartUnder& under = layers.startUnder();
  const cloth::LiftedOver& lifted = layers.liftedOver();
  const std::string below = fmt::format("{}", fmt::join(layers.garmentsBelow(), ", "));
  const char* them = layers.garmentsBelow().size() == 1 ? "it" : "them";
  if (lifted.vertices == 0 && !layers.sidesFromBody() && !layers.belowWoundOneWay()) {
    spdlog::warn("{}: {} of its {} vertices over {} start under {}, on the other side from the rest (the deepest, "
                 "vertex {}, {:.1f} mm), and the faces of {} are not all wound one way, so which side is over cannot "
                 "be told: they were left where they are, passing through {} with their triangles. Wind the faces of "
                 "{} one way, or model {} over {}",
                 name, under.vertices, under.over, below, them, under.deepestVertex, 1e3 * under.deepest_m, below,
                 below, below, name, them);
    return;
  }
  const std::string side = layers.sidesFromBody() ? ", on the body's side" : "";
  spdlog::info("{}: {} of its {} vertices near {} were modelled under {}{} (the deepest, vertex {}, {:.1f} mm): {} "
               "moved out over {}, {:.4g} mm above",
               name, under.vertices, under.over, below, them, side, under.deepestVertex, 1e3 * under.deepest_m,
               lifted.vertices, them, 1e3 * layers.gap_m());
  if (lifted.leftUnder > 0)
    spdlog::warn("{}: {} of its vertices lie too far under {} to be moved out (more than {:.4g} mm, the deepest {:.1f} "
                 "mm): they were left there, and {} passes through {} there, those vertices and their triangles. "
                 "Model {} over {} (wider, or further out from the body)",
                 name, lifted.leftUnder, below, 1e3 * cloth::LayerCollider::kLiftDepthGaps * layers.gap_m(),
                 1e3 * under.deepest_m, name, below, name, below);
}

/// One garment being simulated: its model and solver (and its collider, on a character).
struct GarmentRun {
  std::string name;
  const cloth::ClothModel* model = nullptr;
  std::unique_ptr<cloth::ClothSolver> ownedSolver;  ///< without a character
  cloth::ClothSolver* solver = nullptr;             ///< owned here or by the character world
  const cloth::FieldCollider* collider = nullptr;   ///< on a character
  std::unique_ptr<cloth::LayerCollider> ownedLayers;  ///< without a character
  const cloth::LayerCollider* layers = nullptr;        ///< its own layers and the garments below kept apart, or null
  std::vector<cloth::SphereCollider> spheres;       ///< its own static spheres (--sphere)
};

std::vector<cloth::PinGroup> pinsOf(const GarmentSetup& g, const cloth::ClothModel& model) {
  if (g.pinned.empty()) return {};
  return {cloth::PinGroup::atRest(g.pinned, model.restX(), model.restY(), model.restZ())};
}

/// The paper's Table 3 figures and ours: how much time went to collisions, how far points
/// were traced, where they are, and how deep anything got.
void addCollisionStats(nlohmann::json& stats, const std::vector<GarmentRun>& runs, const cloth::StageTimes& total,
                       long frames, const SetupWorlds& worlds) {
  // As in the paper's Table 3, the share leaves out the animation and its interpolation: the
  // pose fetches the collider makes (timed inside its stage) and the fixtures make.
  // Nor does it count the measuring of the penetration figures below, timed inside the
  // collider's stage: a measurement, not the collision's work.
  double colliderPoses_s = 0, measure_s = 0;
  for (const GarmentRun& r : runs)
    if (r.collider) {
      colliderPoses_s += r.collider->poseSeconds();
      measure_s += r.collider->measureSeconds();
    }
  const double poses_s = colliderPoses_s + total.fixturePoses_s;
  const double simulated = stepSeconds(total) - poses_s - measure_s;
  stats["collision_time_share"] = simulated > 0 ? (total.collide_s - colliderPoses_s - measure_s) / simulated : 0.0;
  stats["penetration_measure_ms_per_frame"] = 1e3 * measure_s / static_cast<double>(std::max(1L, frames));
  stats["animation_ms_per_frame"] = 1e3 * poses_s / static_cast<double>(std::max(1L, frames));
  cloth::FieldCollisionCounters sum;
  std::array<std::size_t, 3> states{};
  for (const GarmentRun& r : runs) {
    if (!r.collider) continue;
    sum += r.collider->fieldCounters();
    if (const std::uint64_t late = r.collider->fieldCounters().embeddedTimedOut; late > 0)
      spdlog::info("{}: {} of the eased pairs were still below T2 after twice their easing time, held there by "
                   "the garment; they collided as any other from then on",
                   r.name, late);
    const auto now = r.collider->pointsPerState();
    for (int k = 0; k < 3; ++k) states[k] += now[k];
  }
  stats["mean_collision_path_voxels"] = sum.meanPathVoxels();
  stats["points_per_state"] = {{"outside_vol", states[0]}, {"inside_vol", states[1]}, {"on_surf", states[2]}};
  stats["vertex_substeps"] = sum.vertexSubsteps;  // free vertices x the substeps counted
  int every = 1;
  bool everySubstep = true;
  for (const GarmentRun& r : runs)
    if (r.collider) {
      every = std::max(every, r.collider->every());
      everySubstep = everySubstep && r.collider->countsEverySubstep();
    }
  stats["collision_every"] = every;
  stats["penetration_counted_on"] = everySubstep ? "every substep" : "tested substeps";
  stats["vertex_substeps_below_T1"] = sum.vertexSubstepsBelowT1;
  stats["vertex_substeps_below_T0"] = sum.vertexSubstepsBelowT0;
  stats["vertex_substeps_inside_body"] = sum.vertexSubstepsInsideBody;
  stats["vertex_substeps_below_T1_pinched"] = sum.vertexSubstepsBelowT1Pinched;
  stats["vertex_substeps_inside_body_pinched"] = sum.vertexSubstepsInsideBodyPinched;
  stats["max_penetration_m"] = sum.maxPenetration_m;
  stats["collisions_registered"] = sum.collisions;
  stats["last_resort_projections"] = sum.projections;
  stats["pairs_embedded_at_start"] = sum.embeddedAtStart;
  stats["pairs_embedded_timed_out"] = sum.embeddedTimedOut;
  stats["sliding_reads_from_contact_planes"] = sum.slidingReadsFromPlanes();
  stats["vertex_substeps_held_in_pinches"] = sum.heldVertexSubsteps;
  stats["vertex_tests_pinched"] = sum.pinchedVertexTests;
  stats["crease_moves"] = sum.creaseMoves;
  stats["crease_moves_refused"] = sum.creaseMovesRefused;
  stats["part_tests_out_of_reach"] = sum.partsOutOfReach;
  stats["face_tests"] = sum.faceTests;
  stats["face_contacts"] = sum.faceContacts;
  stats["face_contacts_inside_body"] = sum.facesInsideBody;
  nlohmann::json transitions;
  const char* names[3] = {"outside_vol", "inside_vol", "on_surf"};
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) transitions[std::string(names[a]) + "->" + names[b]] = sum.transitions[a][b];
  stats["state_transitions"] = transitions;
  if (worlds.size() > 0) {
    nlohmann::json fields = nlohmann::json::array();
    double build_s = 0.0;
    for (std::size_t c = 0; c < worlds.size(); ++c) {
      for (const sim::PartField& f : worlds.world(c).fields()) {
        const auto& d = f.field.dims();
        nlohmann::json entry = {
            {"segment", f.segment},
            {"dims", {d.nx, d.ny, d.nz}},
            {"bytes", f.field.memoryBytes()},
            {"build_ms", f.field.stats().voxelizeMs + f.field.stats().propagateMs + f.field.stats().finishMs}};
        if (worlds.size() > 1) entry["character"] = worlds.characterName(c);
        fields.push_back(std::move(entry));
      }
      build_s += worlds.world(c).fieldBuild_s();
    }
    stats["distance_fields"] = fields;
    stats["distance_field_build_s"] = build_s;
  }
}

}  // namespace

double leastT0(const sim::CharacterWorld& world) {
  double t0 = std::numeric_limits<double>::infinity();
  for (std::size_t g = 0; g < world.garmentCount(); ++g)
    if (const cloth::FieldCollider* c = world.collider(g)) t0 = std::min(t0, c->offsets().t0_m);
  return std::isfinite(t0) ? t0 : 0.0;
}

RunSetup runSetupFromScene(const std::string& scenePath, const std::optional<std::vector<std::string>>& cutAtJoints) {
  scene::Scene sc = scene::loadScene(scenePath);
  for (const std::string& w : sc.warnings) spdlog::warn("{}", w);
  if (sc.garments.empty()) throw Error(fmt::format("{}: the scene has no ClothSet to simulate", scenePath));
  if (cutAtJoints) {
    if (!cutAtJoints->empty() && sc.externalAvatars.empty())
      throw Error(fmt::format("--cut-at-joints cuts a skinned avatar's parts again; {} has no Avatar node (an H-Anim "
                              "Humanoid's parts are rigid as written)",
                              scenePath));
    for (scene::ExternalAvatar& a : sc.externalAvatars) a.cutAtJoints = *cutAtJoints;
  }
  RunSetup setup;
  std::vector<sim::SceneCharacter> characters = sim::sceneCharacters(sc);
  sim::warnOfLyingCharacters(sc, characters);
  setup.settings = sim::toStepSettings(sc.simulation);
  setup.garments = sim::garmentSpecs(sc, characters);
  for (sim::SceneCharacter& c : characters) {
    CharacterSetup& ch = setup.characters.emplace_back();
    ch.avatar = std::shared_ptr<const scene::Avatar>(std::move(c.avatar));
    ch.voxel_m = sc.simulation.voxelSize;
    ch.keepApart = sc.simulation.keepApart;
    ch.name = c.name;
    ch.garments = c.garments;
    ch.motion = c.motion;
    // Alone in its scene, the character answers to every avatar name the scene has (a
    // Humanoid inside an Avatar node's file, say); among several, to its own.
    if (characters.size() == 1) {
      for (const scene::ExternalAvatar& a : sc.externalAvatars)
        if (!a.name.empty()) ch.names.push_back(a.name);
      for (const scene::Avatar& a : sc.avatars)
        if (!a.name.empty()) ch.names.push_back(a.name);
    } else {
      ch.names.push_back(c.name);
    }
    if (const std::string bad = unknownKeepApartPart(ch); !bad.empty())
      throw Error::at(sc.simulation.source, "Simulation keepApart: " + bad);
  }
  return setup;
}

TimeCode frameTimeCode(const RunSetup& setup, long frame) {
  const double rate = setup.settings.frameRate_hz;
  if (setup.timeCodeOfFrame0) return TimeCode{*setup.timeCodeOfFrame0 + frame, rate};
  if (setup.characters.empty()) return TimeCode{frame, rate};
  const CharacterSetup& first = setup.characters.front();
  const TimeCode motionStart = first.animation ? first.animation->start() : TimeCode{0, rate};
  return studio::clothTimeCode(frame, TimeCode{motionStart.frame, rate}, first.leadIn_s);
}

std::string characterNames(const RunSetup& setup) {
  std::vector<std::string> names;
  for (const CharacterSetup& c : setup.characters) names.push_back(c.name);
  return fmt::format("{}", fmt::join(names, ", "));
}

std::optional<std::pair<std::size_t, std::string>> forCharacter(const RunSetup& setup, const std::string& value,
                                                                const std::string& option) {
  const auto eq = value.find('=');
  if (eq == std::string::npos || eq == 0 || std::filesystem::exists(value)) return std::nullopt;
  const CharacterSetup& c = characterNamed(setup, value.substr(0, eq), option + " " + value);
  if (eq + 1 == value.size()) throw Error(fmt::format("{} {}: expected NAME=VALUE after the name", option, value));
  return std::pair{static_cast<std::size_t>(&c - setup.characters.data()), value.substr(eq + 1)};
}

CharacterSetup* oneCharacter(RunSetup& setup, const std::string& what) {
  return const_cast<CharacterSetup*>(oneCharacter(std::as_const(setup), what));
}

const CharacterSetup* oneCharacter(const RunSetup& setup, const std::string& what) {
  if (setup.characters.size() > 1)
    throw Error(fmt::format("{} plays one character; the scene has {} ({})", what, setup.characters.size(),
                            characterNames(setup)));
  return setup.characters.empty() ? nullptr : &setup.characters.front();
}

CharacterSetup* chooseCharacter(RunSetup& setup, const std::string& name, const std::string& option) {
  if (setup.characters.empty()) return nullptr;
  if (name.empty()) {
    if (setup.characters.size() > 1)
      throw Error(fmt::format("the scene has {} characters ({}), and a studio role plays one: give {} NAME",
                              setup.characters.size(), characterNames(setup), option));
    return &setup.characters.front();
  }
  const CharacterSetup& chosen = characterNamed(setup, name, option + " " + name);
  const std::vector<std::size_t> worn = chosen.garments;
  keepGarmentsWhere(setup, [&](std::size_t g) { return std::find(worn.begin(), worn.end(), g) != worn.end(); });
  return &setup.characters.front();
}

const CharacterSetup& characterNamed(const RunSetup& setup, const std::string& name, const std::string& option) {
  for (const CharacterSetup& c : setup.characters)
    if (c.name == name) return c;
  throw Error(fmt::format("{}: the scene has no character called '{}' (it has: {})", option, name,
                          setup.characters.empty() ? std::string("none") : characterNames(setup)));
}

void keepGarmentsWhere(RunSetup& setup, const std::function<bool(std::size_t garment)>& keep) {
  std::vector<std::size_t> renumbered(setup.garments.size(), setup.garments.size());
  std::vector<GarmentSetup> kept;
  for (std::size_t g = 0; g < setup.garments.size(); ++g)
    if (keep(g)) {
      renumbered[g] = kept.size();
      kept.push_back(std::move(setup.garments[g]));
    }
  setup.garments = std::move(kept);
  for (CharacterSetup& c : setup.characters) {
    std::vector<std::size_t> worn;
    for (const std::size_t g : c.garments)
      if (renumbered[g] < setup.garments.size()) worn.push_back(renumbered[g]);
    c.garments = std::move(worn);
  }
  std::erase_if(setup.characters, [](const CharacterSetup& c) { return c.garments.empty(); });
}

std::vector<GarmentSetup> garmentsOf(const RunSetup& setup, const CharacterSetup& character) {
  std::vector<GarmentSetup> out;
  for (const std::size_t g : character.garments) out.push_back(setup.garments[g]);
  return out;
}

motion::MotionOptions motionOptions(const RunSetup& setup) {
  motion::MotionOptions mo;
  mo.clip.rate = setup.settings.frameRate_hz;
  mo.jointMapDirectory = std::string(DRAPE_SHARE_DIR) + "/jointmaps";
  return mo;
}

void addMotion(const RunSetup& setup, CharacterSetup& character, const std::string& motionPath, double metresPerUnit,
               const std::string& jointMap, const std::string& animation, const formats::SkinnedJointMotion* sampled) {
  motion::MotionOptions mo = motionOptions(setup);
  if (metresPerUnit > 0) mo.clip.metresPerUnit = metresPerUnit;
  mo.jointMapPath = jointMap;
  mo.animation = animation;
  mo.sampled = sampled;
  motion::ClipLoadReport report;
  motion::JointMap map;
  character.animation = std::make_shared<const motion::AvatarAnimation>(
      motion::loadAnimation(*character.avatar, motionPath, mo, &report, &map));
  // What was read and how it drives the avatar: a wrong unit or a poor map shows here first.
  const std::span<const int> driving = character.animation->drivingJoint();
  const auto driven = std::count_if(driving.begin(), driving.end(), [](int j) { return j >= 0; });
  spdlog::info("{}: {} frames at {:g} Hz in {}{}; joint map '{}' drives {} of {}'s {} joints", motionPath,
               report.sourceFrames, report.sourceRate, report.units.name, report.unitsOverridden ? " (given)" : "",
               map.name, driven, setup.characters.size() > 1 ? character.name : std::string("the avatar"),
               driving.size());
  // Frames the motion file holds but drape does not play: say so, the timing shifts.
  if (report.standingAxis != "+y") spdlog::info("{}: {}", motionPath, report.stoodUp());
  if (report.referenceTPoseSkipped) spdlog::info("{}: {}", motionPath, report.referenceTPose());
  if (report.restUnfoldFramesSkipped > 0) spdlog::info("{}: {}", motionPath, report.restUnfoldSkipped());
}

std::vector<events::Actor> eventActors(const std::vector<CharacterSetup>& characters) {
  std::vector<events::Actor> actors;
  for (const CharacterSetup& c : characters) actors.push_back({c.avatar.get(), c.names});
  return actors;
}

std::vector<std::pair<std::string, std::string>> parameterOptions(const std::vector<std::string>& sets) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const std::string& set : sets) {
    const auto eq = set.find('=');
    if (eq == std::string::npos || eq == 0)
      throw Error(fmt::format("--set {}: expected NAME=VALUE (a parameter of the event graph)", set));
    out.emplace_back(set.substr(0, eq), set.substr(eq + 1));
  }
  return out;
}

namespace {

/// --send NAME@SECONDS options as timed events; throws naming --send.
std::vector<events::TimedEvent> timedEvents(const std::vector<std::string>& sends) {
  std::vector<events::TimedEvent> out;
  for (const std::string& send : sends) {
    const auto at = send.rfind('@');
    double seconds = -1.0;
    if (at != std::string::npos && at > 0) {
      try {
        std::size_t used = 0;
        seconds = std::stod(send.substr(at + 1), &used);
        if (used != send.size() - at - 1) seconds = -1.0;
      } catch (const std::exception&) {
        seconds = -1.0;
      }
    }
    if (!(seconds >= 0.0) || !std::isfinite(seconds))
      throw Error(fmt::format("--send {}: expected EVENT@SECONDS (an event for the graph's state machines, at a time "
                              "of the script)",
                              send));
    out.push_back({send.substr(0, at), seconds});
  }
  return out;
}

}  // namespace

void addEvents(RunSetup& setup, const std::string& graphPath, const std::vector<std::string>& sets,
               const std::vector<std::string>& sends, long motionFrames) {
  if (setup.characters.empty()) throw Error("--events: there is no avatar for the event graph to move");
  const events::Graph graph = events::readGraph(graphPath);
  const std::vector<events::Actor> actors = eventActors(setup.characters);
  events::Motions motions;
  motions.load(graph, actors, motionOptions(setup));
  events::RenderedCast r = events::render(graph, motions, actors, setup.settings.frameRate_hz, motionFrames,
                                          timedEvents(sends), parameterOptions(sets));
  spdlog::info("{}: the event graph runs {} frames ({:.2f} s){}", graphPath, r.frames,
               static_cast<double>(r.frames - 1) / setup.settings.frameRate_hz,
               r.ended ? "" : ", cut there (it runs on)");
  for (std::size_t c = 0; c < setup.characters.size(); ++c)
    setup.characters[c].animation = std::make_shared<const motion::AvatarAnimation>(std::move(r.animations[c]));
  const bool windy = std::any_of(r.wind.begin(), r.wind.end(), [](const auto& w) { return w.has_value(); });
  setup.motionWind = windy ? std::make_shared<const MotionWind>(std::move(r.wind)) : nullptr;
}

namespace {

/// The animated H-Anim Humanoid `avatar` is, in the VRML97 file it was read from (the scene
/// itself, or the file an Avatar node names): its ROUTEd interpolators, sampled at `rate`;
/// null when nothing moves it. A file without any ROUTE, the common case, is not read again.
std::shared_ptr<const formats::SkinnedJointMotion> humanoidMotion(const scene::Avatar& avatar, double rate) {
  if (!formats::isVrmlPath(avatar.source)) return nullptr;
  if (readFileText(avatar.source).value_or("").find("ROUTE") == std::string::npos) return nullptr;
  for (formats::SkinnedJointMotion& m : formats::readHanimMotions(avatar.source, rate))
    if (m.animation == avatar.name) return std::make_shared<const formats::SkinnedJointMotion>(std::move(m));
  return nullptr;
}

}  // namespace

MotionChoice sceneMotion(const RunSetup& setup, const CharacterSetup* character, const std::string& scenePath,
                         const std::string& motion, const std::string& animation) {
  if (motion == "none") {
    if (!animation.empty())
      throw Error(fmt::format("--animation {}: it chooses one of a motion file's animations, and --motion none plays none",
                              animation));
    return {};
  }
  if (!motion.empty()) return {motion, animation, nullptr};
  const std::string nothingToChoose = fmt::format(
      "--animation {}: the avatar's own file carries no animation to choose from; give the motion with --motion FILE",
      animation);
  if (!character) {
    if (!animation.empty()) throw Error(nothingToChoose);
    return {};
  }
  // With no motion given, the avatar plays what its own file carries, as a viewer of that
  // file would: a glTF, Collada or FBX file's animation, or the interpolators a VRML97
  // file ROUTEs into its Humanoid. Logged, with how to keep it at rest.
  const scene::Avatar& avatar = *character->avatar;
  if (!avatar.animations.empty()) {
    const std::size_t index = formats::detail::chooseAnimation(avatar.animations, animation, avatar.source);
    spdlog::info("{}: the avatar's own file carries {} animation{}; it plays '{}'{} (--motion none keeps it at rest)",
                 avatar.source, avatar.animations.size(), avatar.animations.size() == 1 ? "" : "s",
                 avatar.animations[index],
                 avatar.animations.size() > 1 && animation.empty() ? ", the first (--animation chooses another)" : "");
    return {avatar.source, animation, nullptr};
  }
  if (std::shared_ptr<const formats::SkinnedJointMotion> m = humanoidMotion(avatar, setup.settings.frameRate_hz)) {
    std::error_code ec;
    const bool inTheScene = !scenePath.empty() && std::filesystem::equivalent(avatar.source, scenePath, ec);
    if (!animation.empty() && animation != avatar.name && animation != "0")
      throw Error(fmt::format("--animation {}: {} animates one Humanoid, '{}', the avatar", animation, avatar.source,
                              avatar.name));
    spdlog::info("{}: the {}'s interpolators move its Humanoid '{}', which plays them ({:.3g} s; --motion none keeps it "
                 "at rest)",
                 avatar.source, inTheScene ? "scene" : "avatar file", avatar.name, m->end_s - m->start_s);
    return {avatar.source, avatar.name, std::move(m)};
  }
  if (!animation.empty()) throw Error(nothingToChoose);
  return {};
}

void addSceneMotions(RunSetup& setup, const std::string& scenePath, const std::vector<std::string>& motions,
                     const std::string& animation, double metresPerUnit, const std::string& jointMap) {
  // Per character, the motion given for it by name, else the one given for all, else "".
  std::string forAll;
  std::vector<std::string> given(setup.characters.size());
  std::vector<std::uint8_t> named(setup.characters.size(), 0);
  bool forAllGiven = false;
  for (const std::string& m : motions) {
    if (const auto named_ = forCharacter(setup, m, "--motion")) {
      const auto [i, file] = *named_;
      if (named[i]) throw Error(fmt::format("--motion {}: '{}' is given a motion twice", m, setup.characters[i].name));
      named[i] = 1;
      given[i] = file;
      continue;
    }
    if (forAllGiven) throw Error(fmt::format("--motion {}: a motion for every character is given already ('{}'); name "
                                             "the character each plays on, NAME=FILE",
                                             m, forAll));
    forAllGiven = true;
    forAll = m;
  }
  if (setup.characters.empty()) {
    (void)sceneMotion(setup, nullptr, scenePath, forAll, animation);  // says what cannot be chosen
    return;
  }
  for (std::size_t i = 0; i < setup.characters.size(); ++i) {
    CharacterSetup& c = setup.characters[i];
    // Given for it, given for all, or the one its Avatar node names.
    const std::string motion = named[i] ? given[i] : forAllGiven ? forAll : c.motion;
    const MotionChoice m = sceneMotion(setup, &c, scenePath, motion, animation);
    if (!m.path.empty()) addMotion(setup, c, m.path, metresPerUnit, jointMap, m.animation, m.sampled.get());
  }
}

std::string ownMotionText(const scene::Avatar& avatar) {
  if (!avatar.animations.empty())
    return fmt::format("its own file's animation '{}'{}", avatar.animations.front(),
                       avatar.animations.size() > 1
                           ? fmt::format(", the first of {} (--animation NAME|INDEX chooses)", avatar.animations.size())
                           : "");
  if (humanoidMotion(avatar, 30.0)) return "the interpolators its file routes into it";
  return "";
}

void printHowToRun(const std::string& scene, const scene::Avatar& avatar, const std::string& nodeMotion) {
  const std::string own = nodeMotion.empty() ? ownMotionText(avatar) : nodeMotion;
  if (own.empty())
    fmt::print("run it: drape run {} --motion FILE (a BVH or AMC capture, or an animated avatar file; without it "
               "the avatar stands at rest)\n",
               scene);
  else
    fmt::print("run it: drape run {} (the avatar plays {}; --motion FILE plays another)\n", scene, own);
}

namespace {

/// stats.json's keep_apart: what the correction of the motion changed.
nlohmann::json keepApartJson(const sim::KeepApartReport& report) {
  nlohmann::json pairs = nlohmann::json::array();
  for (const sim::KeptApart& k : report.pairs)
    pairs.push_back({{"part", k.part},
                     {"from", k.from},
                     {"pivot", k.pivot},
                     {"clearance_m", k.target_m},
                     {"short_m", k.deepest_m},
                     {"short_frame", k.deepestFrame},
                     {"frames", k.frames},
                     {"short_after_m", k.remaining_m}});
  return {{"parts", report.parts},
          {"frames_changed", report.framesChanged},
          {"largest_turn_deg", report.largestAngle_deg},
          {"pairs", pairs}};
}

}  // namespace

void logKeptApart(const sim::KeepApartReport& report) {
  if (report.parts.empty()) return;
  spdlog::info("--keep-apart {}: the motion corrected in {} frames, turned by up to {:.1f} degrees, in {:.2f} s; {}",
               fmt::join(report.parts, ","), report.framesChanged, report.largestAngle_deg, report.seconds,
               report.pairs.empty() ? "no part lacked its clearance" : fmt::format("{} pairs", report.pairs.size()));
  for (const sim::KeptApart& k : report.pairs) spdlog::info("  {}", sim::describe(k));
  const auto short_ = std::count_if(report.pairs.begin(), report.pairs.end(),
                                    [](const sim::KeptApart& k) { return k.framesRemaining > 0; });
  if (short_ > 0)
    spdlog::warn("--keep-apart: {} of these pairs still lack clearance in some frames: no joint is turned more than "
                 "{:g} degrees from the captured motion, and a part in line with its joint cannot be turned away",
                 short_, report.maxTurn_deg);
}

void buildPartFieldsOnce(const RunSetup& setup, CharacterSetup& character, const std::string& why) {
  if (character.fields) return;
  const sim::WorldSettings ws = worldSettings(setup, character);
  spdlog::info("building distance fields ({:.4g} m voxels) {}", ws.voxel_m, why);
  const auto began = std::chrono::steady_clock::now();
  character.fields = std::make_shared<const std::vector<sim::PartField>>(
      sim::buildPartFields(*character.avatar, garmentsOf(setup, character), ws));
  spdlog::info("{} distance fields in {:.2f} s", character.fields->size(),
               std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count());
}

std::shared_ptr<sim::LiveKeepApart> liveKeepApart(const RunSetup& setup, CharacterSetup& character, double rate) {
  if (character.keepApart.empty()) return nullptr;
  buildPartFieldsOnce(setup, character, fmt::format("to keep {} apart", fmt::join(character.keepApart, ", ")));
  sim::WorldSettings ws = worldSettings(setup, character);
  ws.keepApart.parts = character.keepApart;
  auto keep = std::make_shared<sim::LiveKeepApart>(*character.avatar, *character.fields,
                                                   sim::keepApartSettings(garmentsOf(setup, character), ws), rate);
  spdlog::info("keeping {} apart on the live motion: each frame corrected {} frames ({:.2f} s) after it comes, the "
               "smoothing's reach ahead",
               fmt::join(character.keepApart, ", "), keep->delay(), static_cast<double>(keep->delay()) / rate);
  return keep;
}

sim::WorldSettings worldSettings(const RunSetup& setup, const CharacterSetup& character) {
  sim::WorldSettings ws;
  ws.step = setup.settings;
  ws.voxel_m = character.voxel_m;
  ws.fieldMethod = character.fieldMethod;
  ws.leadIn_s = character.leadIn_s;
  if (character.animation) ws.keepApart.parts = character.keepApart;
  return ws;
}

std::unique_ptr<sim::CharacterWorld> buildWorld(const RunSetup& setup, const CharacterSetup& character,
                                                std::vector<sim::Guest> guests) {
  const sim::WorldSettings ws = worldSettings(setup, character);
  const bool built = character.fields != nullptr;
  const std::string whose = setup.characters.size() > 1 ? fmt::format("{}: ", character.name) : "";
  spdlog::info("{}{} and binding constraint masks", whose,
               built ? "distance fields built before" : fmt::format("building distance fields ({:.4g} m voxels)", ws.voxel_m));
  auto world = std::make_unique<sim::CharacterWorld>(*character.avatar, character.animation.get(),
                                                     garmentsOf(setup, character), ws, character.fields, std::move(guests));
  if (!built) spdlog::info("{}{} distance fields in {:.2f} s", whose, world->fields().size(), world->fieldBuild_s());
  logKeptApart(world->keepApartReport());
  return world;
}

sim::SettleReport settleWorld(const CharacterSetup& character, sim::CharacterWorld& world) {
  sim::SettleReport report;
  if (!world.settle(character.settle_s, report))
    throw Error(world.instability(), ExitCode::Unstable);
  if (report.frames == 0) return report;
  std::string outcome = fmt::format("{} of the {} eased pairs reached T2", report.pairsEased - report.pairsTimedOut -
                                                                              report.pairsLeft, report.pairsEased);
  if (report.pairsTimedOut > 0)
    outcome += fmt::format(", {} held below it by the garment collide as any other", report.pairsTimedOut);
  if (report.pairsLeft > 0)
    outcome += fmt::format(", {} are still being eased out (a longer --settle lets them out before frame 0)",
                           report.pairsLeft);
  spdlog::info("settled the garments at the rest pose for {:.3g} s before frame 0 ({} frames in {:.2f} s): {}",
               report.seconds, report.frames, report.wall_s, outcome);
  return report;
}

std::string unknownKeepApartPart(const CharacterSetup& character) {
  const scene::Avatar& avatar = *character.avatar;
  for (const std::string& part : character.keepApart)
    if (avatar.findSegment(part) < 0)
      return fmt::format("avatar '{}' has no part '{}' (it has: {})", avatar.name, part,
                         fmt::join(avatar.segmentNames(), ", "));
  return "";
}

std::vector<std::string> keepApartParts(const std::vector<std::string>& option) {
  if (option.size() == 1 && option.front() == "none") return {};
  for (const std::string& part : option)
    if (part == "none") throw Error("--keep-apart: 'none' stands alone (no parts), not in a list");
  return option;
}

void setKeepApart(CharacterSetup& character, const std::vector<std::string>& option) {
  character.keepApart = keepApartParts(option);
  if (const std::string bad = unknownKeepApartPart(character); !bad.empty()) throw Error("--keep-apart: " + bad);
}

std::vector<sim::BodyOverlap> bodyOverlaps(const RunSetup& setup, const CharacterSetup& character,
                                           const sim::CharacterWorld& world) {
  if (!character.animation) return {};
  // Deeper than a voxel beyond rest: the fields read distances to about half a voxel.
  return sim::findBodyOverlaps(*character.avatar, world.poses(), world.fields(), setup.frames,
                               setup.settings.frameRate_hz, character.voxel_m);
}

namespace {

std::vector<sim::BodyOverlap> findOverlaps(const RunSetup& setup, const CharacterSetup& character,
                                           const sim::CharacterWorld& world) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<sim::BodyOverlap> found = bodyOverlaps(setup, character, world);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!found.empty())
    spdlog::info("{} motion puts collidable parts of the body inside each other beyond their overlap at rest, {} "
                 "pairs (stats.json: body_overlaps; found in {:.2f} s); deepest: {}{}",
                 setup.characters.size() > 1 ? fmt::format("{}'s", character.name) : std::string("the"), found.size(),
                 seconds, sim::describe(found.front()),
                 character.keepApart.empty()
                     ? " (--keep-apart PARTS turns named parts out of the others before simulating)"
                     : "");
  return found;
}

/// For an instability report: which of the pinch's parts the motion puts inside each other
/// in that frame.
std::string overlapsInFrame(const std::vector<sim::BodyOverlap>& overlaps, const std::vector<std::string>& parts,
                            long frame) {
  const auto named = [&](const std::string& p) { return std::find(parts.begin(), parts.end(), p) != parts.end(); };
  const auto f = static_cast<std::size_t>(frame);
  std::string out;
  for (const sim::BodyOverlap& o : overlaps) {
    if (!named(o.part) || !named(o.into) || f >= o.depthPerFrame.size() || o.depthPerFrame[f] <= 0) continue;
    out += fmt::format("{}{} is {:.0f} mm into {}", out.empty() ? "" : ", ", o.part, 1e3 * o.depthPerFrame[f], o.into);
  }
  return out.empty() ? "" : fmt::format("; in that frame the motion puts the body inside itself: {}", out);
}

/// Why garment run r stopped in `frame`: the vertex that ran away, the pinch nearest it, and
/// which of the pinch's parts the motion puts inside each other then.
std::string describeInstability(const GarmentRun& r, double maxSpeed_m_s,
                                const std::vector<sim::BodyOverlap>& overlaps, long frame) {
  const cloth::Instability& bad = r.solver->instability();
  std::string out = bad.describe(r.name, maxSpeed_m_s);
  if (!r.collider) return out;
  const cloth::NearestPinch near = cloth::nearestPinch(*r.model, *r.collider, bad.vertex, bad.substepsPerFrame);
  return out + cloth::describePinch(near, bad.vertex) + overlapsInFrame(overlaps, near.pinch.parts, frame);
}

}  // namespace

long defaultFrames(const RunSetup& setup) {
  double seconds = -1.0;
  for (const CharacterSetup& c : setup.characters)
    if (c.animation) seconds = std::max(seconds, c.leadIn_s + c.animation->duration());
  if (seconds < 0.0) throw Error("--frames is required (it defaults to the motion's length only with --motion)");
  return static_cast<long>(std::ceil(seconds * setup.settings.frameRate_hz));
}

void warnOfFramesWithinTheLeadIn(const RunSetup& setup, const FramesAsked& asked) {
  double leadIn_s = 0.0;
  for (const CharacterSetup& c : setup.characters)
    if (c.animation) leadIn_s = std::max(leadIn_s, c.leadIn_s);
  const double leadInFrames = leadIn_s * setup.settings.frameRate_hz;
  constexpr double kRounding = 1e-9;  // 0.2 s at 30 Hz is 6 frames, not a hair past
  const auto last = static_cast<double>(asked.lastFrame);
  if (!(leadInFrames > 0.0) || last > leadInFrames + kRounding) return;
  const long motionStarts = static_cast<long>(std::ceil(leadInFrames - kRounding));
  spdlog::warn("--frames {} ends {} the motion's first frame: the first {} frames are the {:g} s lead-in, blending "
               "from the rest pose into the motion; --frames {} {} {} frames of the motion itself{}",
               asked.frames, last < leadInFrames - kRounding ? "before" : "at", motionStarts, leadIn_s,
               motionStarts + asked.frames, asked.verb, asked.frames, asked.takesLeadIn ? " (or give --lead-in 0)" : "");
}

void validateRunSetup(const RunSetup& setup) {
  if (setup.garments.empty()) throw Error("drape run: no garment to simulate");
  std::vector<int> wornBy(setup.garments.size(), 0);
  for (const CharacterSetup& c : setup.characters) {
    if (!c.avatar) throw Error("drape run: a character has no avatar", ExitCode::Internal);
    for (const std::size_t g : c.garments) {
      if (g >= setup.garments.size()) throw Error("drape run: a character wears no such garment", ExitCode::Internal);
      ++wornBy[g];
    }
  }
  if (!setup.characters.empty() && std::any_of(wornBy.begin(), wornBy.end(), [](int n) { return n != 1; }))
    throw Error("drape run: every garment is to be worn by one character", ExitCode::Internal);
  setup.settings.validate("--");
  if (setup.frames < 1 && !setup.motionStreamed) throw Error(fmt::format("--frames must be >= 1, got {}", setup.frames));
  if (setup.objEvery < 1) throw Error(fmt::format("--every must be >= 1, got {}", setup.objEvery));
  for (const SphereSetup& s : setup.spheres)
    if (!(s.radius_m > 0.0) || !s.centre_m.allFinite())
      throw Error(fmt::format("--sphere needs a finite centre and a radius > 0, got radius {}", s.radius_m));
  for (const GarmentSetup& g : setup.garments) {
    g.material.validate("--");
    for (std::uint32_t v : g.pinned)
      if (v >= g.mesh.vertexCount())
        throw Error(fmt::format("--pin-vertices: vertex {} is out of range ({} has {} vertices, 0..{})", v, g.name,
                                g.mesh.vertexCount(), g.mesh.vertexCount() - 1));
  }
}

int stableSubsteps(const RunSetup& setup) {
  int n = 1;
  for (const GarmentSetup& g : setup.garments) {
    const cloth::SubstepChoice c =
        cloth::fewestStableSubsteps(g.mesh, mesh::Topology::build(g.mesh, kMinTriangleArea_m2), g.material,
                                    setup.settings.frameRate_hz, setup.settings.maxAddedMass, n,
                                    setup.settings.massScalingBound());
    n = std::max(n, c.substepsPerFrame);
  }
  return n;
}

std::vector<std::string> facePartsOption(const std::vector<std::string>& given) {
  return given == std::vector<std::string>{"none"} ? std::vector<std::string>{} : given;
}

void garmentVertexStates(const cloth::ClothSolver& solver, const cloth::FieldCollider* collider,
                         std::vector<std::uint8_t>& out) {
  const std::size_t n = solver.state().size();
  if (collider) collider->vertexDisplayStates(out);
  if (!collider || out.size() != n) out.assign(n, render::vertex_state::kOutside);  // before the first test too
  for (const cloth::PinGroup& group : solver.pins()) {
    const std::uint8_t flag = group.motion ? render::vertex_state::kBound : render::vertex_state::kPinned;
    for (const std::uint32_t v : group.vertices)
      if (v < n) out[v] |= flag;
  }
}

SetupWorlds::SetupWorlds(const RunSetup& setup) : place_(setup.garments.size()) {
  const std::size_t n = setup.characters.size();
  keepApartReports_.resize(n);
  for (std::size_t c = 0; c < n; ++c) {
    names_.push_back(setup.characters[c].name);
    for (std::size_t k = 0; k < setup.characters[c].garments.size(); ++k) place_[setup.characters[c].garments[k]] = {c, k};
  }
  // The setup's guests, after the characters (in the scene's order, as a run of them all
  // would give them to each world).
  std::vector<sim::Guest> visitors;
  for (const CharacterSetup& g : setup.guests)
    visitors.push_back({g.name, g.avatar.get(), g.animation.get(), g.fields});
  if (n == 1) {  // one world, which keeps its parts apart itself
    worlds_.push_back(buildWorld(setup, setup.characters.front(), visitors));
    return;
  }
  // Every body first, as its own world will move it: its fields, and its motion kept apart.
  std::vector<CharacterSetup> played = setup.characters;
  for (std::size_t c = 0; c < n; ++c) {
    CharacterSetup& character = played[c];
    buildPartFieldsOnce(setup, character, fmt::format("for {}", character.name));
    fields_.push_back(character.fields);
    keptApart_.emplace_back();
    if (character.keepApart.empty() || !character.animation) continue;
    sim::WorldSettings ws = worldSettings(setup, character);
    keptApart_[c] = std::make_unique<motion::AvatarAnimation>(*character.animation);
    keepApartReports_[c] = sim::keepBodyApart(*character.avatar, *keptApart_[c], *character.fields,
                                              sim::keepApartSettings(garmentsOf(setup, character), ws));
    logKeptApart(keepApartReports_[c]);
    character.animation = std::shared_ptr<const motion::AvatarAnimation>(std::shared_ptr<void>(), keptApart_[c].get());
    character.keepApart.clear();
  }
  for (std::size_t c = 0; c < n; ++c) {
    std::vector<sim::Guest> guests;
    for (std::size_t o = 0; o < n; ++o)
      if (o != c) guests.push_back({played[o].name, played[o].avatar.get(), played[o].animation.get(), fields_[o]});
    guests.insert(guests.end(), visitors.begin(), visitors.end());
    worlds_.push_back(buildWorld(setup, played[c], std::move(guests)));
  }
}

const sim::KeepApartReport& SetupWorlds::keepApartReport(std::size_t c) const {
  return worlds_.size() == 1 ? worlds_.front()->keepApartReport() : keepApartReports_[c];
}

std::vector<const sim::CharacterWorld*> SetupWorlds::all() const {
  std::vector<const sim::CharacterWorld*> out;
  for (const auto& w : worlds_) out.push_back(w.get());
  return out;
}

void SetupWorlds::sizeJoints(std::vector<std::vector<RigidTransform>>& out) const {
  out.resize(worlds_.size());
  for (std::size_t c = 0; c < worlds_.size(); ++c) out[c].resize(worlds_[c]->avatar().joints.size());
}

void SetupWorlds::evaluateJoints(long frame, std::vector<std::vector<RigidTransform>>& out) const {
  for (std::size_t c = 0; c < worlds_.size(); ++c) worlds_[c]->poses().evaluate(worlds_[c]->frameTime(frame), out[c]);
}

namespace {

/// drape run's sink: the run directory's files.
class WriterSink final : public FrameSink {
 public:
  explicit WriterSink(const RunSetup& setup) : setup_(setup) {}
  void begin(const std::vector<const sim::CharacterWorld*>& worlds) override {
    std::vector<CharacterAtStart> characters;
    for (const sim::CharacterWorld* world : worlds) {
      CharacterAtStart& c = characters.emplace_back();
      c.fields = &world->fields();
      c.skinAllowance_m = leastT0(*world);
      c.joints.resize(world->avatar().joints.size());
      world->poses().evaluate(0.0, c.joints);
    }
    writer_ = std::make_unique<RunWriter>(setup_, characters);
  }
  void write(const FrameTaken& frame) override { writer_->write(frame); }
  void end(long frames) override { writer_->close(frames); }
  void stats(const nlohmann::json& stats) override { writer_->writeStats(stats); }

 private:
  const RunSetup& setup_;
  std::unique_ptr<RunWriter> writer_;
};

}  // namespace

int simulateRun(const RunSetup& setup, const FrameGate& gate) {
  validateRunSetup(setup);
  createOutDir(setup.outDir);
  WriterSink sink(setup);
  return simulateInto(setup, sink, gate);
}

namespace {

/// The wind over frame `frame`: what the event graph set at the motion frame at its end
/// (the scene's during the lead-in and where the graph set none).
Vec3 windOf(const RunSetup& setup, long frame) {
  const double rate = setup.settings.frameRate_hz;
  const double t =
      static_cast<double>(frame) / rate - (setup.characters.empty() ? 0.0 : setup.characters.front().leadIn_s);
  if (t < 0.0) return setup.settings.wind_m_s;
  const MotionWind& wind = *setup.motionWind;
  const auto f = std::min(wind.size() - 1, static_cast<std::size_t>(std::floor(t * rate + 1e-6)));
  return wind[f].value_or(setup.settings.wind_m_s);
}

/// stats.json's entry for a character: its name and garments, and what the correction of its
/// motion changed.
nlohmann::json characterJson(const RunSetup& setup, const CharacterSetup& character,
                             const sim::KeepApartReport& keptApart) {
  nlohmann::json garments = nlohmann::json::array();
  for (const std::size_t g : character.garments) garments.push_back(setup.garments[g].name);
  nlohmann::json entry = {{"name", character.name}, {"avatar", character.avatar->name}, {"garments", garments}};
  if (!keptApart.parts.empty()) entry["keep_apart"] = keepApartJson(keptApart);
  else if (character.liveKeptApart) entry["keep_apart"] = keepApartJson(character.liveKeptApart->report());
  return entry;
}

}  // namespace

int simulateInto(const RunSetup& setup, FrameSink& sink, const FrameGate& gate) {
  validateRunSetup(setup);
  const cloth::StepSettings& settings = setup.settings;

  // Build every garment (topology checks happen here: non-manifold, degenerate). On the
  // characters, their worlds build the part fields, bind the masks and own the solvers.
  for (const GarmentSetup& g : setup.garments) (void)mesh::Topology::build(g.mesh, kMinTriangleArea_m2);
  SetupWorlds worlds(setup);
  // A streamed motion is not all there yet: where it puts the body inside itself is found
  // at the end, for the stats.
  std::vector<std::vector<sim::BodyOverlap>> overlaps(worlds.size());
  if (!setup.motionStreamed)
    for (std::size_t c = 0; c < worlds.size(); ++c) overlaps[c] = findOverlaps(setup, setup.characters[c], worlds.world(c));
  // Per garment, the overlaps of the body that wears it (an instability report names them).
  const auto overlapsOf = [&](std::size_t g) -> const std::vector<sim::BodyOverlap>& {
    static const std::vector<sim::BodyOverlap> none;
    return worlds.size() > 0 ? overlaps[worlds.characterOf(g)] : none;
  };
  std::vector<GarmentRun> runs(setup.garments.size());
  // Without a character every solver first, then the layer colliders, which read the
  // solvers of the garments below.
  std::vector<std::vector<std::size_t>> below;
  std::vector<int> stepLayers(setup.garments.size(), 0);  // per garment (sim::layersOf)
  if (worlds.size() == 0) {
    below = sim::garmentsBelow(setup.garments);
    stepLayers = sim::layersOf(below);
    for (std::size_t gi = 0; gi < setup.garments.size(); ++gi) {
      const GarmentSetup& g = setup.garments[gi];
      const mesh::Topology topology = mesh::Topology::build(g.mesh, kMinTriangleArea_m2);
      auto model = cloth::ClothModel::build(g.mesh, topology, g.material, settings.massScaling());
      runs[gi].ownedSolver = std::make_unique<cloth::ClothSolver>(model, settings, pinsOf(g, *model));
      runs[gi].ownedSolver->setStitches(g.stitches, g.name);
    }
  }
  for (std::size_t gi = 0; gi < setup.garments.size(); ++gi) {
    const GarmentSetup& g = setup.garments[gi];
    GarmentRun& r = runs[gi];
    r.name = g.name;
    if (worlds.size() > 0) {
      r.solver = &worlds.solver(gi);
      cloth::FieldCollider* collider = worlds.collider(gi);
      r.collider = collider;
      collider->setCountEverySubstep(setup.countEverySubstep);
      collider->setContactPlanes(!setup.exactSliding);
      collider->setPinchHold(!setup.freePinches);
      if (!g.offsetsGiven) {
        const cloth::OffsetSurfaces& t = collider->offsets();
        spdlog::info("{}: offset surfaces T0..T3 {:.3g}, {:.3g}, {:.3g} and {:.3g} mm: 1, 2, 3 and 6 voxels, as no "
                     "offsets are written (the Simulation node's or the garment's offsets, or --offsets)",
                     g.name, 1e3 * t.t0_m, 1e3 * t.t1_m, 1e3 * t.t2_m, 1e3 * t.t3_m);
      }
      logEasedPairs(g.name, *collider);
      const sim::CharacterWorld& world = worlds.world(worlds.characterOf(gi));
      r.layers = world.layerCollider(worlds.indexInWorld(gi));
      stepLayers[gi] = world.layer(worlds.indexInWorld(gi));
    } else {
      r.solver = r.ownedSolver.get();
      // Before the spheres: where they disagree, a sphere wins.
      r.ownedLayers = sim::makeLayerCollider(
          setup.garments, gi, below[gi], g.pinned,
          [&](std::size_t i) -> cloth::ClothSolver& { return *runs[i].ownedSolver; }, 1.0 / settings.frameRate_hz);
      if (r.ownedLayers) r.ownedSolver->addCollider(*r.ownedLayers);
      r.layers = r.ownedLayers.get();
    }
    if (r.layers && r.layers->thickness_m() > 0)
      spdlog::info("{}: its layers kept {:.4g} mm apart (self collision, tested every {} substeps)", g.name,
                   1e3 * r.layers->thickness_m(), r.layers->every());
    if (r.layers && !r.layers->garmentsBelow().empty())
      spdlog::info("{}: kept {:.4g} mm over {} (stepped after {}, tested every {} substeps)", g.name,
                   1e3 * r.layers->gap_m(), fmt::join(r.layers->garmentsBelow(), ", "),
                   r.layers->garmentsBelow().size() == 1 ? "it" : "them", r.layers->every());
    if (r.layers && r.layers->startUnder().vertices > 0) logStartUnder(g.name, *r.layers);
    r.model = &r.solver->model();
    // Each garment its own spheres: garments step in parallel, and a collider keeps counts.
    r.spheres.reserve(setup.spheres.size());  // the solver keeps references
    for (const SphereSetup& s : setup.spheres) r.solver->addCollider(r.spheres.emplace_back(s.centre_m, s.radius_m));
    const double stable = r.model->estimatedStableStep_s();
    if (r.model->addedMass_kg() > 0.0)
      spdlog::info("{}: mass scaling added {:.2f} % of its mass ({:.1f} g) on {} of {} vertices to keep the "
                   "{:.3g} ms substep stable",
                   g.name, 100.0 * r.model->addedMassFraction(),
                   1e3 * r.model->addedMass_kg(), r.model->massScaledVertexCount(), r.model->vertexCount(),
                   1e3 * settings.substep_s());
    if (settings.bendEvery > 1)
      spdlog::info("{}: bending forces every {} substeps ({:.3g} ms, {:.0f} % of their stable step)", g.name,
                   settings.bendEvery, 1e3 * settings.bendEvery * settings.substep_s(),
                   100.0 * settings.bendEvery * settings.substep_s() / r.model->bendingStableStep_s());
    logDamping(g.name, *r.solver);
    if (settings.integrator == cloth::IntegratorKind::BackwardEuler) {
      spdlog::info("{}: backward Euler, {} substeps per frame ({:.3g} ms, {:.3g} times the explicit steps' estimated "
                   "stable step), each a linear solve by conjugate gradients",
                   g.name, settings.substepsPerFrame, 1e3 * settings.substep_s(), settings.substep_s() / stable);
      // A scene's explicit count is many times what the implicit step needs, at many times its cost.
      if (settings.substepsPerFrame > 8 && settings.substep_s() < 2.0 * stable)
        spdlog::warn("{}: backward Euler is stable at substeps many times the explicit steps' {:.3g} ms; fewer "
                     "run faster (e.g. --substeps {}, an eighth)",
                     g.name, 1e3 * stable, cloth::implicitSubstepsFor(settings.substepsPerFrame));
    } else if (settings.integrator == cloth::IntegratorKind::RungeKutta4) {
      // Judged by the membrane's stiffest mode (the solver refused a longer substep), not by
      // the wave-speed estimate, which is symplectic Euler's.
      const double most =
          cloth::rungeKuttaStableStep_s(r.solver->dampedMembraneFrequency_rad_s(), r.model->material().damping_s);
      spdlog::info("{}: Runge-Kutta (fourth order), {} substeps per frame ({:.3g} ms, {:.0f} % of the {:.3g} ms the "
                   "membrane's stiffest mode allows), four force evaluations each",
                   g.name, settings.substepsPerFrame, 1e3 * settings.substep_s(),
                   100.0 * settings.substep_s() / most, 1e3 * most);
    } else if (settings.substep_s() > stable)
      spdlog::warn("{}: the substep {:.3g} s is longer than the estimated stable step {:.3g} s; "
                   "the run may diverge (try --substeps {} or more)",
                   g.name, settings.substep_s(), stable,
                   static_cast<long>(std::ceil(1.0 / (settings.frameRate_hz * stable))));
  }
  sink.begin(worlds.all());

  // Per-frame records for stats.json: each frame's own stage times (frame 0, the initial
  // state, simulates nothing: the settling's times are not the run's), and the output's,
  // which the writing thread fills by frame.
  std::vector<double> frameMs, energy;
  std::vector<StageMs> frameStageMs;
  std::vector<double> frameOutputMs;
  StageLaps stageLaps;
  const auto stageTotals = [&] {
    StageMs sum{};
    for (const GarmentRun& r : runs) sum += stageTotalsMs(r.solver->stageTimes());
    return sum;
  };
  cloth::EdgeStrain maxStrain;
  double outputSeconds = 0.0;
  std::string unstable;
  bool unstableNan = false;

  // The frame loop: a thread of its own steps every garment a frame and takes what the
  // outputs need from the solvers and the poses (which only it touches); this one hands
  // each frame to the sink (drape run's files: caches, poses, the skinned body tucked). On
  // two cores they overlap: the skin's fit and tuck cost more per frame than the walking
  // skirt's simulation.
  const auto prepare = [&](FrameTaken& slot) {
    slot.positions.resize(runs.size());
    slot.states.resize(runs.size());
    worlds.sizeJoints(slot.joints);
  };
  const auto take = [&](long frame, FrameTaken& taken) {
    taken.frame = frame;
    double e = 0.0;
    for (std::size_t g = 0; g < runs.size(); ++g) {
      const cloth::ClothSolver& solver = *runs[g].solver;
      solver.state().copyPositions(taken.positions[g]);
      garmentVertexStates(solver, runs[g].collider, taken.states[g]);
      e += solver.totalEnergy();
      const cloth::EdgeStrain strain = cloth::edgeStrain(*runs[g].model, solver.state());
      maxStrain.stretch = std::max(maxStrain.stretch, strain.stretch);
      maxStrain.compression = std::max(maxStrain.compression, strain.compression);
    }
    energy.push_back(e);
    worlds.evaluateJoints(frame, taken.joints);
  };
  const auto write = [&](const FrameTaken& taken) {
    const Clock::time_point start = Clock::now();
    sink.write(taken);
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    outputSeconds += seconds;
    const auto f = static_cast<std::size_t>(taken.frame);
    if (frameOutputMs.size() <= f) frameOutputMs.resize(f + 1, 0.0);
    frameOutputMs[f] = 1e3 * seconds;
  };

  sim::SettleReport settled;
  for (std::size_t c = 0; c < worlds.size(); ++c) settled += settleWorld(setup.characters[c], worlds.world(c));
  Progress progress("drape run", std::max(0L, setup.frames));
  long done = 0;
  std::exception_ptr stopped;
  const Clock::time_point loopStart = Clock::now();
  {
    FramesAhead ahead(kFramesAhead, 0, gate ? -1 : setup.frames, prepare, [&](long frame, FrameTaken& taken) {
      if (gate && !gate(frame)) return false;
      if (frame > 0) {
        if (setup.motionWind && !setup.motionWind->empty()) {
          const Vec3 wind = windOf(setup, frame);
          for (GarmentRun& r : runs) r.solver->setWind(wind);
        }
        const Clock::time_point start = Clock::now();
        const std::vector<std::uint8_t> stable =
            sim::stepInParallel(runs.size(), frame, [&](std::size_t g) -> cloth::ClothSolver& { return *runs[g].solver; },
                                stepLayers);
        for (std::size_t g = 0; g < runs.size() && unstable.empty(); ++g) {
          sim::logFrameRecovery(*runs[g].solver, setup.garments[g].name, frame);
          if (!stable[g]) {
            unstable = describeInstability(runs[g], settings.maxSpeed_m_s, overlapsOf(g), frame);
            unstableNan = runs[g].solver->instability().nan;
          }
        }
        frameMs.push_back(1e3 * std::chrono::duration<double>(Clock::now() - start).count());
        if (!unstable.empty()) return false;
      }
      frameStageMs.push_back(stageLaps.lap(stageTotals()));
      take(frame, taken);
      done = frame;
      progress.update(frame);
      return true;
    });
    // What the simulating side throws (a gate that gave up waiting) ends the run as an
    // instability does: the frames before it are the sink's, then the outputs are finished.
    for (;;) {
      const FrameTaken* taken = nullptr;
      try {
        taken = ahead.next();
      } catch (...) {
        stopped = std::current_exception();
      }
      if (taken == nullptr) break;
      write(*taken);
    }
  }
  const double loopSeconds = std::chrono::duration<double>(Clock::now() - loopStart).count();
  progress.finish();
  if (setup.motionStreamed) {
    RunSetup played = setup;
    played.frames = done;
    for (std::size_t c = 0; c < worlds.size(); ++c) overlaps[c] = findOverlaps(played, setup.characters[c], worlds.world(c));
  }

  // Close the outputs and write the stats (also after an instability).
  sink.end(done);
  cloth::StageTimes total;
  for (const GarmentRun& r : runs) total += r.solver->stageTimes();
  const auto simulatedFrames = static_cast<double>(std::max<std::size_t>(1, frameMs.size()));
  nlohmann::json stats;
  stats["frames"] = done;
  stats["frames_requested"] = gate ? done : setup.frames;
  stats["settle"] = {{"frames", settled.frames},
                     {"seconds", settled.seconds},
                     {"wall_s", settled.wall_s},
                     {"pairs_eased", settled.pairsEased},
                     {"pairs_timed_out", settled.pairsTimedOut},
                     {"pairs_left", settled.pairsLeft}};
  stats["frame_rate"] = settings.frameRate_hz;
  stats["substeps_per_frame"] = settings.substepsPerFrame;
  stats["max_refinement"] = settings.maxRefinement;
  stats["integrator"] = cloth::integratorName(settings.integrator);
  stats["ms_per_frame"] = median(frameMs);
  // What a user waits for: simulation and output overlapped, per simulated frame.
  stats["loop_wall_ms_per_frame"] = 1e3 * loopSeconds / static_cast<double>(std::max<long>(1, done));
  // Per simulated frame on average, and each frame's own (frame_ms_per_stage), by the same names.
  const StageMs runMs = stageTotals();
  nlohmann::json means, byFrame;
  for (std::size_t i = 0; i < kStageNames.size(); ++i) {
    means[kStageNames[i]] = runMs[i] / simulatedFrames;
    nlohmann::json& column = byFrame[kStageNames[i]] = nlohmann::json::array();
    for (const StageMs& frame : frameStageMs) column.push_back(frame[i]);
  }
  means["output"] = outputSeconds * 1e3 / static_cast<double>(energy.size());
  stats["ms_per_stage"] = std::move(means);
  frameOutputMs.resize(frameStageMs.size(), 0.0);
  byFrame["output"] = frameOutputMs;
  stats["frame_ms_per_stage"] = std::move(byFrame);
  stats["energy"] = energy;
  stats["max_strain"] = maxStrain.largest();
  stats["max_stretch"] = maxStrain.stretch;
  stats["max_compression"] = maxStrain.compression;
  stats["nan_detected"] = unstableNan;
  stats["unstable"] = !unstable.empty();
  stats["instability"] = unstable.empty() ? nlohmann::json(nullptr) : nlohmann::json(unstable);
  nlohmann::json garments = nlohmann::json::array();
  for (std::size_t g = 0; g < runs.size(); ++g) {
    const cloth::ClothModel& m = *runs[g].model;
    nlohmann::json entry = {{"name", setup.garments[g].name},
                            {"vertices", m.vertexCount()},
                            {"triangles", m.triangleCount()},
                            {"pinned", setup.garments[g].pinned.size()},
                            {"mass_kg", m.totalMass_kg()},
                            {"added_mass_kg", m.addedMass_kg()},
                            {"mass_scaled_vertices", m.massScaledVertexCount()},
                            {"estimated_stable_substep_s", m.estimatedStableStep_s()},
                            {"frames_refined", runs[g].solver->refinedFrames()},
                            {"strain_limit", runs[g].solver->strainLimit()},
                            {"strain_limit_corrections", runs[g].solver->strainLimitCorrections()},
                            {"stitches", runs[g].solver->stitches().size()},
                            {"stitch_corrections", runs[g].solver->stitchCorrections()}};
    if (settings.integrator == cloth::IntegratorKind::BackwardEuler) {
      const cloth::SolveStats solves = runs[g].solver->solveStats();
      entry["implicit_solves"] = {{"substeps", solves.solves},
                                  {"iterations", solves.iterations},
                                  {"mean_iterations", solves.meanIterations()},
                                  {"unconverged", solves.unconverged},
                                  {"indefinite", solves.indefinite}};
    }
    const long limitedFrom = runs[g].solver->strainLimitedFrom();
    entry["strain_limited_from_frame"] = limitedFrom > 0 ? nlohmann::json(limitedFrom) : nlohmann::json(nullptr);
    if (runs[g].collider) {
      const cloth::OffsetSurfaces& o = runs[g].collider->offsets();
      entry["offsets_m"] = {o.t0_m, o.t1_m, o.t2_m, o.t3_m};
      nlohmann::json faces = nlohmann::json::array();
      for (const cloth::CollisionPart& p : runs[g].collider->parts())
        if (p.faceSamples) faces.push_back(p.name);
      entry["face_samples_with"] = faces;
    }
    if (const cloth::LayerCollider* layers = runs[g].layers) {
      const cloth::LayerCounters& s = layers->layerCounters();
      if (layers->thickness_m() > 0)
        entry["self_collision"] = {{"thickness_m", layers->thickness_m()},
                                   {"tests", s.tests},
                                   {"candidate_pairs", s.candidates},
                                   {"candidate_lists_made", s.rebuilds},
                                   {"candidate_lists_mended", s.mends},
                                   {"contacts", s.contacts},
                                   {"crossings", s.crossings}};
      if (!layers->garmentsBelow().empty())
        entry["worn_over"] = {{"garments", layers->garmentsBelow()},
                              {"gap_m", layers->gap_m()},
                              {"tests", s.tests},
                              {"candidate_pairs", s.candidates},
                              {"candidate_lists_made", s.rebuilds},
                              {"candidate_lists_mended", s.mends},
                              {"vertices_starting_under", layers->startUnder().vertices},
                              {"vertices_lifted_over", layers->liftedOver().vertices},
                              {"vertices_left_under", layers->liftedOver().leftUnder},
                              {"contacts", s.contactsBelow},
                              {"crossings", s.crossingsBelow}};
    }
    garments.push_back(std::move(entry));
  }
  stats["garments"] = garments;
  nlohmann::json bodyOverlaps = nlohmann::json::array();
  for (std::size_t c = 0; c < overlaps.size(); ++c)
    for (const sim::BodyOverlap& o : overlaps[c])
      bodyOverlaps.push_back({{"character", setup.characters[c].name},
                            {"part", o.part},
                            {"into", o.into},
                            {"depth_m", o.depth_m},
                            {"deepest_frame", o.deepestFrame},
                            {"first_frame", o.firstFrame},
                            {"last_frame", o.lastFrame},
                            {"frames", o.frames}});
  stats["body_overlaps"] = bodyOverlaps;
  nlohmann::json characters = nlohmann::json::array();
  for (std::size_t c = 0; c < worlds.size(); ++c)
    characters.push_back(characterJson(setup, setup.characters[c], worlds.keepApartReport(c)));
  // One character's correction where it always was; several characters' in theirs.
  if (characters.size() == 1 && characters[0].contains("keep_apart")) stats["keep_apart"] = characters[0]["keep_apart"];
  stats["characters"] = characters;
  addCollisionStats(stats, runs, total, done, worlds);
  sink.stats(stats);

  if (stopped) std::rethrow_exception(stopped);

  if (!unstable.empty())
    throw Error(fmt::format("{} (results up to frame {} kept{})", unstable, done,
                            setup.outDir.empty() ? std::string() : " in " + setup.outDir),
                ExitCode::Unstable);
  return 0;
}

}  // namespace drape::cli
