#include "run_writer.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drape/core/error.hpp"
#include "drape/core/log.hpp"
#include "drape/formats/gltf_writer.hpp"
#include "drape/formats/obj.hpp"
#include "drape/formats/pc2.hpp"
#include "drape/formats/run_manifest.hpp"
#include "drape/formats/state_cache.hpp"
#include "drape/formats/vrml_write.hpp"
#include "drape/motion/skinning.hpp"
#include "drape/render/outputs.hpp"
#include "drape/sim/body_skin.hpp"

namespace drape::cli {
namespace {

namespace fs = std::filesystem;

std::string fileSafe(const std::string& name) {
  std::string out;
  for (char c : name) out += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') ? c : '_';
  return out.empty() ? std::string("part") : out;
}

/// One garment's files: a cache of positions and one of vertex states per frame, and every
/// frame kept for result.wrl.
struct GarmentFiles {
  std::string name;
  std::string meshName;  ///< the mesh's own name, which its OBJ frames' comments give
  std::string fileStem;  ///< "garment" alone, "garment-<name>" when there are several
  const std::vector<mesh::Triangle>* triangles = nullptr;
  std::unique_ptr<formats::Pc2Writer> cache;
  std::unique_ptr<formats::StateCacheWriter> states;
  std::vector<std::vector<Vec3>> frames;
};

/// One avatar body part written as a deforming mesh: rest topology and a cache of world
/// positions per frame (role "segment" in the manifest).
struct SegmentFiles {
  std::string name;
  int joint = -1;
  std::string fileStem;
  const mesh::TriMesh* mesh = nullptr;  ///< in the joint's frame
  std::unique_ptr<formats::Pc2Writer> cache;
};

/// One character's files: its parts, its skinned body (when the avatar has one), its drawn
/// meshes (when it has some), and its joints per frame for result.wrl.
struct CharacterFiles {
  const CharacterSetup* setup = nullptr;
  std::vector<SegmentFiles> segments;
  std::vector<std::vector<RigidTransform>> jointFrames;  ///< per joint, per frame
  std::unique_ptr<sim::BodySkin> skin;
  std::unique_ptr<formats::Pc2Writer> skinCache;
  std::vector<Vec3> skinPositions;
  std::unique_ptr<formats::Pc2Writer> drawnCache;
  std::vector<Vec3> drawnPositions;
};

}  // namespace

void createOutDir(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(fs::path(dir) / "frames", ec);
  if (ec) throw Error(fmt::format("--out {}: cannot create the directory ({})", dir, ec.message()));
}

struct RunWriter::Impl {
  const RunSetup& setup;
  fs::path out;
  formats::RunManifest manifest;
  std::vector<GarmentFiles> garments;
  std::vector<CharacterFiles> characters;
  std::vector<Vec3> positions;
  std::vector<sim::GarmentSurface> surfaces;
  bool closed = false;

  Impl(const RunSetup& s, const std::vector<CharacterAtStart>& atStart) : setup(s), out(s.outDir) {
    createOutDir(setup.outDir);
    manifest.frameRate = setup.settings.frameRate_hz;
    manifest.startFrame = static_cast<long>(frameTimeCode(setup, 0).frame);
    for (const GarmentSetup& g : setup.garments) {
      GarmentFiles f;
      f.name = g.name;
      f.meshName = g.mesh.name;
      f.fileStem = setup.garments.size() == 1 ? "garment" : "garment-" + fileSafe(g.name);
      f.triangles = &g.mesh.triangles;
      formats::writeObj((out / (f.fileStem + ".obj")).string(), g.mesh.positions, g.mesh.triangles,
                        "drape run: rest topology of " + g.name + " (m)");
      f.cache = std::make_unique<formats::Pc2Writer>((out / (f.fileStem + ".pc2")).string(), g.mesh.vertexCount(), 0.0,
                                                     1.0);
      f.states = std::make_unique<formats::StateCacheWriter>((out / (f.fileStem + ".states")).string(),
                                                             g.mesh.vertexCount());
      manifest.meshes.push_back({g.name, "garment", f.fileStem + ".obj", f.fileStem + ".pc2", f.fileStem + ".states",
                                 wearer(garments.size()), g.colour});
      garments.push_back(std::move(f));
    }
    if (atStart.size() != setup.characters.size())
      throw Error(fmt::format("run writer: {} characters at the start for {}", atStart.size(), setup.characters.size()),
                  ExitCode::Internal);
    for (std::size_t c = 0; c < setup.characters.size(); ++c) characters.push_back(characterFiles(c, atStart[c]));
  }

  /// Who wears garment g, in a run of several characters; "" otherwise.
  [[nodiscard]] std::string wearer(std::size_t g) const {
    if (setup.characters.size() < 2) return "";
    for (const CharacterSetup& c : setup.characters)
      if (std::find(c.garments.begin(), c.garments.end(), g) != c.garments.end()) return c.name;
    return "";
  }

  /// Character c's rest files: its parts and its skinned body. Alone, its files are
  /// segments/PART and body; among several, segments/CHARACTER/PART and body-CHARACTER.
  CharacterFiles characterFiles(std::size_t c, const CharacterAtStart& start) {
    CharacterFiles files;
    files.setup = &setup.characters[c];
    const scene::Avatar& avatar = *files.setup->avatar;
    const bool several = setup.characters.size() > 1;
    const std::string who = several ? files.setup->name : "";
    const std::string segmentDir = several ? "segments/" + fileSafe(who) + "/" : "segments/";
    files.jointFrames.resize(avatar.joints.size());
    std::error_code ec;
    fs::create_directories(out / segmentDir, ec);
    if (avatar.skin && start.fields) {
      // The skinned body, which players draw instead of the segments (the collision's own
      // bodies, still written for the overlays and exporters).
      const std::string stem = several ? "body-" + fileSafe(who) : "body";
      files.skin = std::make_unique<sim::BodySkin>(avatar, *start.fields, start.skinAllowance_m);
      files.skin->pose(start.joints, files.skinPositions);
      formats::writeObj((out / (stem + ".obj")).string(), files.skinPositions, avatar.skin->mesh.triangles,
                        several ? "drape run: " + who + "'s skinned body (m)" : "drape run: the avatar's skinned body (m)");
      files.skinCache =
          std::make_unique<formats::Pc2Writer>((out / (stem + ".pc2")).string(), files.skinPositions.size(), 0.0, 1.0);
      manifest.meshes.push_back({"body", "skin", stem + ".obj", stem + ".pc2", "", who, std::nullopt});
    }
    if (avatar.drawnSkin) {
      // Hair, eyes: skinned as they are, neither fitted nor tucked (the cloth never meets them).
      const std::string stem = several ? "drawn-" + fileSafe(who) : "drawn";
      motion::poseSkin(avatar, *avatar.drawnSkin, start.joints, files.drawnPositions);
      formats::writeObj((out / (stem + ".obj")).string(), files.drawnPositions, avatar.drawnSkin->mesh.triangles,
                        fmt::format("drape run: {} drawn meshes ({}) (m)", several ? who + "'s" : "the avatar's",
                                    fmt::join(avatar.drawnMeshesRead, ", ")));
      files.drawnCache =
          std::make_unique<formats::Pc2Writer>((out / (stem + ".pc2")).string(), files.drawnPositions.size(), 0.0, 1.0);
      manifest.meshes.push_back({"drawn", "drawn", stem + ".obj", stem + ".pc2", "", who, std::nullopt});
    }
    for (const scene::Segment& seg : avatar.segments) {
      SegmentFiles sf;
      sf.name = seg.name;
      sf.joint = seg.joint;
      sf.mesh = &seg.mesh;
      sf.fileStem = segmentDir + fileSafe(seg.name);
      std::vector<Vec3> rest;
      for (const Vec3& p : seg.mesh.positions) rest.push_back(start.joints[static_cast<std::size_t>(seg.joint)].apply(p));
      formats::writeObj((out / (sf.fileStem + ".obj")).string(), rest, seg.mesh.triangles,
                        "drape run: body part " + seg.name + (several ? " of " + who : "") + " (m)");
      sf.cache = std::make_unique<formats::Pc2Writer>((out / (sf.fileStem + ".pc2")).string(), rest.size(), 0.0, 1.0);
      manifest.meshes.push_back({seg.name, "segment", sf.fileStem + ".obj", sf.fileStem + ".pc2", "", who, std::nullopt});
      files.segments.push_back(std::move(sf));
    }
    return files;
  }

  /// frames/frame_NNNNN.obj (frames/garment-NAME_NNNNN.obj with several garments).
  void writeObjFrame(const GarmentFiles& f, long frame, const std::vector<Vec3>& p) const {
    const std::string name = garments.size() == 1 ? fmt::format("frame_{:05d}.obj", frame)
                                                  : fmt::format("{}_{:05d}.obj", f.fileStem, frame);
    formats::writeObj((out / "frames" / name).string(), p, *f.triangles,
                      fmt::format("drape run: frame {} of {} (m)", frame, f.meshName));
  }

  void write(const FrameTaken& taken) {
    for (std::size_t g = 0; g < garments.size(); ++g) {
      GarmentFiles& f = garments[g];
      const std::vector<Vec3>& p = taken.positions[g];
      f.cache->writeFrame(p);
      f.frames.push_back(p);
      f.states->writeFrame(taken.states[g]);
      if (taken.frame % setup.objEvery == 0) writeObjFrame(f, taken.frame, p);
    }
    for (std::size_t c = 0; c < characters.size(); ++c) writeCharacter(characters[c], taken.joints[c], taken);
  }

  void writeCharacter(CharacterFiles& files, const std::vector<RigidTransform>& joints, const FrameTaken& taken) {
    for (std::size_t j = 0; j < joints.size(); ++j) files.jointFrames[j].push_back(joints[j]);
    for (SegmentFiles& sf : files.segments) {
      positions.clear();
      const RigidTransform& pose = joints[static_cast<std::size_t>(sf.joint)];
      for (const Vec3& p : sf.mesh->positions) positions.push_back(pose.apply(p));
      sf.cache->writeFrame(positions);
    }
    if (files.skinCache) {
      // Tucked under the garments it wears.
      surfaces.clear();
      for (const std::size_t g : files.setup->garments) surfaces.push_back({taken.positions[g], *garments[g].triangles});
      files.skin->pose(joints, surfaces, files.skinPositions);
      files.skinCache->writeFrame(files.skinPositions);
    }
    if (files.drawnCache) {
      motion::poseSkin(*files.setup->avatar, *files.setup->avatar->drawnSkin, joints, files.drawnPositions);
      files.drawnCache->writeFrame(files.drawnPositions);
    }
  }

  /// result.wrl (any VRML97 browser, and drape's reader) and result.glb (glTF viewers, DCC
  /// tools): the garments and, on a character, the animated avatar.
  void writeResultFiles() const {
    formats::vrml::Animation animation;
    animation.frameRate = setup.settings.frameRate_hz;
    for (std::size_t g = 0; g < garments.size(); ++g)
      animation.garments.push_back({garments[g].name, *garments[g].triangles, garments[g].frames,
                                    setup.garments[g].colour.value_or(Vec3(0.8, 0.25, 0.2))});
    for (const CharacterFiles& files : characters) {
      const scene::Avatar& avatar = *files.setup->avatar;
      // Among several characters, each joint's node named for its character too.
      const std::string prefix = characters.size() > 1 ? fileSafe(files.setup->name) + "_" : "";
      for (std::size_t j = 0; j < avatar.joints.size(); ++j) {
        formats::vrml::JointTrack track;
        track.name = prefix + avatar.joints[j].name;
        for (const SegmentFiles& sf : files.segments)
          if (sf.joint == static_cast<int>(j)) track.segments.push_back(*sf.mesh);
        track.frames = files.jointFrames[j];
        animation.joints.push_back(std::move(track));
      }
    }
    formats::vrml::writeAnimation((out / "result.wrl").string(), animation);
    (void)formats::exportRunToGlb(setup.outDir, (out / "result.glb").string());
    if (setup.preview) {
      const render::PreviewFiles preview = render::renderPreview(setup.outDir);
      spdlog::info("preview: {}{}", preview.contactSheet, preview.video.empty() ? " (no ffmpeg: no video)" : ", " + preview.video);
    }
  }

  void close(long frames) {
    if (closed) return;
    closed = true;
    for (GarmentFiles& f : garments) {
      f.cache->close();
      f.states->close();
      // The last frame as OBJ too, whatever objEvery skips.
      const long last = static_cast<long>(f.frames.size()) - 1;
      if (last > 0 && last % setup.objEvery != 0) writeObjFrame(f, last, f.frames.back());
    }
    for (CharacterFiles& files : characters) {
      for (SegmentFiles& sf : files.segments) sf.cache->close();
      if (files.skinCache) files.skinCache->close();
      if (files.drawnCache) files.drawnCache->close();
    }
    manifest.frames = frames + 1;
    formats::writeRunManifest(setup.outDir, manifest);
    writeResultFiles();
  }
};

RunWriter::RunWriter(const RunSetup& setup, const std::vector<CharacterAtStart>& characters)
    : impl_(std::make_unique<Impl>(setup, characters)) {}

RunWriter::~RunWriter() = default;

void RunWriter::write(const FrameTaken& frame) { impl_->write(frame); }

void RunWriter::close(long frames) { impl_->close(frames); }

void RunWriter::writeStats(const nlohmann::json& stats) const {
  const std::string path = (impl_->out / "stats.json").string();
  std::ofstream file(path);
  file << stats.dump(2) << "\n";
  if (!file) throw Error(fmt::format("{}: write failed", path));
}

}  // namespace drape::cli
