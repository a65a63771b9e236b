// Scenes from VRML97: avatars from the real H-Anim files in data/vrml, every field of
// drape's nodes with values and defaults, PROTOs from the prelude and from the file,
// DEF/USE sharing, Inline, unit scale, masks, and the domain errors with their lines.

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "drape/core/error.hpp"
#include "drape/formats/vrml_read.hpp"
#include "drape/scene/scene.hpp"
#include "drape/scene/scene_build.hpp"
#include "drape/testing/errors.hpp"
#include "drape/testing/temp_dir.hpp"

namespace drape::scene {
namespace {

const std::string kVrmlData = std::string(DRAPE_DATA_DIR) + "/vrml/";

Scene fromText(const std::string& text, const std::string& name = "scene.wrl", const std::string& dir = ".") {
  return buildScene(formats::vrml::readText(text, name, dir));
}

using drape::testing::errorOf;

std::string tempDir() {
  return drape::testing::processTempDir("scene").string();
}

const std::string kTriangle =
    "IndexedFaceSet { coord Coordinate { point [ 0 0 0, 1 0 0, 0 1 0 ] } coordIndex [ 0 1 2 -1 ] }";

TEST(VrmlScene, Sr1IsAnAvatarOfThirtyJoints) {
  const Scene s = loadScene(kVrmlData + "choreonoid_SR1.wrl");
  ASSERT_EQ(s.avatars.size(), 1u);
  const Avatar& a = s.avatars[0];
  EXPECT_EQ(a.name, "SR1");
  EXPECT_EQ(a.joints.size(), 30u);
  EXPECT_EQ(a.segments.size(), 30u);
  for (std::size_t j = 0; j < a.joints.size(); ++j)
    EXPECT_LT(a.joints[j].parent, static_cast<int>(j));  // parents first
  const int waist = a.findJoint("WAIST");
  ASSERT_EQ(waist, 0);
  EXPECT_NEAR(a.joints[0].restCenter.z(), 0.7135, 1e-6);
  // WAIST_P sits 0.176 m above the waist (translation 0 0 0.176 in the file).
  EXPECT_NEAR(a.joints[static_cast<std::size_t>(a.findJoint("WAIST_P"))].restCenter.z(), 0.7135 + 0.176, 1e-5);
  // WAIST_LINK0: a 0.08 m box at the joint and a 0.05 x 0.05 x 0.111 box 0.0955 m above it,
  // in the joint's frame (unit scale, aligned with the root).
  const Segment& link = a.segments[static_cast<std::size_t>(a.findSegment("WAIST_LINK0"))];
  EXPECT_EQ(link.joint, waist);
  EXPECT_EQ(link.mesh.triangleCount(), 24u);
  const Aabb box = link.mesh.bounds();
  EXPECT_NEAR(box.min.x(), -0.04, 1e-6);
  EXPECT_NEAR(box.max.x(), 0.04, 1e-6);
  EXPECT_NEAR(box.min.z(), -0.04, 1e-6);
  EXPECT_NEAR(box.max.z(), 0.0955 + 0.0555, 1e-6);
  EXPECT_TRUE(s.garments.empty());
  EXPECT_TRUE(s.scenery.empty());
}

TEST(VrmlScene, Gr001SegmentsComeFromInlineFiles) {
  const Scene s = loadScene(kVrmlData + "choreonoid_GR001/GR001.wrl");
  ASSERT_EQ(s.avatars.size(), 1u);
  EXPECT_EQ(s.avatars[0].joints.size(), 21u);
  ASSERT_EQ(s.avatars[0].segments.size(), 21u);
  for (const Segment& seg : s.avatars[0].segments) {
    EXPECT_GT(seg.mesh.triangleCount(), 20u) << seg.name;
    // The parts are in millimetres under a 0.001 scale: a segment spans centimetres.
    EXPECT_LT(seg.mesh.bounds().size().maxCoeff(), 0.2) << seg.name;
  }
}

TEST(VrmlScene, TorusAndVaseLoad) {
  const Scene torus = loadScene(kVrmlData + "choreonoid_Torus.wrl");
  ASSERT_EQ(torus.avatars.size(), 1u);
  EXPECT_EQ(torus.avatars[0].joints.size(), 1u);
  EXPECT_EQ(torus.avatars[0].segments.at(0).mesh.triangleCount(), 2048u);  // the Extrusion, tessellated
  const Scene vase = loadScene(kVrmlData + "choreonoid_vase.wrl");
  EXPECT_TRUE(vase.avatars.empty());
  ASSERT_EQ(vase.scenery.size(), 1u);
  EXPECT_EQ(vase.scenery[0].name, "BudVase");
  EXPECT_EQ(vase.scenery[0].mesh.triangleCount(), 2592u);
  // Transform scale 0.006: the vase is centimetres-to-decimetres tall, not metres.
  EXPECT_LT(vase.scenery[0].mesh.bounds().size().maxCoeff(), 1.0);
}

TEST(VrmlScene, EveryFieldWithValues) {
  const Scene s = fromText(
      "#VRML V2.0 utf8\n"
      "Simulation { gravity 0 0 -9.8 frameRate 25 stepsPerFrame 40 airViscosity 0.05 wind 1 0 0.5\n"
      "  offsets [ 0.001 0.002 0.003 0.004 ] voxelSize 0.005 integrator \"euler\" collisionEvery 2 bendEvery 4 unitScale 0.01\n"
      "  maxRefinement 4 strainLimit 0.25 rescueStrainLimit 0.75 implicitTolerance 0.0002\n"
      "  keepApart [ \"LeftForeArm\", \"RightForeArm\" ] }\n"
      "DEF Body Humanoid { humanoidBody DEF Root Joint { name \"root\" children [ DEF Hips Segment { name \"hips\" "
      "children Shape { geometry Box { } } } ] } }\n"
      "DEF Silk ClothMaterial { name \"silk\" density 1300 thickness 0.0002 youngsModulus 2e6 poissonRatio 0.25 "
      "bendingStiffness 1e-6\n"
      "  damping 0.1 staticFriction 0.4 dynamicFriction 0.2 compressionScale 0.5 }\n"
      "DEF Scarf ClothSet { name \"scarf\" material USE Silk avatar USE Body collidesWith [ \"hips\" ] faceSamplesWith "
      "[ \"hips\" ] stitches [ 0 2, 1 0 ] selfCollision 0.004 offsets [ 0.001 0.002 0.003 0.012 ] maskTolerance "
      "0.002 "
      "bindThreshold 0.03\n  cloth " +
      kTriangle + "\n  constraintMask " + kTriangle +
      " }\n"
      "Avatar { name \"guest\" url [ \"guest.glb\" ] jointMap [ \"map.json\" ] translation 100 0 0 scale 2 }\n");
  const SimulationSettings& sim = s.simulation;
  EXPECT_TRUE(s.hasSimulationNode);
  EXPECT_TRUE(sim.gravity.isApprox(Vec3(0, 0, -9.8), 1e-6));
  EXPECT_DOUBLE_EQ(sim.frameRate, 25);
  EXPECT_EQ(sim.stepsPerFrame, 40);
  EXPECT_NEAR(sim.airViscosity, 0.05, 1e-7);
  EXPECT_EQ(sim.wind, Vec3(1, 0, 0.5));
  ASSERT_TRUE(sim.offsets.has_value());
  EXPECT_NEAR((*sim.offsets)[0], 0.001, 1e-9);
  EXPECT_NEAR((*sim.offsets)[3], 0.004, 1e-9);
  EXPECT_NEAR(sim.voxelSize, 0.005, 1e-9);
  EXPECT_EQ(sim.integrator, "euler");
  EXPECT_EQ(sim.collisionEvery, 2);
  EXPECT_EQ(sim.bendEvery, 4);
  EXPECT_EQ(sim.maxRefinement, 4);
  EXPECT_NEAR(sim.strainLimit, 0.25, 1e-7);
  EXPECT_NEAR(sim.rescueStrainLimit, 0.75, 1e-7);
  EXPECT_NEAR(sim.implicitTolerance, 0.0002, 1e-10);
  EXPECT_EQ(sim.keepApart, (std::vector<std::string>{"LeftForeArm", "RightForeArm"}));
  EXPECT_NEAR(sim.unitScale, 0.01, 1e-9);

  ASSERT_EQ(s.materials.size(), 1u);
  const ClothMaterial& m = s.materials[0];
  EXPECT_EQ(m.name, "silk");
  EXPECT_NEAR(m.density, 1300, 1e-3);
  EXPECT_NEAR(m.thickness, 0.0002, 1e-9);
  EXPECT_NEAR(m.youngsModulus, 2e6, 1e-1);
  EXPECT_NEAR(m.poissonRatio, 0.25, 1e-7);
  EXPECT_NEAR(m.bendingStiffness, 1e-6, 1e-12);
  EXPECT_NEAR(m.bendingStiffnessOrDerived(), 1e-6, 1e-12);
  EXPECT_NEAR(m.damping, 0.1, 1e-7);
  EXPECT_NEAR(m.staticFriction, 0.4, 1e-7);
  EXPECT_NEAR(m.dynamicFriction, 0.2, 1e-7);
  EXPECT_NEAR(m.compressionScale, 0.5, 1e-7);
  EXPECT_NEAR(m.arealDensity(), 0.26, 1e-6);

  ASSERT_EQ(s.garments.size(), 1u);
  const Garment& g = s.garments[0];
  EXPECT_EQ(g.name, "scarf");
  EXPECT_EQ(g.material, 0);
  EXPECT_EQ(g.avatar, 0);
  EXPECT_EQ(g.collidesWith, std::vector<std::string>{"hips"});
  EXPECT_EQ(g.faceSamplesWith, std::vector<std::string>{"hips"});
  EXPECT_EQ(g.stitches, (std::vector<std::array<std::uint32_t, 2>>{{0, 2}, {1, 0}}));
  EXPECT_NEAR(g.maskTolerance, 0.002, 1e-9);
  EXPECT_NEAR(g.bindThreshold, 0.03, 1e-9);
  EXPECT_NEAR(g.selfCollision, 0.004, 1e-9);  // metres, as maskTolerance: not scaled
  ASSERT_TRUE(g.offsets.has_value());
  EXPECT_NEAR((*g.offsets)[3], 0.012, 1e-9);
  EXPECT_EQ(g.maskVertices, (std::vector<std::uint32_t>{0, 1, 2}));
  EXPECT_NEAR(g.mesh.positions[1].x(), 0.01, 1e-9);  // 1 file unit at unitScale 0.01

  ASSERT_EQ(s.externalAvatars.size(), 1u);
  const ExternalAvatar& guest = s.externalAvatars[0];
  EXPECT_EQ(guest.name, "guest");
  EXPECT_EQ(guest.urls, std::vector<std::string>{"guest.glb"});
  EXPECT_EQ(guest.jointMap, std::vector<std::string>{"map.json"});
  EXPECT_NEAR(guest.placement.translation.x(), 1.0, 1e-6);  // 100 file units
  EXPECT_NEAR(guest.scale, 0.02, 1e-9);
  ASSERT_EQ(s.avatars.size(), 1u);
  EXPECT_NEAR(s.avatars[0].segments.at(0).mesh.bounds().size().x(), 0.02, 1e-7);  // a 2-unit Box
}

TEST(VrmlScene, EveryFieldDefaults) {
  const Scene s =
      fromText("#VRML V2.0 utf8\nSimulation { }\nClothSet { cloth " + kTriangle + " material ClothMaterial { } }\n");
  const SimulationSettings defaults;
  EXPECT_TRUE(s.simulation.gravity.isApprox(defaults.gravity, 1e-6));
  EXPECT_EQ(s.simulation.frameRate, defaults.frameRate);
  EXPECT_EQ(s.simulation.stepsPerFrame, defaults.stepsPerFrame);
  EXPECT_NEAR(s.simulation.airViscosity, defaults.airViscosity, 1e-7);
  EXPECT_EQ(s.simulation.wind, defaults.wind);
  EXPECT_FALSE(s.simulation.offsets.has_value());  // each garment's then follow the voxel size
  EXPECT_NEAR(s.simulation.voxelSize, defaults.voxelSize, 1e-9);
  EXPECT_EQ(s.simulation.integrator, defaults.integrator);
  EXPECT_EQ(s.simulation.collisionEvery, defaults.collisionEvery);
  EXPECT_EQ(s.simulation.bendEvery, defaults.bendEvery);
  EXPECT_EQ(s.simulation.maxRefinement, defaults.maxRefinement);
  EXPECT_EQ(s.simulation.strainLimit, defaults.strainLimit);
  EXPECT_NEAR(s.simulation.rescueStrainLimit, defaults.rescueStrainLimit, 1e-7);
  EXPECT_NEAR(s.simulation.implicitTolerance, defaults.implicitTolerance, 1e-10);
  EXPECT_TRUE(s.simulation.keepApart.empty());
  EXPECT_EQ(s.simulation.unitScale, 1.0);
  const ClothMaterial md;
  ASSERT_EQ(s.materials.size(), 1u);
  const ClothMaterial& m = s.materials[0];
  EXPECT_NEAR(m.density, md.density, 1e-6);
  EXPECT_NEAR(m.thickness, md.thickness, 1e-9);
  EXPECT_NEAR(m.youngsModulus, md.youngsModulus, 1e-3);
  EXPECT_NEAR(m.poissonRatio, md.poissonRatio, 1e-7);
  EXPECT_LT(m.bendingStiffness, 0.0);
  EXPECT_NEAR(m.bendingStiffnessOrDerived(), 5e5 * 0.0005 * 0.0005 * 0.0005 / (12 * (1 - 0.09)), 1e-12);
  EXPECT_NEAR(m.damping, md.damping, 1e-7);
  EXPECT_NEAR(m.staticFriction, md.staticFriction, 1e-7);
  EXPECT_NEAR(m.dynamicFriction, md.dynamicFriction, 1e-7);
  EXPECT_NEAR(m.compressionScale, md.compressionScale, 1e-7);
  ASSERT_EQ(s.garments.size(), 1u);
  const Garment gd;
  EXPECT_NEAR(s.garments[0].maskTolerance, gd.maskTolerance, 1e-9);
  EXPECT_NEAR(s.garments[0].bindThreshold, gd.bindThreshold, 1e-9);
  EXPECT_TRUE(s.garments[0].maskVertices.empty());
  EXPECT_TRUE(s.garments[0].collidesWith.empty());
  EXPECT_TRUE(s.garments[0].stitches.empty());
  EXPECT_EQ(s.garments[0].selfCollision, 0.0);  // layers pass through one another, as in the paper
  EXPECT_FALSE(s.garments[0].offsets.has_value());  // the Simulation node's
  EXPECT_EQ(s.garments[0].avatar, -1);
  // No Simulation node at all: the same defaults, flagged.
  EXPECT_FALSE(fromText("#VRML V2.0 utf8\nGroup { }\n").hasSimulationNode);
}

TEST(VrmlScene, DefUseSharesOneMaterialBetweenTwoGarments) {
  const Scene s = fromText(
      "#VRML V2.0 utf8\nDEF Denim ClothMaterial { density 600 }\n"
      "DEF A ClothSet { material USE Denim cloth " +
      kTriangle +
      " }\n"
      "DEF B ClothSet { material USE Denim cloth " +
      kTriangle +
      " }\n"
      "DEF C ClothSet { cloth " +
      kTriangle + " }\n");
  ASSERT_EQ(s.garments.size(), 3u);
  ASSERT_EQ(s.materials.size(), 2u);  // Denim once, and the default for C
  EXPECT_EQ(s.garments[0].material, 0);
  EXPECT_EQ(s.garments[1].material, 0);
  EXPECT_EQ(s.garments[2].material, 1);
  EXPECT_EQ(s.materials[0].name, "Denim");
  EXPECT_EQ(s.materials[1].name, "default");
}

TEST(VrmlScene, FileDeclaredProtosLoadAndKeepLines) {
  const std::string protos =
      "#VRML V2.0 utf8\n"
      "PROTO ClothMaterial [ exposedField SFFloat density 100 exposedField SFFloat thickness 0.001 ] { Group { } }\n"
      "PROTO ClothSet [ exposedField MFNode cloth [ ] exposedField SFNode material NULL ] { Group { children IS cloth "
      "} }\n";
  const Scene s = fromText(protos + "DEF Wool ClothMaterial { density 250 }\nClothSet { material USE Wool cloth " +
                           kTriangle + " }\n");
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_NEAR(s.materials[0].density, 250, 1e-6);
  EXPECT_NEAR(s.materials[0].thickness, 0.001, 1e-9);                              // the file's own default
  EXPECT_NEAR(s.materials[0].youngsModulus, ClothMaterial{}.youngsModulus, 1e-6);  // a field the file's PROTO lacks
  // Errors still point at the line of the value.
  const std::string message = errorOf([&] {
    (void)fromText(protos +
                   "ClothMaterial { density 10 }\nDEF Bad ClothMaterial {\n  thickness -1\n}\n"
                   "ClothSet { material USE Bad cloth " +
                   kTriangle + " }\n");
  });
  EXPECT_EQ(message.rfind("scene.wrl:6: ClothMaterial Bad: thickness -1 m is negative", 0), 0u) << message;
}

TEST(VrmlScene, GarmentsGetTheirWorldTransform) {
  const Scene s = fromText(
      "#VRML V2.0 utf8\nTransform { translation 0 2 0 rotation 0 0 1 1.5707963267948966 scale 2 2 2 children [\n"
      "  ClothSet { cloth Shape { geometry " +
      kTriangle + " } }\n] }\n");
  ASSERT_EQ(s.garments.size(), 1u);
  const auto& p = s.garments[0].mesh.positions;
  EXPECT_NEAR((p[0] - Vec3(0, 2, 0)).norm(), 0.0, 1e-6);
  EXPECT_NEAR((p[1] - Vec3(0, 4, 0)).norm(), 0.0, 1e-6);  // x axis turned onto y, doubled
  EXPECT_NEAR((p[2] - Vec3(-2, 2, 0)).norm(), 0.0, 1e-6);
}

TEST(VrmlScene, WorldInfoUnitScale) {
  const Scene s =
      fromText("#VRML V2.0 utf8\nWorldInfo { info [ \"unitScale 0.001\" ] }\nClothSet { cloth " + kTriangle + " }\n");
  EXPECT_NEAR(s.simulation.unitScale, 0.001, 1e-12);
  EXPECT_NEAR(s.garments.at(0).mesh.positions[1].x(), 0.001, 1e-12);
}

TEST(VrmlScene, InlinedHumanoidBecomesAnAvatar) {
  const std::string dir = tempDir();
  std::ofstream(dir + "/body.wrl")
      << "#VRML V2.0 utf8\nHumanoid { name \"inlined\" humanoidBody Joint { name \"root\" children "
         "Segment { name \"trunk\" children Shape { geometry Sphere { } } } } }\n";
  std::ofstream(dir + "/world.wrl")
      << "#VRML V2.0 utf8\nTransform { translation 0 1 0 children Inline { url \"body.wrl\" } }\n";
  const Scene s = loadScene(dir + "/world.wrl");
  ASSERT_EQ(s.avatars.size(), 1u);
  EXPECT_EQ(s.avatars[0].name, "inlined");
  EXPECT_NEAR(s.avatars[0].joints.at(0).restCenter.y(), 1.0, 1e-9);
  EXPECT_GT(s.avatars[0].segments.at(0).mesh.triangleCount(), 10u);
}

TEST(VrmlScene, ExampleSceneMatchesTheWaistband) {
  const Scene s = loadScene(std::string(DRAPE_SOURCE_DIR) + "/examples/dressed_avatar/scene.wrl");
  ASSERT_EQ(s.garments.size(), 1u);
  const Garment& g = s.garments[0];
  EXPECT_EQ(g.name, "skirt");
  EXPECT_EQ(g.mesh.vertexCount(), 168u);
  ASSERT_EQ(g.maskVertices.size(), 24u);
  for (std::uint32_t v : g.maskVertices) EXPECT_LT(v, 24u);  // the top ring
  EXPECT_EQ(g.avatar, 0);
  EXPECT_EQ(s.avatars[0].segments.size(), 4u);
}

TEST(VrmlScene, DomainErrorsFromTheBadCorpus) {
  const std::string dir = std::string(DRAPE_TEST_DATA_DIR) + "/bad/";
  const auto at = [&](const std::string& file, int line, const std::string& text) {
    const std::string message = errorOf([&] { (void)loadScene(dir + file); });
    EXPECT_EQ(message.rfind(dir + file + ":" + std::to_string(line) + ": ", 0), 0u) << message;
    EXPECT_NE(message.find(text), std::string::npos) << message;
  };
  at("clothset_without_cloth.wrl", 2, "ClothSet empty has no cloth");
  at("negative_thickness.wrl", 4, "thickness -0.001 m is negative");
  at("negative_density.wrl", 3, "density -5 kg/m^3 is negative");
  at("poisson_half.wrl", 6, "poissonRatio 0.5 is outside [0, 0.5)");
  at("mask_no_match.wrl", 5, "matches no cloth vertex within maskTolerance 0.01 m");
  at("simulation_zero_steps.wrl", 4, "stepsPerFrame 0 must be at least 1");
}

TEST(VrmlScene, GarmentsWornOverGarments) {
  const std::string body = "#VRML V2.0 utf8\nDEF H Humanoid { humanoidBody Joint { children Segment { name \"hips\" } } }\n"
                           "DEF G Humanoid { humanoidBody Joint { children Segment { name \"hips\" } } }\n";
  const Scene s = fromText(body + "DEF Shirt ClothSet { avatar USE H cloth " + kTriangle +
                           " }\nDEF Vest ClothSet { avatar USE H over [ \"Shirt\" ] cloth " + kTriangle +
                           " }\nDEF Coat ClothSet { avatar USE H over [ \"Vest\", \"Shirt\" ] overGap 0.006 cloth " +
                           kTriangle + " }\n");
  ASSERT_EQ(s.garments.size(), 3u);
  EXPECT_TRUE(s.garments[0].over.empty());
  EXPECT_EQ(s.garments[1].over, std::vector<std::string>{"Shirt"});
  EXPECT_NEAR(s.garments[1].overGap, 0.004, 1e-9);  // the default (an SFFloat)
  EXPECT_EQ(s.garments[2].over, (std::vector<std::string>{"Vest", "Shirt"}));
  EXPECT_NEAR(s.garments[2].overGap, 0.006, 1e-9);

  const auto expectError = [&](const std::string& garments, const std::string& text) {
    const std::string message = errorOf([&] { (void)fromText(body + garments); });
    EXPECT_NE(message.find(text), std::string::npos) << message;
  };
  expectError("DEF Shirt ClothSet { avatar USE H cloth " + kTriangle + " }\nDEF Vest ClothSet { avatar USE H\n over [ "
              "\"Shrit\" ] cloth " + kTriangle + " }\n",
              "scene.wrl:6: ClothSet Vest: over names 'Shrit', which is no garment of the scene (it has: Shirt, Vest)");
  expectError("DEF Vest ClothSet { avatar USE H over [ \"Vest\" ] cloth " + kTriangle + " }\n",
              "ClothSet Vest: over names itself");
  expectError("DEF Shirt ClothSet { avatar USE G cloth " + kTriangle + " }\nDEF Vest ClothSet { avatar USE H over [ "
              "\"Shirt\" ] cloth " + kTriangle + " }\n",
              "ClothSet Vest: over names 'Shirt', which another character wears (or none)");
  expectError("DEF A ClothSet { avatar USE H over [ \"C\" ] cloth " + kTriangle +
                  " }\nDEF B ClothSet { avatar USE H over [ \"A\" ] cloth " + kTriangle +
                  " }\nDEF C ClothSet { avatar USE H over [ \"B\" ] cloth " + kTriangle + " }\n",
              "scene.wrl:4: ClothSet A: worn over itself through A over C over B over A");
  expectError("DEF Vest ClothSet { avatar USE H\n overGap 0 cloth " + kTriangle + " }\n",
              "scene.wrl:5: ClothSet Vest: overGap 0 m: expected a gap above the garments it is worn over, more than 0");
}

TEST(VrmlScene, MoreDomainErrors) {
  EXPECT_NE(errorOf([&] {
              (void)fromText(
                  "#VRML V2.0 utf8\nDEF H Humanoid { humanoidBody Joint { children Segment { name \"hips\" } } }\n"
                  "ClothSet { avatar USE H collidesWith [ \"elbow\" ] cloth " +
                  kTriangle + " }\n");
            }).find("collidesWith names 'elbow', which avatar H has no segment called"),
            std::string::npos);
  EXPECT_NE(errorOf([&] {
              (void)fromText("#VRML V2.0 utf8\nClothSet {\n  selfCollision -0.002 cloth " + kTriangle + " }\n");
            }).find("scene.wrl:3: ClothSet garment 1: selfCollision -0.002 m: expected a thickness, 0 (none) or more"),
            std::string::npos);
  EXPECT_NE(errorOf([&] {
              (void)fromText("#VRML V2.0 utf8\nClothSet {\n  offsets [ 0.002 0.004 0.006 ] cloth " + kTriangle + " }\n");
            }).find("scene.wrl:3: ClothSet garment 1: offsets needs 4 values (T0 T1 T2 T3 in m), found 3"),
            std::string::npos);
  EXPECT_NE(errorOf([&] {
              (void)fromText("#VRML V2.0 utf8\nClothSet {\n  offsets [ 0.002 0.004 0.003 0.008 ] cloth " + kTriangle +
                             " }\n");
            }).find("ClothSet garment 1: offsets must not decrease (T2 = 0.003 m < T1 = 0.004 m)"),
            std::string::npos);
  // Face samples: with parts the garment collides with, on its avatar.
  EXPECT_NE(errorOf([&] {
              (void)fromText(
                  "#VRML V2.0 utf8\nDEF H Humanoid { humanoidBody Joint { children [ Segment { name \"hips\" } "
                  "Segment { name \"thigh\" } ] } }\n"
                  "ClothSet { avatar USE H collidesWith [ \"hips\" ]\n  faceSamplesWith [ \"thigh\" ] cloth " +
                  kTriangle + " }\n");
            }).find("scene.wrl:4: ClothSet garment 1: faceSamplesWith names 'thigh', which is not in its collidesWith"),
            std::string::npos);
  EXPECT_NE(errorOf([&] {
              (void)fromText(
                  "#VRML V2.0 utf8\nDEF H Humanoid { humanoidBody Joint { children Segment { name \"hips\" } } }\n"
                  "ClothSet { avatar USE H faceSamplesWith [ \"knee\" ] cloth " +
                  kTriangle + " }\n");
            }).find("faceSamplesWith names 'knee', which avatar H has no segment called"),
            std::string::npos);
  // Stitches: pairs of distinct cloth vertices.
  const auto stitched = [&](const std::string& pairs) {
    return errorOf([&] { (void)fromText("#VRML V2.0 utf8\nClothSet { cloth " + kTriangle + "\n  stitches [ " + pairs + " ] }\n"); });
  };
  EXPECT_NE(stitched("0 1, 2").find("scene.wrl:3: ClothSet garment 1: stitches holds 3 vertex indices; expected pairs"),
            std::string::npos);
  EXPECT_NE(stitched("0 1, 2 3").find("scene.wrl:3: ClothSet garment 1: stitch 2 names vertex 3; expected a cloth "
                                      "vertex, 0 to 2"),
            std::string::npos);
  EXPECT_NE(stitched("-1 1").find("stitch 1 names vertex -1; expected a cloth vertex"), std::string::npos);
  EXPECT_NE(stitched("1 1").find("scene.wrl:3: ClothSet garment 1: stitch 1 joins vertex 1 to itself"),
            std::string::npos);
  EXPECT_NE(errorOf([&] {
              (void)fromText("#VRML V2.0 utf8\nClothSet { cloth Shape { geometry Box { } } }\n");
            }).find("cloth must be an IndexedFaceSet or a Shape holding one, not Box"),
            std::string::npos);
  EXPECT_NE(errorOf([&] {
              (void)fromText("#VRML V2.0 utf8\nClothSet { cloth " + kTriangle +
                             " material ClothMaterial { poissonRatio -0.1 } }\n");
            }).find("scene.wrl:2: ClothMaterial: poissonRatio -0.1 is outside [0, 0.5)"),
            std::string::npos);
  // The solver's last resorts, each named with the line of its value.
  EXPECT_NE(errorOf([&] { (void)fromText("#VRML V2.0 utf8\nSimulation {\n  maxRefinement 0 }\n"); })
                .find("scene.wrl:3: Simulation: maxRefinement 0 must be in [1, 64]"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { (void)fromText("#VRML V2.0 utf8\nSimulation { strainLimit -0.5 }\n"); })
                .find("scene.wrl:2: Simulation: strainLimit -0.5 must be a stretch beyond the rest length in [0, 10]"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { (void)fromText("#VRML V2.0 utf8\nSimulation { rescueStrainLimit 11 }\n"); })
                .find("rescueStrainLimit 11 must be a stretch beyond the rest length in [0, 10]"),
            std::string::npos);
  for (const char* tolerance : {"0", "1", "-0.1"})
    EXPECT_NE(errorOf([&] {
                (void)fromText(std::string("#VRML V2.0 utf8\nSimulation {\n  implicitTolerance ") + tolerance + " }\n");
              }).find(std::string("scene.wrl:3: Simulation: implicitTolerance ") + tolerance +
                      " must be a fraction in (0, 1)"),
              std::string::npos)
        << tolerance;
}

// The CLI: `drape inspect` on a scene and on a bad file (exit code 2, one line).
std::pair<int, std::string> run(const std::string& args) {
  std::string output;
  FILE* p = ::popen((std::string(DRAPE_EXE) + " " + args + " 2>&1").c_str(), "r");
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, p) != nullptr) output += buffer;
  const int status = ::pclose(p);
  return {WEXITSTATUS(status), output};
}

TEST(VrmlScene, DrapeInspectSummarisesAScene) {
  const auto [code, out] = run("inspect " + std::string(DRAPE_SOURCE_DIR) + "/examples/dressed_avatar/scene.wrl");
  EXPECT_EQ(code, 0) << out;
  EXPECT_NE(out.find("body (H-Anim): 4 joints, 4 segments"), std::string::npos) << out;
  EXPECT_NE(out.find("skirt: 168 vertices, 288 triangles"), std::string::npos) << out;
  EXPECT_NE(out.find("2 boundary loops"), std::string::npos) << out;
  EXPECT_NE(out.find("constraint mask 24 vertices"), std::string::npos) << out;
  EXPECT_NE(out.find("Cotton: density 300 kg/m^3"), std::string::npos) << out;
  EXPECT_NE(out.find("30 frames/s x 70 steps/frame"), std::string::npos) << out;
  EXPECT_NE(out.find("an unstable frame is computed again with up to 8 times the steps, then edges are held to 1.5 "
                     "times their rest length"),
            std::string::npos)
      << out;
}

TEST(VrmlScene, DrapeInspectRejectsABadFileWithExitCode2) {
  const std::string file = std::string(DRAPE_TEST_DATA_DIR) + "/bad/coin_use_in_own_def.wrl";
  const auto [code, out] = run("inspect " + file);
  EXPECT_EQ(code, 2) << out;
  EXPECT_NE(out.find(file + ":2:49: USE T inside its own DEF T"), std::string::npos) << out;
}

}  // namespace
}  // namespace drape::scene
