// The glTF exporter: rigid fits, what the .glb holds when read back (morph targets that
// reproduce every frame, TRS keys that reproduce a rigid part), and the Khronos validator.

#include <gtest/gtest.h>

#include <tiny_gltf.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <random>

#include "drape/core/error.hpp"
#include "drape/formats/gltf_writer.hpp"
#include "drape/formats/pc2.hpp"
#include "drape/testing/glb_read.hpp"
#include "test_run_fixture.hpp"

namespace drape::formats {
namespace {

using drape::testing::accessorData;
using drape::testing::loadGlb;

TEST(FitRigid, RecoversRandomMotionsAndRejectsDeformation) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<Vec3> from(20);
    for (Vec3& p : from) p = Vec3(u(rng), u(rng), u(rng));
    RigidTransform x;
    x.rotation = Quat(Eigen::AngleAxisd(3.0 * u(rng), Vec3(u(rng), u(rng), u(rng)).normalized()));
    x.translation = Vec3(u(rng), u(rng), u(rng));
    std::vector<Vec3> to;
    for (const Vec3& p : from) to.push_back(x.apply(p));
    const RigidFit fit = fitRigid(from, to);
    ASSERT_LT(fit.maxError_m, 1e-9);
    ASSERT_LT(fit.transform.rotation.angularDistance(x.rotation), 1e-9);
    to[3] += Vec3(0.01, 0.0, 0.0);  // one point off by 1 cm: not rigid any more
    ASSERT_GT(fitRigid(from, to).maxError_m, 1e-3);
  }
}

TEST(GltfWriter, RunExportReproducesEveryFrame) {
  const std::string dir = testrun::writeTestRun(testrun::freshDir("gltf"), 20);
  const std::string glb = dir + "/result.glb";
  const RunExportSummary s = exportRunToGlb(dir, glb);
  EXPECT_EQ(s.frames, 20);
  EXPECT_EQ(s.rigid, 1u) << "the torso moves rigidly";
  EXPECT_EQ(s.deforming, 1u) << "the flag deforms";

  const tinygltf::Model model = loadGlb(glb);
  ASSERT_EQ(model.nodes.size(), 2u);
  ASSERT_EQ(model.animations.size(), 1u);
  EXPECT_EQ(model.animations[0].channels.size(), 3u) << "weights for the flag; translation and rotation for the torso";
  const Pc2Cache flag = readPc2(dir + "/flag.pc2");
  const Pc2Cache torso = readPc2(dir + "/torso.pc2");

  // The flag: base + target (f - 1) is frame f, for every frame.
  const tinygltf::Node& flagNode = model.nodes[0];
  EXPECT_EQ(flagNode.name, "flag");
  const tinygltf::Primitive& prim = model.meshes[static_cast<std::size_t>(flagNode.mesh)].primitives[0];
  ASSERT_EQ(prim.targets.size(), 19u);
  const std::vector<float> base = accessorData<float>(model, prim.attributes.at("POSITION"));
  for (std::size_t f = 0; f < 20; ++f) {
    std::vector<float> p = base;
    if (f > 0) {
      const std::vector<float> d = accessorData<float>(model, prim.targets[f - 1].at("POSITION"));
      for (std::size_t i = 0; i < p.size(); ++i) p[i] += d[i];
    }
    for (std::size_t v = 0; v < flag.pointCount; ++v)
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(p[3 * v + static_cast<std::size_t>(k)], flag.frames[f][v][k], 1e-5);
  }
  // The weights at key f switch target f - 1 on, all others off.
  const tinygltf::AnimationSampler& ws = model.animations[0].samplers[0];
  const std::vector<float> times = accessorData<float>(model, ws.input);
  const std::vector<float> weights = accessorData<float>(model, ws.output);
  ASSERT_EQ(times.size(), 20u);
  EXPECT_NEAR(times[19], 19.0 / testrun::kRate, 1e-6);
  ASSERT_EQ(weights.size(), 20u * 19u);
  for (std::size_t f = 0; f < 20; ++f)
    for (std::size_t t = 0; t < 19; ++t) ASSERT_EQ(weights[f * 19 + t], f > 0 && t == f - 1 ? 1.0f : 0.0f);

  // The torso: node TRS at key f applied to its rest mesh gives frame f.
  const tinygltf::Node& torsoNode = model.nodes[1];
  const std::vector<float> rest = accessorData<float>(
      model, model.meshes[static_cast<std::size_t>(torsoNode.mesh)].primitives[0].attributes.at("POSITION"));
  const std::vector<float> tr = accessorData<float>(model, model.animations[0].samplers[1].output);
  const std::vector<float> rot = accessorData<float>(model, model.animations[0].samplers[2].output);
  for (std::size_t f = 0; f < 20; ++f) {
    const Quat q(rot[4 * f + 3], rot[4 * f], rot[4 * f + 1], rot[4 * f + 2]);
    const Vec3 t(tr[3 * f], tr[3 * f + 1], tr[3 * f + 2]);
    for (std::size_t v = 0; v < torso.pointCount; ++v) {
      const Vec3 p = q * Vec3(rest[3 * v], rest[3 * v + 1], rest[3 * v + 2]) + t;
      ASSERT_LT((p - torso.frames[f][v]).norm(), 1e-4) << "frame " << f << " vertex " << v;
    }
  }
}

TEST(GltfWriter, ARunWithoutASkinnedBodyKeepsItsPartsWhenTheSkinIsAskedFor) {
  const std::string dir = testrun::writeTestRun(testrun::freshDir("gltf_no_skin"), 5);
  const RunExportSummary s = exportRunToGlb(dir, dir + "/skin.glb", ExportedBody::Skin);
  EXPECT_EQ(s.rigid, 1u) << "the torso";
  EXPECT_EQ(s.deforming, 1u) << "the flag";
  EXPECT_EQ(s.skins, 0u);
}

TEST(GltfWriter, KhronosValidatorReportsNoErrors) {
  const std::string validator = std::string(DRAPE_SOURCE_DIR) + "/tools/gltf-validator/validate.js";
  if (std::system("node --version >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "node is not installed (scripts/install-deps installs it)";
  if (!std::filesystem::exists(std::string(DRAPE_SOURCE_DIR) + "/tools/gltf-validator/node_modules/gltf-validator")) {
    GTEST_SKIP() << "the gltf-validator npm package is not installed (scripts/install-deps runs npm ci)";
  }
  const std::string dir = testrun::writeTestRun(testrun::freshDir("gltf_validate"), 12);
  const std::string glb = dir + "/result.glb";
  (void)exportRunToGlb(dir, glb);
  // A second file with a garment only, one frame: no animation at all.
  GltfAnimation still;
  still.deforming.push_back(
      {"square", {{0, 1, 2}, {0, 2, 3}}, {{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)}}});
  writeGlb(dir + "/still.glb", still);
  for (const std::string& file : {glb, dir + "/still.glb"}) {
    const std::string command = "node " + validator + " " + file + " 2>&1";
    std::FILE* pipe = ::popen(command.c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    std::string output;
    std::array<char, 4096> buffer{};
    while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) output += buffer.data();
    const int status = ::pclose(pipe);
    EXPECT_NE(output.find("\"errors\":0"), std::string::npos) << output;
    EXPECT_EQ(status, 0) << output;
  }
}

TEST(GltfWriter, BadInputIsRefused) {
  const std::string dir = testrun::freshDir("gltf_bad");
  EXPECT_THROW(writeGlb(dir + "/x.glb", GltfAnimation{}), Error);
  GltfAnimation bad;
  bad.deforming.push_back({"tri", {{0, 1, 5}}, {{Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY()}}});
  EXPECT_THROW(writeGlb(dir + "/x.glb", bad), Error);
  bad.deforming[0].triangles = {{0, 1, 2}};
  bad.deforming[0].frames.push_back({Vec3::Zero()});  // frame 1 has the wrong size
  EXPECT_THROW(writeGlb(dir + "/x.glb", bad), Error);
  EXPECT_THROW((void)exportRunToGlb(dir, dir + "/x.glb"), Error) << "not a run directory";
}

}  // namespace
}  // namespace drape::formats
