#pragma once
// What `drape run` simulates, however it was described: garments (meshes in metres,
// materials, pinned vertices), settings, frame count and outputs. Built from command-line
// options today (cmd_run.cpp) and from a VRML97 scene later; both feed simulateRun(), the
// one loop that steps every garment and writes DIR/frames/, DIR/*.pc2, DIR/*.obj,
// DIR/stats.json and DIR/manifest.json.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "drape/cloth/collider.hpp"
#include "drape/core/timecode.hpp"
#include "drape/events/runtime.hpp"
#include "drape/cloth/material.hpp"
#include "drape/mesh/trimesh.hpp"
#include "drape/motion/animation.hpp"
#include "drape/scene/avatar.hpp"
#include "drape/sim/body_overlap.hpp"
#include "drape/sim/character_world.hpp"
#include "frames_ahead.hpp"

namespace drape::cli {

/// A garment: name, rest mesh (m), material, pinned vertices, and, on a character, its
/// constraint mask (bound vertices), collision candidates and offsets.
using GarmentSetup = sim::GarmentSpec;

/// A character garments are worn by: a segmented avatar, the garments it wears and,
/// optionally, its motion.
struct CharacterSetup {
  std::shared_ptr<const scene::Avatar> avatar;
  std::shared_ptr<const motion::AvatarAnimation> animation;  ///< null: the avatar stands at rest
  double voxel_m = 0.005;                                     ///< distance-field voxel size
  field::FieldMethod fieldMethod = field::FieldMethod::Dvdp;
  double leadIn_s = 1.0;                                      ///< rest pose -> first motion frame
  /// Longest settling at the rest pose before frame 0 (sim::CharacterWorld::settle; 0: none).
  double settle_s = 1.0;
  /// Parts whose motion is corrected to keep them out of the collidable parts (--keep-apart).
  std::vector<std::string> keepApart{};
  /// The part fields, when built before for these garments (a cloth-server's, once for all
  /// its takes); null: the world builds them.
  std::shared_ptr<const std::vector<sim::PartField>> fields{};
  /// A live motion's keep-apart (the capture corrects it on its way in; liveKeepApart): its
  /// report goes where a recorded motion's does. Null otherwise.
  std::shared_ptr<const sim::LiveKeepApart> liveKeptApart{};
  /// What the scene calls the character (its Avatar or Humanoid node), besides the avatar's
  /// own name: an event graph's Plays name it so.
  std::vector<std::string> names{};
  /// What the run calls it (messages, --motion NAME=FILE, its files in a run directory of
  /// several characters): the scene's name for it, unique in the setup.
  std::string name{};
  /// The garments it wears: indices into RunSetup::garments, ascending.
  std::vector<std::size_t> garments{};
  /// The motion its Avatar node names (`motion`), played when a command gives it none; "": none.
  std::string motion{};
};

/// Per motion frame, the wind an event graph set (none: the scene's).
using MotionWind = std::vector<std::optional<Vec3>>;

struct SphereSetup {
  Vec3 centre_m = Vec3::Zero();
  double radius_m = 0.0;
};

struct RunSetup {
  std::vector<GarmentSetup> garments;
  cloth::StepSettings settings;
  std::vector<SphereSetup> spheres;    ///< analytic sphere colliders (every garment collides)
  /// The characters the garments are worn by, each colliding with its own avatar's parts
  /// (every garment worn by one of them); none: the garments hang on their pins.
  std::vector<CharacterSetup> characters;
  /// Other characters of the scene whose bodies every world's garments collide with too,
  /// whose garments this run does not simulate (a cloth-server's --guest): each with its
  /// part fields built and the motion it plays (a pose stream's, corrected where the scene
  /// keeps parts apart), in the scene's order.
  std::vector<CharacterSetup> guests;
  long frames = 0;                     ///< frames to simulate after the initial one
  long objEvery = 1;                   ///< write an OBJ frame every K frames
  std::string outDir;
  bool preview = false;                ///< also a contact sheet and (with ffmpeg) an MP4
  /// With reduced-frequency collision tests, count penetration on every substep (not only
  /// the tested ones): about a collision test's time on each untested substep.
  bool countEverySubstep = false;
  /// Sliding points read the distance field on every test instead of their contact planes.
  bool exactSliding = false;
  /// With reduced-frequency collision tests, pinched points move freely between tests
  /// instead of being held by the parts that pressed them (FieldCollider::setPinchHold).
  bool freePinches = false;
  /// The character's motion arrives while the run simulates (a cloth-server's pose
  /// stream): it is played as it is (a pose stream carries the motion already corrected
  /// where the scene keeps parts apart), and where it puts the body inside itself is found
  /// at the end.
  bool motionStreamed = false;
  /// The wind of each motion frame where an event graph sets it (docs/EVENTS.md); null or
  /// empty: the settings' wind throughout. A cloth-server's grows as its poses come.
  std::shared_ptr<const MotionWind> motionWind{};
  /// The time code of frame 0 (a frame number at the frame rate; a studio player's, its
  /// cloth take's). None: frameTimeCode's.
  std::optional<std::int64_t> timeCodeOfFrame0;
};

/// The time code of frame `frame` of the run, as the studio numbers a cloth take's: the
/// setup's timeCodeOfFrame0 and on; else, on characters, motion frame 0 at the first one's
/// motion's time code (0 where it has none) and the lead-in's frames before it; else the frame.
[[nodiscard]] TimeCode frameTimeCode(const RunSetup& setup, long frame);

/// The setup's one character, for `what` plays one (the studio's roles, a live capture): null
/// when it has none; throws drape::Error saying so when it has several.
[[nodiscard]] CharacterSetup* oneCharacter(RunSetup& setup, const std::string& what);
[[nodiscard]] const CharacterSetup* oneCharacter(const RunSetup& setup, const std::string& what);
/// The one character a studio role plays: the one `name` names, its garments and no other's
/// kept in `setup`, or (`name` empty) the scene's only one. Throws drape::Error naming
/// `option` when none is called so, or the scene has several and `name` is empty; null when
/// the scene has no character.
CharacterSetup* chooseCharacter(RunSetup& setup, const std::string& name, const std::string& option);
/// The setup's characters' names, "Ada, Bea", for messages.
[[nodiscard]] std::string characterNames(const RunSetup& setup);
/// A per-character option's value, NAME=VALUE (`--motion`, `--live`): the index of the
/// character the scene calls NAME, and VALUE; none when `value` names no one (it has no
/// '=' after its first character, or a file of its whole name exists). Throws drape::Error
/// naming `option` for a NAME the scene does not have, or an empty VALUE.
[[nodiscard]] std::optional<std::pair<std::size_t, std::string>> forCharacter(const RunSetup& setup,
                                                                            const std::string& value,
                                                                            const std::string& option);
/// The character named `name` ("NAME", as --motion NAME=FILE gives it); throws drape::Error
/// listing the setup's characters when none is called so.
[[nodiscard]] const CharacterSetup& characterNamed(const RunSetup& setup, const std::string& name,
                                                   const std::string& option);
/// Leaves out the garments `keep` refuses (by index into setup.garments), and the characters
/// left wearing none; the others' garment indices follow.
void keepGarmentsWhere(RunSetup& setup, const std::function<bool(std::size_t garment)>& keep);
/// The specs of the garments `character` wears, in its order (its world's garment order).
[[nodiscard]] std::vector<GarmentSetup> garmentsOf(const RunSetup& setup, const CharacterSetup& character);

/// Garments, materials, settings and the avatars (as the setup's characters, without motion)
/// from a VRML97 scene. Throws drape::Error on a bad scene or one with no ClothSet.
/// `cutAtJoints`, when given, replaces the Avatar node's cutAtJoints (drape run
/// --cut-at-joints; empty: parts by dominant weight alone).
[[nodiscard]] RunSetup runSetupFromScene(const std::string& scenePath,
                                         const std::optional<std::vector<std::string>>& cutAtJoints = std::nullopt);

/// Loads a motion file onto `character`'s avatar (rate = the setup's frame rate). `metresPerUnit`
/// > 0 overrides the units guess; `jointMap` "" picks one of the shipped maps; `animation`
/// chooses one of a glTF motion file's animations ("" the first); `sampled`, when given, is
/// that animation already sampled at the setup's frame rate (the file is not read again).
void addMotion(const RunSetup& setup, CharacterSetup& character, const std::string& motionPath, double metresPerUnit = 0.0,
               const std::string& jointMap = "", const std::string& animation = "",
               const formats::SkinnedJointMotion* sampled = nullptr);

/// How motion files load onto the setup's avatar: at its frame rate, with the shipped joint
/// maps (what --motion and an event graph's Plays share).
[[nodiscard]] motion::MotionOptions motionOptions(const RunSetup& setup);

/// Plays an EGML event graph (docs/EVENTS.md) on the setup's characters: each plays the
/// events that name it and those that name none (docs/EVENTS.md), and the wind it sets
/// blows on all. `sets` are NAME=VALUE parameters, `sends` NAME@SECONDS events; `motionFrames` > 0
/// renders that many motion frames at most (an endless graph needs it).
void addEvents(RunSetup& setup, const std::string& graphPath, const std::vector<std::string>& sets,
               const std::vector<std::string>& sends, long motionFrames);

/// The characters as an event graph's actors (each answering to the names the scene gives it).
[[nodiscard]] std::vector<events::Actor> eventActors(const std::vector<CharacterSetup>& characters);

/// --set NAME=VALUE options as parameters; throws naming --set.
[[nodiscard]] std::vector<std::pair<std::string, std::string>> parameterOptions(const std::vector<std::string>& sets);

/// --motion's help after "Motion for the avatar ", and --animation's, for run, play and render.
inline constexpr const char* kMotionHelp =
    "(.bvh, .amc; an avatar file's animation, .glb, .gltf, .vrm, .dae, .fbx; or an H-Anim humanoid's interpolators, .wrl), "
    "retargeted unless the avatar is that file's; none: at rest. Without it, the avatar plays its own file's "
    "animation if the file carries one (a glTF, Collada or FBX animation, or interpolators ROUTEd into a VRML97 "
    "Humanoid)";
inline constexpr const char* kAnimationHelp =
    "Which of an avatar file's animations plays (of --motion's file, or without --motion of the avatar's own; of a "
    ".wrl, its animated Humanoids), by name or by index from 0 (default: the first; drape inspect FILE lists them)";

/// The motion a scene command plays (`drape run`, `play`, `render`): `motion` as given, none
/// for "none" (the avatar stays at rest), and with none given the avatar's own, where the
/// file it was read from carries one: a glTF, Collada or FBX animation (`animation` chooses
/// which), or ROUTEd interpolators that drive its Humanoid in a VRML97 file (the scene
/// itself or the file an Avatar node names); played as a viewer of that file would play it,
/// and logged, with how to keep it at rest.
struct MotionChoice {
  std::string path;       ///< "": no motion
  std::string animation;  ///< for addMotion: which of the file's animations
  /// The motion as sampled to find it (a VRML97 Humanoid's interpolators), or null.
  std::shared_ptr<const formats::SkinnedJointMotion> sampled;
};
[[nodiscard]] MotionChoice sceneMotion(const RunSetup& setup, const CharacterSetup* character, const std::string& scenePath,
                                       const std::string& motion, const std::string& animation);

/// How a scene command's --motion options load: FILE (or none) for every character, NAME=FILE
/// for the character called NAME (overriding a FILE for all), each with sceneMotion's
/// choice where none is given (its own file's animation). `metresPerUnit` and `jointMap` as
/// addMotion takes them. Throws drape::Error naming --motion for a NAME the scene lacks or
/// a character given twice.
void addSceneMotions(RunSetup& setup, const std::string& scenePath, const std::vector<std::string>& motions,
                     const std::string& animation, double metresPerUnit = 0.0, const std::string& jointMap = "");
/// --motion's help on commands that take it once per character (NAME=FILE).
inline constexpr const char* kMotionPerCharacterHelp =
    "; with several characters in the scene, FILE plays on every one and NAME=FILE on the one the scene calls NAME "
    "(repeatable)";
/// What `avatar` plays without --motion, as the end of "the avatar plays ..." ("its own
/// file's animation 'walk'"), or "" when it stands at rest.
[[nodiscard]] std::string ownMotionText(const scene::Avatar& avatar);
/// The line `drape make-skirt` and `make-scene` end with: how to run the scene they wrote,
/// and what moves `avatar` there without --motion (what sceneMotion would play): its Avatar
/// node's `motion` file when there is one, else its own file's animation, else nothing.
void printHowToRun(const std::string& scene, const scene::Avatar& avatar, const std::string& nodeMotion = "");

/// The world settings of one of the setup's characters (the step, its voxel size, field
/// method, lead-in and keep-apart).
[[nodiscard]] sim::WorldSettings worldSettings(const RunSetup& setup, const CharacterSetup& character);

/// A character's world: fields built, masks bound, solvers ready for the garments it wears,
/// which collide with `guests`' bodies too. Used by `drape run`, `drape play SCENE` and
/// `drape bench paper` alike.
[[nodiscard]] std::unique_ptr<sim::CharacterWorld> buildWorld(const RunSetup& setup, const CharacterSetup& character,
                                                              std::vector<sim::Guest> guests = {});
/// Settles the world's garments before frame 0 for at most the character's settle_s
/// (sim::CharacterWorld::settle) and logs what it did. Call after the colliders' settings,
/// before the first frame. Throws drape::Error (Unstable) when a garment goes unstable.
sim::SettleReport settleWorld(const CharacterSetup& character, sim::CharacterWorld& world);
/// The least T0 of the world's garments: how far the drawn skin may stand out of the body
/// parts (sim::BodySkin).
[[nodiscard]] double leastT0(const sim::CharacterWorld& world);

/// Builds the character's part fields (sim::buildPartFields) into it, saying `why`, unless
/// they were built before: a world built after takes them.
void buildPartFieldsOnce(const RunSetup& setup, CharacterSetup& character, const std::string& why);
/// A live motion's keep-apart (sim::LiveKeepApart), as a world corrects a recorded motion:
/// the character's keepApart parts, the margin its garments need. The part fields it reads are
/// built here (buildPartFieldsOnce) unless they were before: build them before the capture
/// is opened, so that its first frames do not wait for them. Null when the character keeps no parts apart. `rate` is the motion's.
[[nodiscard]] std::shared_ptr<sim::LiveKeepApart> liveKeepApart(const RunSetup& setup, CharacterSetup& character,
                                                               double rate);
/// Logs what a keep-apart changed in the motion: one line, and one per pair it moved.
void logKeptApart(const sim::KeepApartReport& report);

/// The parts --keep-apart names: the list, or none for 'none' (which overrides a scene's).
[[nodiscard]] std::vector<std::string> keepApartParts(const std::vector<std::string>& option);

/// --keep-apart given: the character keeps those parts apart instead of the scene's. Throws
/// "--keep-apart: ..." for a part its avatar does not have, before any field is built.
void setKeepApart(CharacterSetup& character, const std::vector<std::string>& option);

/// "avatar 'A' has no part 'P' (it has: ...)" for a keepApart part the character's avatar
/// does not have; "" when it has them all.
[[nodiscard]] std::string unknownKeepApartPart(const CharacterSetup& character);

/// Where a character's motion puts its world's collidable parts inside each other over
/// setup.frames, beyond their overlap at rest and deeper than a voxel (sim::findBodyOverlaps);
/// none without a motion. `drape run` writes them into stats.json, `drape inspect --motion`
/// lists them.
[[nodiscard]] std::vector<sim::BodyOverlap> bodyOverlaps(const RunSetup& setup, const CharacterSetup& character,
                                                         const sim::CharacterWorld& world);
/// Frames to simulate when none are asked for: the lead-in plus the longest motion. Throws
/// naming --frames when no character has a motion.
[[nodiscard]] long defaultFrames(const RunSetup& setup);

/// What a command's --frames asks: `frames` as given, the frame it ends on (frame 0 is the
/// rest pose: `drape run` ends on frame N, `drape play`, which shows frame 0 first, on N - 1),
/// what it does with them ("simulates", "shows") and whether the command has --lead-in.
struct FramesAsked {
  long frames = 0;
  long lastFrame = 0;
  std::string_view verb;
  bool takesLeadIn = false;
};
/// Warns when --frames, counted from the lead-in's first frame, ends before or at the motion's
/// first: such a run never shows the body moved by its motion (a common slip on an avatar file
/// that plays its own animation, where no --motion recalls the lead-in). Nothing when no
/// character has a motion.
void warnOfFramesWithinTheLeadIn(const RunSetup& setup, const FramesAsked& asked);

/// Checks the setup (garment topology, materials, settings, pins) and throws drape::Error
/// (BadInput) with one line naming what is wrong.
void validateRunSetup(const RunSetup& setup);

/// The smallest substep count per frame that the settings' explicit integrator is estimated
/// to keep stable for every garment, with mass scaling adding at most the settings'
/// maxAddedMass of each (cloth::fewestStableSubsteps: the Runge-Kutta step's own bound and
/// scaling for it, symplectic Euler's for the others), at least 1.
[[nodiscard]] int stableSubsteps(const RunSetup& setup);

/// Simulates and writes every output (each frame once `gate`, if given, lets it: a live
/// motion's). Returns 0; on instability it finishes the files written so far (caches, stats
/// with nan_detected, manifest) and throws drape::Error with ExitCode::Unstable naming
/// garment, vertex and frame.
int simulateRun(const RunSetup& setup, const std::function<bool(long frame)>& gate = nullptr);

/// Every character's world of a setup (buildWorld), and where each garment of the setup is
/// simulated: `drape run`'s loop and `drape play SCENE`'s step them alike. Among several
/// characters, each world's garments collide with the others' bodies too (sim::Guest): their
/// fields are built and their motions kept apart first, so that every world sees each body
/// where its own world moves it.
class SetupWorlds {
 public:
  explicit SetupWorlds(const RunSetup& setup);
  /// What keeping character c's parts apart changed in its motion (empty: nothing asked).
  [[nodiscard]] const sim::KeepApartReport& keepApartReport(std::size_t c) const;

  /// Characters (and worlds), in the setup's order.
  [[nodiscard]] std::size_t size() const { return worlds_.size(); }
  [[nodiscard]] sim::CharacterWorld& world(std::size_t c) { return *worlds_[c]; }
  [[nodiscard]] const sim::CharacterWorld& world(std::size_t c) const { return *worlds_[c]; }
  [[nodiscard]] std::vector<const sim::CharacterWorld*> all() const;
  [[nodiscard]] const std::string& characterName(std::size_t c) const { return names_[c]; }

  /// The character that wears garment g of the setup, and the garment in its world.
  [[nodiscard]] std::size_t characterOf(std::size_t g) const { return place_[g].first; }
  [[nodiscard]] std::size_t indexInWorld(std::size_t g) const { return place_[g].second; }
  [[nodiscard]] cloth::ClothSolver& solver(std::size_t g) { return worlds_[place_[g].first]->mutableSolver(place_[g].second); }
  [[nodiscard]] const cloth::ClothSolver& solver(std::size_t g) const {
    return worlds_[place_[g].first]->solver(place_[g].second);
  }
  [[nodiscard]] cloth::FieldCollider* collider(std::size_t g) {
    return worlds_[place_[g].first]->collider(place_[g].second);
  }
  [[nodiscard]] const cloth::FieldCollider* collider(std::size_t g) const {
    return worlds_[place_[g].first]->collider(place_[g].second);
  }

  /// Sizes `out` to every character's joints.
  void sizeJoints(std::vector<std::vector<RigidTransform>>& out) const;
  /// Every character's joints in the world at `frame` into `out` (sized by sizeJoints).
  void evaluateJoints(long frame, std::vector<std::vector<RigidTransform>>& out) const;

 private:
  std::vector<std::unique_ptr<sim::CharacterWorld>> worlds_;
  std::vector<std::string> names_;
  /// Among several characters: each one's part fields and motion as played (kept apart
  /// where asked, before the worlds, which then keep nothing apart themselves) and the report.
  std::vector<std::shared_ptr<const std::vector<sim::PartField>>> fields_;
  std::vector<std::unique_ptr<motion::AvatarAnimation>> keptApart_;
  std::vector<sim::KeepApartReport> keepApartReports_;
  std::vector<std::pair<std::size_t, std::size_t>> place_;  ///< per garment: character, index in its world
};

/// Where a run's frames go: drape run's files (run_writer.hpp), a cloth-server's stream.
class FrameSink {
 public:
  virtual ~FrameSink() = default;
  /// The worlds are built (one per character, in the setup's order; none without a
  /// character) and the garments' solvers made; the settling and frame 0 come next.
  virtual void begin(const std::vector<const sim::CharacterWorld*>& worlds) = 0;
  /// Each frame in order from 0, on the calling thread while the next are simulated.
  virtual void write(const FrameTaken& frame) = 0;
  /// After the last frame written, also when the run stopped unstable: `frames` frames
  /// were simulated after frame 0.
  virtual void end(long frames) = 0;
  /// Then the run's stats.json.
  virtual void stats(const nlohmann::json& stats) = 0;
};

/// Asked on the simulating thread before each frame from 0: false when there is no frame
/// to simulate (a pose stream ended), true when its motion is there. It may wait, and what
/// it throws ends the run as an instability does (outputs finished, then the error).
using FrameGate = std::function<bool(long frame)>;

/// The simulate-and-hand-over loop behind simulateRun: every frame of the setup (all of
/// setup.frames without a gate; as long as the gate lets it with one) to `sink`. Returns 0;
/// throws as simulateRun does.
int simulateInto(const RunSetup& setup, FrameSink& sink, const FrameGate& gate);

/// The parts a --face-samples-with option names: as given, or none for "none".
[[nodiscard]] std::vector<std::string> facePartsOption(const std::vector<std::string>& given);

/// A garment's vertex states now, as the overlays draw them (render::vertex_state): its
/// collider's collision states (all outside without a collider, or before its first test)
/// with the pinned and bound flags of its fixtures. `drape run` records them per frame,
/// `drape play` shows them live.
void garmentVertexStates(const cloth::ClothSolver& solver, const cloth::FieldCollider* collider,
                         std::vector<std::uint8_t>& out);

}  // namespace drape::cli
