// `drape inspect FILE`: a readable summary of any file drape reads, or of a run directory
// (inspect_run.hpp). The readers register an inspector per file extension
// (registerInspector in their cmd_inspect_*.cpp).

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>

#include <fmt/format.h>
#include <fmt/ostream.h>

#include "command.hpp"
#include "drape/core/error.hpp"
#include "drape/core/files.hpp"
#include "drape/sim/body_overlap.hpp"
#include "inspect_run.hpp"
#include "inspect_studio.hpp"
#include "run_setup.hpp"

namespace drape::cli {
namespace {

std::vector<InspectorEntry>& inspectors() {
  static std::vector<InspectorEntry> entries;
  return entries;
}

/// With a scene and its avatar's motion: where the motion puts the collidable parts inside
/// each other (sim::findBodyOverlaps), as `drape run` finds it, without simulating.
void inspectBodyOverlaps(const std::string& scenePath, const std::string& motionPath,
                         const std::vector<std::string>& keepApart, std::ostream& out) {
  RunSetup setup = runSetupFromScene(scenePath);
  CharacterSetup* character = oneCharacter(setup, "drape inspect --motion");
  if (!character) throw Error(fmt::format("--motion: {} has no avatar to move", scenePath));
  addMotion(setup, *character, motionPath);
  if (!keepApart.empty()) setKeepApart(*character, keepApart);
  setup.frames = defaultFrames(setup);
  const std::unique_ptr<sim::CharacterWorld> world = buildWorld(setup, *character);
  const std::vector<sim::BodyOverlap> found = bodyOverlaps(setup, *character, *world);
  fmt::print(out, "body overlaps over {} frames with {} (collidable parts inside each other beyond their overlap at "
                  "rest, deeper than a voxel): {}\n",
             setup.frames, motionPath, found.empty() ? "none" : std::to_string(found.size()));
  for (const sim::BodyOverlap& o : found) fmt::print(out, "  {}\n", sim::describe(o));
  if (!found.empty() && character->keepApart.empty())
    fmt::print(out, "cloth caught between such parts has no place; `drape run --keep-apart PARTS` (or the scene's "
                    "Simulation keepApart) turns the parts named out of the others before simulating\n");
}

RunFunction setupInspect(CLI::App& app) {
  static std::string path, motion;
  static std::vector<std::string> keepApart;
  static RunQuery query;
  app.add_option("file", path,
                 "The file to summarise, a run directory (what `drape run --out` wrote), or a studio's NATS server "
                 "(nats://HOST:PORT)")
      ->required();
  app.add_option("--motion", motion,
                 "With a scene: also load this motion onto its avatar and list where it puts the collidable parts "
                 "inside each other (cloth between them has no place), without simulating");
  app.add_option("--keep-apart", keepApart,
                 "With --motion: first correct the motion to keep these parts out of the others, as `drape run "
                 "--keep-apart` does, and list what is left (instead of the scene's keepApart; 'none' for none)")
      ->delimiter(',');
  app.add_option("--deepest", query.deepest,
                 "With a run directory: list the N garment vertices that go deepest into the body (its skin, as "
                 "players draw it), each in its deepest frame, with its state and the collidable parts it is nearest")
      ->check(CLI::PositiveNumber);
  app.add_option("--stretched", query.stretched,
                 "With a run directory: list the N garment edges stretched most beyond their length at rest, each in "
                 "the frame it is longest, with its vertices' states and the collidable parts nearest its middle (a "
                 "pinch between two parts shows there)")
      ->check(CLI::PositiveNumber);
  app.add_option("--vertex", query.vertex,
                 "With a run directory: follow this garment vertex frame by frame: its state, its distance to the "
                 "skin and to the two nearest collidable parts (what it rests on)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--range", query.range,
                 "With --deepest, --stretched or --vertex: only the run's frames FIRST:LAST (0-based, inclusive; FIRST: to the "
                 "end; one FRAME)");
  app.add_option("--garment", query.garment,
                 "With --deepest, --stretched or --vertex: only this garment (by its name in the run)");
  app.footer([] {
    std::string text = "Understands:";
    text += fmt::format("\n  {:<29} {}", "DIR", "a run directory (manifest.json): its meshes, figures and, with "
                                                "--deepest, --stretched or --vertex, where its garments lie against "
                                                "the body");
    text += fmt::format("\n  {:<29} {}", "nats://HOST:PORT",
                        "a studio's NATS server: each drape stream, its take, what it carries, how far it has come");
    // Joined first: a width given with fmt::join pads each extension, not the list.
    for (const InspectorEntry& e : registeredInspectors())
      text += fmt::format("\n  {:<29} {}", fmt::format("{}", fmt::join(e.extensions, " ")), e.what);
    return text;
  });
  return [] {
    if (isServerUrl(path)) {
      inspectStudio(path, std::cout);
      return 0;
    }
    if (!std::filesystem::exists(path)) throw Error(fmt::format("{}: no such file", path));
    if (std::filesystem::is_directory(path)) {
      if (!motion.empty() || !keepApart.empty()) throw Error("--motion and --keep-apart go with a scene, not a run");
      inspectRun(path, query, std::cout);
      return 0;
    }
    if (query.any()) throw Error(fmt::format("--deepest, --stretched, --vertex, --range and --garment go with a run directory, not with {}",
                              path));
    const std::string ext = lowerExtension(path);
    for (const InspectorEntry& e : registeredInspectors()) {
      if (std::find(e.extensions.begin(), e.extensions.end(), ext) != e.extensions.end()) {
        if (!keepApart.empty() && motion.empty()) throw Error("--keep-apart goes with --motion");
        if (!motion.empty() && ext != ".wrl" && ext != ".vrml")
          throw Error(fmt::format("--motion goes with a scene (.wrl), not with {}", path));
        e.inspect(path, std::cout);
        if (!motion.empty()) inspectBodyOverlaps(path, motion, keepApart, std::cout);
        return 0;
      }
    }
    throw Error(fmt::format("{}: drape cannot inspect '{}' files (see drape inspect --help)", path, ext));
  };
}

const bool registered_cmd_inspect = registerCommand(
    {"inspect", "Print a readable summary of a scene, avatar, motion or mesh file, or of a run", "", 30, &setupInspect});

}  // namespace

bool registerInspector(std::vector<std::string> extensions, std::string what, Inspector inspector) {
  inspectors().push_back({std::move(extensions), std::move(what), std::move(inspector)});
  return true;
}

const std::vector<InspectorEntry>& registeredInspectors() { return inspectors(); }

}  // namespace drape::cli
