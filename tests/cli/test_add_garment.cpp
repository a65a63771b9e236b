// `drape make-skirt --add-to` and `drape make-scene --add-to`: one more garment for a
// character of a scene already written. Two commands make the bundled layered skirts, to the
// byte of their caches; a garment added to one of two characters lies where the scene stands
// that character and leaves the garments it is worn over as they were; an avatar that wears
// nothing yet is dressed; a garment the scene cannot take is refused with the scene left as
// it was.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "drape/scene/scene.hpp"

namespace drape::add_garment {

using testing::CliResult;
using testing::runDrape;
using testing::runInto;
using testing::ScratchDir;
using testing::slurp;
using testing::statsOf;

const std::string kSource = DRAPE_SOURCE_DIR;
const std::string kBody = "'" + std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_rig_cmu_mb.mhskel'";
const std::string kWalk = "'" + kSource + "/examples/walking_skirt/walk.bvh'";

const scene::Garment& garmentNamed(const scene::Scene& sc, const std::string& name) {
  for (const scene::Garment& g : sc.garments)
    if (g.name == name) return g;
  ADD_FAILURE() << "no garment " << name;
  return sc.garments.front();
}

/// The largest distance between two meshes' vertices, vertex by vertex (infinite when their
/// vertex or triangle counts differ).
double largestDistance(const mesh::TriMesh& a, const mesh::TriMesh& b) {
  if (a.positions.size() != b.positions.size() || a.triangles != b.triangles)
    return std::numeric_limits<double>::infinity();
  double largest = 0.0;
  for (std::size_t i = 0; i < a.positions.size(); ++i)
    largest = std::max(largest, (a.positions[i] - b.positions[i]).norm());
  return largest;
}

TEST(AddGarment, TwoCommandsMakeTheBundledLayeredSkirts) {
  // examples/layered_skirts/README: the petticoat and the skirt, made by make-skirt and put in
  // one scene. Made by the two commands, the scene runs to the same bytes as the bundled one.
  ScratchDir dir("add-garment-layered");
  const std::string scene = dir / "layered/scene.wrl";
  const CliResult petticoat = runDrape("make-skirt " + kBody + " --clearance 0.02 --flare 0.12 --length 0.38 " +
                                           "--name Petticoat --colour 0.92,0.9,0.84 --out '" + (dir / "layered") + "'",
                                       dir);
  ASSERT_EQ(petticoat.code, 0) << petticoat.err;
  EXPECT_NE(petticoat.out.find("wrote " + (dir / "layered") + "/scene.wrl, Petticoat.obj, Petticoat_waistband.obj"),
            std::string::npos)
      << petticoat.out;
  const CliResult skirt =
      runDrape("make-skirt --add-to '" + scene + "' --clearance 0.035 --flare 0.25 --over Petticoat", dir);
  ASSERT_EQ(skirt.code, 0) << skirt.err;
  EXPECT_NE(skirt.out.find("Skirt: 264 vertices, 480 triangles"), std::string::npos) << skirt.out;
  EXPECT_NE(skirt.out.find("worn by Body over Petticoat, 0.004 m above"), std::string::npos) << skirt.out;
  EXPECT_NE(skirt.out.find("added it to " + scene + "; wrote skirt.obj, waistband.obj beside it"), std::string::npos)
      << skirt.out;
  EXPECT_TRUE(std::filesystem::exists(dir / "layered/skirt.obj"));

  const scene::Scene made = scene::loadScene(scene);
  const scene::Scene bundled = scene::loadScene(kSource + "/examples/layered_skirts/scene.wrl");
  ASSERT_EQ(made.garments.size(), 2u);
  for (const char* name : {"Petticoat", "Skirt"}) {
    const scene::Garment& a = garmentNamed(made, name);
    const scene::Garment& b = garmentNamed(bundled, name);
    EXPECT_EQ(largestDistance(a.mesh, b.mesh), 0.0) << name;
    EXPECT_EQ(a.maskVertices, b.maskVertices) << name;
    EXPECT_EQ(a.over, b.over) << name;
    EXPECT_EQ(a.collidesWith, b.collidesWith) << name;
  }
  // Its own knit, named after it; a colour neither garment had (the petticoat's was given).
  ASSERT_EQ(made.materials.size(), 2u);
  EXPECT_EQ(made.materials[static_cast<std::size_t>(garmentNamed(made, "Skirt").material)].name, "Skirt knit");
  ASSERT_TRUE(garmentNamed(made, "Skirt").colour.has_value());
  EXPECT_NEAR(garmentNamed(made, "Skirt").colour->x(), 0.7, 1e-6);

  const std::string options = " --motion " + kWalk + " --frames 12";
  const std::string ours = runInto(dir, "ours", "'" + scene + "'" + options);
  const std::string theirs =
      runInto(dir, "bundled", "'" + kSource + "/examples/layered_skirts/scene.wrl'" + options);
  for (const char* cache : {"garment-Petticoat.pc2", "garment-Skirt.pc2"})
    EXPECT_EQ(slurp(ours + "/" + cache), slurp(theirs + "/" + cache)) << cache;
  EXPECT_GT(statsOf(ours)["garments"][1]["worn_over"]["contacts"].get<long>(), 0);
}

TEST(AddGarment, ASkirtOverAnotherWithTheDefaultsClearsItAndWalks) {
  // Both skirts made with make-skirt's defaults: the second is fitted over the first, its
  // waistband one gap out from the other's and every lower ring two (before, it lay on it,
  // vertex for vertex). Worn over it through the walk it stays stable: where a vertex of the
  // skirt below pushes into a triangle held at its waistband, the free corner is not flung
  // out (cloth::LayerCollider::kMostLever).
  ScratchDir dir("add-garment-defaults");
  const CliResult skirt = runDrape("make-skirt " + kBody + " --out '" + (dir / "layered") + "'", dir);
  ASSERT_EQ(skirt.code, 0) << skirt.err;
  const std::string scene = dir / "layered/scene.wrl";
  const CliResult over = runDrape("make-skirt --add-to '" + scene + "' --name Over --over Skirt", dir);
  ASSERT_EQ(over.code, 0) << over.err;
  EXPECT_EQ(over.out.find("lie under"), std::string::npos) << over.out;
  const scene::Scene sc = scene::loadScene(scene);
  const mesh::TriMesh& under = garmentNamed(sc, "Skirt").mesh;
  const mesh::TriMesh& outer = garmentNamed(sc, "Over").mesh;
  ASSERT_EQ(under.positions.size(), outer.positions.size());  // the same rings and angles
  const double gap = garmentNamed(sc, "Over").overGap;
  EXPECT_NEAR(gap, 0.004, 1e-9);
  // Each ring's vertex lies at the same angle and height as the other's; a staggered ring's
  // vertices fall short of its ellipse's extents (by 1 - cos 7.5 degrees: 1.7 mm at
  // the hip, 2.6 mm at the hem), which are what the fit clears, so its vertices are a little
  // less than two gaps out.
  const std::size_t around = 24;
  for (std::size_t v = 0; v < under.positions.size(); ++v) {
    const double apart = (outer.positions[v] - under.positions[v]).norm();
    EXPECT_GE(apart, v < around ? 0.99 * gap : 1.25 * gap) << "vertex " << v;
    EXPECT_LE(apart, v < around ? 1.01 * gap : 2 * gap + 0.003) << "vertex " << v;
  }
  const std::string run = dir / "walk";
  const CliResult walked = runDrape("run '" + scene + "' --motion " + kWalk + " --frames 60 --out '" + run + "'", dir);
  ASSERT_EQ(walked.code, 0) << walked.err;
  EXPECT_EQ(walked.err.find("warning"), std::string::npos) << walked.err;
  const nlohmann::json stats = statsOf(run);
  EXPECT_EQ(stats["unstable"], false);
  EXPECT_EQ(stats["last_resort_projections"], 0);
  EXPECT_LT(stats["max_stretch"].get<double>(), 0.3);
  EXPECT_GT(stats["garments"][1]["worn_over"]["contacts"].get<long>(), 0);
}

TEST(AddGarment, OnOneOfTwoCharactersWhereTheSceneStandsThem) {
  // Bea stands 1.2 m to Ada's side. A skirt fitted to her there by make-skirt, and the same
  // skirt modelled on the avatar's own file and put on her by make-scene, lie on her and
  // match; worn over her skirt, they leave both characters' skirts as they were (one way).
  ScratchDir dir("add-garment-two");
  const std::string scene = testing::twoCharactersWithBeaAt(dir, "1.2 0 0");
  const std::string before = runInto(dir, "before", "'" + scene + "' --frames 8");

  const CliResult which = runDrape("make-skirt --add-to '" + scene + "' --clearance 0.035 --flare 0.25", dir);
  EXPECT_EQ(which.code, 2);
  EXPECT_NE(which.err.find("the scene has 2 characters (Ada, Bea); say which wears the garment with --character NAME"),
            std::string::npos)
      << which.err;
  const CliResult fitted = runDrape("make-skirt --add-to '" + scene + "' --character Bea --clearance 0.035 " +
                                        "--flare 0.25 --over 'Bea skirt' --name 'Bea overskirt'",
                                    dir);
  ASSERT_EQ(fitted.code, 0) << fitted.err;
  EXPECT_NE(fitted.out.find("(the avatar plays " + std::string(DRAPE_DATA_DIR) + "/mocap/cmu_walk_delfem2.bvh;"),
            std::string::npos)
      << fitted.out;

  // The same skirt made on the avatar alone, where its own file stands it (at the origin).
  const CliResult alone = runDrape("make-skirt " + kBody + " --clearance 0.035 --flare 0.25 --out '" +
                                       (dir / "alone") + "'",
                                   dir);
  ASSERT_EQ(alone.code, 0) << alone.err;
  const CliResult put = runDrape("make-scene --add-to '" + scene + "' --character Bea --garment '" +
                                     (dir / "alone/skirt.obj") + "' --mask '" + (dir / "alone/waistband.obj") +
                                     "' --name 'Bea second' --over 'Bea overskirt' --offsets 0.004,0.008,0.012,0.024",
                                 dir);
  ASSERT_EQ(put.code, 0) << put.err;
  EXPECT_NE(put.out.find("worn by Bea over Bea overskirt"), std::string::npos) << put.out;

  const scene::Scene sc = scene::loadScene(scene);
  ASSERT_EQ(sc.garments.size(), 4u);
  const scene::Garment& over = garmentNamed(sc, "Bea overskirt");
  const scene::Garment& second = garmentNamed(sc, "Bea second");
  EXPECT_EQ(over.over, std::vector<std::string>{"Bea skirt"});
  EXPECT_EQ(second.over, std::vector<std::string>{"Bea overskirt"});
  ASSERT_TRUE(second.offsets.has_value());
  EXPECT_NEAR((*second.offsets)[3], 0.024, 1e-7);  // SFFloat
  EXPECT_NEAR(over.mesh.bounds().center().x(), 1.2, 0.03);
  // Both written to 10 micrometres.
  EXPECT_LT(largestDistance(over.mesh, second.mesh), 2e-5);
  EXPECT_FALSE(over.colour && second.colour && (*over.colour - *second.colour).norm() < 0.05);

  // The second one is the first one again, 4 mm over it: the run takes one of the two out.
  std::string text = slurp(scene);
  text = text.substr(0, text.find("# Bea second: added by"));
  std::ofstream(scene, std::ios::trunc) << text;
  const std::string after = runInto(dir, "after", "'" + scene + "' --frames 8");
  for (const char* cache : {"garment-Ada skirt.pc2", "garment-Bea skirt.pc2"})
    EXPECT_EQ(slurp(before + "/" + cache), slurp(after + "/" + cache)) << cache;
  const nlohmann::json stats = statsOf(after);
  EXPECT_EQ(stats["vertex_substeps_inside_body"], 0);
  EXPECT_EQ(stats["garments"][2]["name"], "Bea overskirt");
  EXPECT_GT(stats["garments"][2]["worn_over"]["contacts"].get<long>(), 0);
  EXPECT_EQ(stats["garments"][2]["worn_over"]["crossings"], 0);
}

TEST(AddGarment, AnAvatarThatWearsNothingYetIsDressed) {
  // Bea stands in the scene without her skirt: a run leaves her out (saying so), and
  // make-skirt --add-to dresses her where she stands, then a run takes her in.
  ScratchDir dir("add-garment-undressed");
  std::string text = slurp(testing::twoCharactersWithBeaAt(dir, "1.2 0 0"));
  const std::size_t from = text.find("    DEF BeaSkirt ClothSet {");
  ASSERT_NE(from, std::string::npos);
  text.erase(from, text.find("\n    }\n", from) + 7 - from);
  const std::string scene = dir / "undressed.wrl";
  std::ofstream(scene) << text;
  const CliResult before = runDrape("run '" + scene + "' --frames 2 --out '" + (dir / "before") + "'", dir);
  ASSERT_EQ(before.code, 0) << before.err;
  EXPECT_NE(before.err.find("avatar 'Bea' wears no garment; it is left out"), std::string::npos) << before.err;

  const CliResult dressed = runDrape("make-skirt --add-to '" + scene + "' --character Bea --name 'Bea skirt'", dir);
  ASSERT_EQ(dressed.code, 0) << dressed.err;
  EXPECT_NE(dressed.out.find("worn by Bea"), std::string::npos) << dressed.out;
  const scene::Scene sc = scene::loadScene(scene);
  ASSERT_EQ(sc.garments.size(), 2u);
  const Aabb box = garmentNamed(sc, "Bea skirt").mesh.bounds();
  EXPECT_NEAR(box.center().x(), 1.2, 0.02);
  const std::string out = dir / "after";
  const CliResult after = runDrape("run '" + scene + "' --frames 5 --out '" + out + "'", dir);
  ASSERT_EQ(after.code, 0) << after.err;
  EXPECT_EQ(after.err.find("wears no garment"), std::string::npos) << after.err;
  const nlohmann::json stats = statsOf(out);
  EXPECT_EQ(stats["garments"].size(), 2u);
  EXPECT_EQ(stats["vertex_substeps_inside_body"], 0);

  // A scene of one avatar and no garment at all is dressed without --character.
  std::string alone = slurp(kSource + "/examples/walking_skirt/scene.wrl");
  alone = alone.substr(0, alone.find("DEF Skirt ClothSet"));
  alone.replace(alone.find("\"../../data/"), 12, "\"" + std::string(DRAPE_DATA_DIR) + "/");
  const std::string lone = dir / "alone.wrl";
  std::ofstream(lone) << alone;
  const CliResult first = runDrape("make-skirt --add-to '" + lone + "'", dir);
  ASSERT_EQ(first.code, 0) << first.err;
  EXPECT_EQ(scene::loadScene(lone).garments.size(), 1u);
}

TEST(AddGarment, AGarmentTheSceneCannotTakeLeavesItAsItWas) {
  ScratchDir dir("add-garment-refused");
  const std::string scene = dir / "scene.wrl";
  std::ofstream(scene) << testing::exampleSceneWithDataFound(kSource + "/examples/walking_skirt/scene.wrl");
  const std::string original = slurp(scene);
  const auto refused = [&](const std::string& args, const std::string& says) {
    const std::string before = slurp(scene);
    const CliResult r = runDrape(args, dir);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.out;
    EXPECT_NE(r.err.find(says), std::string::npos) << args << "\n" << r.err;
    EXPECT_TRUE(slurp(scene) == before) << args << ": the scene changed";
  };
  const std::string add = "make-skirt --add-to '" + scene + "' ";
  refused(add + "--over Skirt", "the scene has a garment called 'Skirt' already; call this one something else with --name");
  refused(add + "--name Outer --over Petticoat", "--over Petticoat: not a garment of 'Body' in " + scene + " (it wears: Skirt)");
  refused(add + "--name Outer --over-gap 0.01", "--over-gap goes with --over");
  refused(add + "--name Outer --out '" + (dir / "x") + "'", "--out does not go with --add-to");
  refused(add + "--name Outer " + kBody, "the garment goes on the scene's character; give no avatar");
  refused(add + "--name Outer --character Ada", "--character Ada: " + scene + " has no character of that name");
  refused(add + "--name Outer --waist-segment Waist", "the avatar has no segment 'Waist'");
  refused("make-skirt " + kBody + " --out '" + (dir / "x") + "' --over Skirt", "--over goes with --add-to SCENE");
  refused("make-skirt --clearance 0.03", "make-skirt: give the avatar to fit it to, or --add-to SCENE");
  // A skirt narrower than the one it is worn over lies under it, most of it deeper than drape
  // run moves out: refused. (make-skirt --over fits it over the skirt; a skirt modelled on
  // the body alone, put on by make-scene, is not.)
  const auto modelled = [&](const std::string& name, const std::string& fit) {
    const CliResult made = runDrape("make-skirt " + kBody + " " + fit + " --out '" + (dir / name) + "'", dir);
    EXPECT_EQ(made.code, 0) << made.err;
    return "make-scene --add-to '" + scene + "' --garment '" + (dir / name) + "/skirt.obj' --mask '" + (dir / name) +
           "/waistband.obj' --name " + name + " --over Skirt";
  };
  const std::string inner = modelled("Inner", "--clearance 0.01 --flare 0.05");
  refused(inner, "of the vertices of 'Inner' lie under Skirt by more than 16 mm (the deepest, vertex ");

  // The MakeHuman dress needs far more substeps than the skirt's scene steps.
  const std::string dress = "make-scene --add-to '" + scene + "' --garment '" + kSource +
                            "/data/garments/makehuman_female_elegantsuit01_dress.mhclo' --units dm --mask '" + kSource +
                            "/examples/walking_dress/mask.obj' --name dress ";
  refused(dress + "--substeps 155", "--substeps does not go with --add-to: the garment is added to the scene as it is");
  refused(dress, "the scene steps 33 substeps per frame, and 'dress' needs ");
  refused(dress, "set stepsPerFrame ");

  // A character's node without a DEF name cannot be named by a ClothSet appended to the file.
  std::string undefined = original;
  testing::replaceOnce(undefined, "DEF Body Avatar {", "Avatar {");
  testing::replaceOnce(undefined, "  avatar USE Body\n", "");
  std::ofstream(scene, std::ios::trunc) << undefined;
  refused(add + "--name Outer", "(line 32) has no DEF name for the new ClothSet to USE; write DEF NAME before it");

  // One called by its name field uses its DEF name.
  std::string named = original;
  testing::replaceOnce(named, "DEF Body Avatar {", "DEF Body Avatar {\n  name \"Ada\"");
  std::ofstream(scene, std::ios::trunc) << named;
  // A little narrower than the skirt low down: the run moves those vertices out over it.
  const CliResult r = runDrape(modelled("Outer", "--clearance 0.022 --flare 0.11"), dir);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("worn by Ada over Skirt"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("144 of its vertices lie under Skirt by up to 2.7 mm: drape run moves them out over it"),
            std::string::npos)
      << r.out;
  const nlohmann::json over = statsOf(runInto(dir, "run", "'" + scene + "' --frames 3"))["garments"][1]["worn_over"];
  EXPECT_EQ(over["vertices_lifted_over"], 144);
  EXPECT_EQ(over["vertices_left_under"], 0);

  // Written by hand over the skirt, the narrow one is run: the run says what it leaves under.
  std::ofstream(scene, std::ios::trunc) << named;
  ASSERT_EQ(runDrape(add + "--name Inner --clearance 0.01 --flare 0.05", dir).code, 0);
  std::string under = slurp(scene);
  const std::size_t last = under.rfind("  maskTolerance 0.0005");
  under.insert(last, "  over [ \"Skirt\" ]\n");
  std::ofstream(scene, std::ios::trunc) << under;
  const CliResult ran = runDrape("run '" + scene + "' --frames 2 --out '" + (dir / "inner") + "'", dir);
  EXPECT_EQ(ran.code, 0) << ran.err;
  EXPECT_NE(ran.err.find("Inner: 192 of its vertices lie too far under Skirt to be moved out (more than 16 mm"),
            std::string::npos)
      << ran.err;
  EXPECT_EQ(statsOf(dir / "inner")["garments"][1]["worn_over"]["vertices_left_under"], 192);
  const std::string added = slurp(scene);
  EXPECT_TRUE(added.substr(0, named.size()) == named) << "the scene's own text changed";
  EXPECT_NE(added.find("  avatar USE Body\n  collidesWith", named.size()), std::string::npos);
}

TEST(AddGarment, AnImplicitOrRungeKuttaSceneTakesAGarmentAtItsOwnSubsteps) {
  // A skirt added to a scene stepped by backward Euler (5 substeps) or by the Runge-Kutta step
  // at its own bound (11, no mass allowed) is judged by that scene's integrator: backward
  // Euler needs no mass at any substep, and the Runge-Kutta step none where the unscaled
  // membrane keeps its bound, so both take it as they are. (Judged by symplectic Euler's
  // bound, or by element estimates that add mass where none is needed, both were refused.)
  ScratchDir dir("add-garment-integrators");
  for (const std::string integrator : {"backward-euler", "runge-kutta-4"}) {
    SCOPED_TRACE(integrator);
    const std::string out = dir / integrator;
    const CliResult petticoat = runDrape("make-skirt " + kBody + " --integrator " + integrator +
                                             " --clearance 0.02 --flare 0.12 --length 0.38 --name Petticoat --out '" +
                                             out + "'",
                                         dir);
    ASSERT_EQ(petticoat.code, 0) << petticoat.err;
    const scene::Scene before = scene::loadScene(out + "/scene.wrl");
    EXPECT_EQ(before.simulation.maxAddedMass, 0.0);
    const CliResult skirt = runDrape(
        "make-skirt --add-to '" + out + "/scene.wrl' --clearance 0.035 --flare 0.25 --over Petticoat", dir);
    ASSERT_EQ(skirt.code, 0) << skirt.err;
    EXPECT_NE(skirt.out.find("substeps per frame keep it stable"), std::string::npos) << skirt.out;
    const scene::Scene after = scene::loadScene(out + "/scene.wrl");
    EXPECT_EQ(after.garments.size(), 2u);
    EXPECT_EQ(after.simulation.integrator, integrator);
    EXPECT_EQ(after.simulation.stepsPerFrame, before.simulation.stepsPerFrame);
  }
}

}  // namespace drape::add_garment
