#pragma once
// `--add-to SCENE` of `drape make-skirt` and `drape make-scene`: one more garment for a
// character of a scene already written (a skirt over the petticoat it wears), appended to the
// scene file as a ClothSet, after the scene with it has been read as `drape run` reads it.

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "drape/cloth/material.hpp"
#include "drape/core/math.hpp"
#include "drape/mesh/trimesh.hpp"
#include "drape/scene/scene.hpp"
#include "drape/sim/scene_setup.hpp"
#include "avatar_scale.hpp"
#include "scene_text.hpp"

namespace drape::cli {

/// The options `drape make-skirt` and `drape make-scene` share for adding a garment.
struct AddToOptions {
  std::string scene;              ///< --add-to: the scene the garment is added to ("": a new scene)
  std::string character;          ///< --character: who wears it there
  std::vector<std::string> over;  ///< --over: the garments it is worn over
  double overGap_m = 0.004;       ///< --over-gap
  bool overGapGiven = false;      ///< --over-gap given (else 4 mm, less on a character under 1 m tall)
  /// --colour: R, G, B from 0 to 1; empty: the command's own colour, or with --add-to one
  /// that no garment of the scene has.
  std::vector<double> colour;
};

/// Adds --add-to (`addToHelp`), --character, --over, --over-gap and --colour (whose help
/// names `ownColour`, the command's default) to the command.
void addAddToOptions(CLI::App& app, AddToOptions& o, const std::string& addToHelp, const std::string& ownColour);

/// Whether the command adds to a scene; throws drape::Error for what does not go together:
/// the avatar positional, --out and the scene's own settings `sceneOptions` with --add-to;
/// no avatar, no --out, or --character, --over, --over-gap without it; --over-gap without
/// --over.
bool addingToScene(const CLI::App& app, const AddToOptions& o, const std::string& command, const std::string& avatar,
                   const std::string& out, const std::vector<std::string>& sceneOptions);

/// A scene a garment is being added to, and the character who will wear it.
struct SceneToDress {
  std::string path;   ///< the scene file
  std::string text;   ///< its text as it is
  scene::Scene scene;
  sim::SceneCharacter character;  ///< who will wear the garment: loaded and placed as the scene says
  std::string avatarDef;          ///< the DEF name of its Avatar or Humanoid node, for `avatar USE`
  /// The file its Avatar node loads (the first of its urls that exists); "" for a Humanoid
  /// written in the scene.
  std::string avatarFile;
  /// Where that file's frame lies in the scene: a point p of it is at placement(scale p).
  RigidTransform placement;
  double scale = 1.0;
};

/// Reads the scene and finds its character `character` (its Avatar or Humanoid node's name),
/// or its only one when `character` is "". Throws drape::Error naming the scene when it does
/// not load, dresses no character yet, has several and none is named, has no such
/// character, or the character's node has no DEF name of the scene's own file to USE.
[[nodiscard]] SceneToDress openSceneToDress(const std::string& path, const std::string& character);

/// Throws drape::Error when `name` is taken by a garment of the scene or `over` names
/// anything but the character's own garments.
void checkNewGarment(const SceneToDress& dress, const std::string& name, const std::vector<std::string>& over);

/// Checks that the scene's substeps per frame (its Simulation node's stepsPerFrame, mass
/// scaling within its maxAddedMass, bending every bendEvery) keep the new garment stable, and
/// returns the fraction of its mass that scaling adds. Throws drape::Error naming the scene,
/// the garment and the substeps per frame it needs.
double checkSceneSteps(const SceneToDress& dress, const mesh::TriMesh& garment, const cloth::Material& material,
                       const std::string& name);

/// The first of a few garment colours that no garment of the scene has.
[[nodiscard]] Vec3 unusedColour(const scene::Scene& scene);

/// A mesh in world metres, in the scene file's units (its unitScale).
[[nodiscard]] mesh::TriMesh inFileUnits(const SceneToDress& dress, mesh::TriMesh world);

/// On a character under 1 m tall (`scale`, the scene's voxel being its own): the default
/// --over-gap scaled from a person's 4 mm by its height, and a warning when the scene's voxel
/// is a person's, whose offsets are too wide around small parts. Returns what was scaled,
/// for the command's message ("0.62 mm above Skirt (a person's: 4 mm)"), or "".
std::string fitToASmallCharacter(AddToOptions& o, const SceneToDress& dress, const SceneScale& scale);

/// Where the new garment goes and what it looks like: the options' over, gap and colour (a
/// colour of the scene's garments' own when none is given), the character's DEF as its
/// avatar, `material` (a node's text) as its material.
void dressFor(ClothSetText& c, const SceneToDress& dress, const AddToOptions& o, const std::string& material);

/// The comment written above the new ClothSet: who added it and who wears it over what.
[[nodiscard]] std::string addedComment(const std::string& command, const std::string& name, const SceneToDress& dress,
                                       const AddToOptions& o);
/// "worn by Bea over Petticoat, 0.004 m above".
[[nodiscard]] std::string wornText(const SceneToDress& dress, const AddToOptions& o);
/// The line that says the scene's substeps keep it stable, with the mass scaling adds.
void printSceneSteps(const SceneToDress& dress, double addedMassFraction);

/// Appends `clothSet` (a ClothSet node's text, of a garment worn by the character) to the
/// scene and rewrites the file, once the new text has been read and built as `drape run`
/// reads it and what of the garment starts under the garments it is worn over has been
/// found as `drape run` finds it (sim::makeLayerCollider): a scene that would not load, or a
/// garment lying under them too deep for the run to move out, is refused with the file left
/// as it was. Prints how many of its vertices the run will move out over them.
void appendToScene(const SceneToDress& dress, const std::string& clothSet);

}  // namespace drape::cli
