#include "drape/motion/clip_io.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/core/files.hpp"
#include "drape/formats/asf_amc.hpp"
#include "drape/motion/interpolate.hpp"
#include "drape/motion/standing.hpp"

namespace drape::motion {
namespace {

Quat axisRotation(formats::BvhChannel channel, double degrees) {
  const double r = degrees * M_PI / 180.0;
  switch (channel) {
    case formats::BvhChannel::Xrotation: return Quat(Eigen::AngleAxisd(r, Vec3::UnitX()));
    case formats::BvhChannel::Yrotation: return Quat(Eigen::AngleAxisd(r, Vec3::UnitY()));
    case formats::BvhChannel::Zrotation: return Quat(Eigen::AngleAxisd(r, Vec3::UnitZ()));
    default: return Quat::Identity();
  }
}

int positionAxis(formats::BvhChannel channel) {
  switch (channel) {
    case formats::BvhChannel::Xposition: return 0;
    case formats::BvhChannel::Yposition: return 1;
    case formats::BvhChannel::Zposition: return 2;
    default: return -1;
  }
}

// Joint positions (and end sites) of one frame, for the T-pose test.
std::vector<Vec3> framePoints(const Clip& clip, std::size_t f) {
  std::vector<RigidTransform> world(clip.skeleton.size());
  forwardKinematics(clip.skeleton, clip.frameRotations(f), clip.rootTranslations[f], world);
  std::vector<Vec3> points;
  for (std::size_t j = 0; j < world.size(); ++j) {
    points.push_back(world[j].translation);
    if (clip.skeleton.joints[j].endSite) points.push_back(world[j].apply(*clip.skeleton.joints[j].endSite));
  }
  return points;
}

// Arms out: the widest horizontal distance between two points is at least 70% of the
// vertical extent (a T-pose spans about its height; arms down span about a third).
bool looksLikeTPose(const std::vector<Vec3>& points) {
  double minY = 1e300, maxY = -1e300, span = 0.0;
  for (const Vec3& p : points) {
    minY = std::min(minY, p.y());
    maxY = std::max(maxY, p.y());
    for (const Vec3& q : points) span = std::max(span, std::hypot(p.x() - q.x(), p.z() - q.z()));
  }
  return maxY > minY && span > 0.7 * (maxY - minY);
}

/// The least joint speed an unfolding from the rest pose has (restUnfoldFrames), deg/s: a
/// quarter turn in half a second.
constexpr double kUnfoldFloor_deg_s = 180.0;

double largestJointChangeDegrees(const Clip& clip, std::size_t f0, std::size_t f1) {
  const auto a = clip.frameRotations(f0);
  const auto b = clip.frameRotations(f1);
  double largest = 0.0;
  for (std::size_t j = 0; j < a.size(); ++j) largest = std::max(largest, a[j].angularDistance(b[j]));
  return largest * 180.0 / M_PI;
}

void finishClip(Clip& clip, double metresPerUnitValue, const ClipLoadOptions& options, ClipLoadReport* report,
                const UnitsGuess& guess) {
  clip.skeleton.scale(metresPerUnitValue);
  for (Vec3& t : clip.rootTranslations) t *= metresPerUnitValue;
  ClipLoadReport r;
  r.units = guess;
  r.unitsOverridden = options.metresPerUnit.has_value();
  r.sourceRate = clip.rate;
  r.sourceFrames = clip.frameCount();
  // Stood up first: the reference T-pose test, the retargeting and the grounding read +y as up.
  const Standing standing = standUp(clip);
  r.standingAxis = standing.axis;
  r.standingTurn = standing.turn;
  if (options.skipReferenceTPose && firstFrameIsReferenceTPose(clip)) {
    dropLeadingFrames(clip, 1);
    r.referenceTPoseSkipped = true;
  }
  if (options.skipRestUnfold) {
    r.restUnfoldFramesSkipped = restUnfoldFrames(clip);
    dropLeadingFrames(clip, r.restUnfoldFramesSkipped);
  }
  if (!(options.rate >= 0.0) || options.rate > 1e4) throw Error(fmt::format("motion rate {} Hz is out of range", options.rate));
  if (options.rate > 0.0 && std::abs(options.rate - clip.rate) > 1e-9 * clip.rate) clip = resample(clip, options.rate);
  clip.start = TimeCode{0, clip.rate};
  if (report) *report = r;
}

double chooseScale(double extent, const ClipLoadOptions& options, UnitsGuess& guess) {
  guess = guessUnits(extent);
  if (options.metresPerUnit) {
    if (!(*options.metresPerUnit > 0.0) || !std::isfinite(*options.metresPerUnit))
      throw Error(fmt::format("--motion-scale: must be a positive number of metres per unit, not {}", *options.metresPerUnit));
    return *options.metresPerUnit;
  }
  return guess.metresPerUnit;
}

}  // namespace

Quat eulerRotation(const std::string& order, const Vec3& anglesRad);

UnitsGuess guessUnits(double extentInUnits) {
  struct Candidate {
    double metresPerUnit;
    const char* name;
  };
  static constexpr Candidate kCandidates[] = {
      {1.0, "m"}, {0.01, "cm"}, {0.001, "mm"}, {0.0254, "in"}, {kCmuMetresPerUnit, "CMU units (0.0564 m)"}};
  constexpr double kHumanExtent = 1.7;  // m, height or T-pose arm span
  UnitsGuess best{1.0, "m", extentInUnits};
  double bestScore = 1e300;
  if (!(extentInUnits > 0.0)) return best;
  for (const Candidate& c : kCandidates) {
    const double score = std::abs(std::log(extentInUnits * c.metresPerUnit / kHumanExtent));
    if (score < bestScore) {
      bestScore = score;
      best = {c.metresPerUnit, c.name, extentInUnits};
    }
  }
  return best;
}

bool firstFrameIsReferenceTPose(const Clip& clip) {
  if (clip.frameCount() < 3) return false;
  if (!looksLikeTPose(framePoints(clip, 0)) || looksLikeTPose(framePoints(clip, 1))) return false;
  const double jump = largestJointChangeDegrees(clip, 0, 1);
  const double next = largestJointChangeDegrees(clip, 1, 2);
  return jump > 20.0 && jump > 4.0 * next;
}

std::string ClipLoadReport::referenceTPose() const {
  return referenceTPoseSkipped ? "frame 1 is a reference T-pose, not played" : "";
}

std::string ClipLoadReport::stoodUp() const {
  if (standingAxis == "+y") return {};
  return fmt::format("it stands along {}: turned to stand along +y, as drape's scenes do", standingAxis);
}

std::string ClipLoadReport::restUnfoldSkipped() const {
  if (restUnfoldFramesSkipped == 0) return {};
  const std::size_t first = referenceTPoseSkipped ? 2 : 1;
  const std::size_t last = first + restUnfoldFramesSkipped - 1;
  return fmt::format("frames {}-{} unfold from the rest pose (not played; the lead-in blends into frame {})", first,
                     last, last + 1);
}

std::size_t restUnfoldFrames(const Clip& clip) {
  const std::size_t n = clip.frameCount();
  if (n < 3 || !(clip.rate > 0.0)) return 0;
  // Joint speeds between successive frames, degrees per second.
  std::vector<double> speed(n - 1);
  for (std::size_t f = 1; f < n; ++f) speed[f - 1] = largestJointChangeDegrees(clip, f - 1, f) * clip.rate;
  std::vector<double> sorted = speed;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  const double fast = std::max(4.0 * sorted[sorted.size() / 2], kUnfoldFloor_deg_s);
  std::size_t run = 0;
  while (run < speed.size() && speed[run] > fast) ++run;
  // Longer than a quarter second, or most of the clip: the motion itself is fast.
  const auto longest = static_cast<std::size_t>(std::floor(0.25 * clip.rate));
  if (run == 0 || run > longest || 2 * run >= n) return 0;
  // From the rest pose: every joint the run turns far starts it near its rest orientation,
  // within a quarter of the turn (a hand's relaxed fingers, say, may sit off rest and stay).
  constexpr double kFarDegrees = 10.0, kRestShare = 0.25;
  const auto first = clip.frameRotations(0), last = clip.frameRotations(run);
  for (std::size_t j = 0; j < first.size(); ++j) {
    const double turn = first[j].angularDistance(last[j]) * 180.0 / M_PI;
    if (turn <= kFarDegrees) continue;
    if (first[j].angularDistance(Quat::Identity()) * 180.0 / M_PI > kRestShare * turn) return 0;
  }
  return run;
}

void dropLeadingFrames(Clip& clip, std::size_t count) {
  count = std::min(count, clip.frameCount());
  const std::size_t n = clip.skeleton.size();
  clip.rotations.erase(clip.rotations.begin(), clip.rotations.begin() + static_cast<std::ptrdiff_t>(count * n));
  clip.rootTranslations.erase(clip.rootTranslations.begin(), clip.rootTranslations.begin() + static_cast<std::ptrdiff_t>(count));
}

Clip resample(const Clip& clip, double rate) {
  Clip out = clip;
  out.rate = rate;
  out.rotations.clear();
  out.rootTranslations.clear();
  if (clip.frameCount() == 0) return out;
  const std::size_t n = clip.skeleton.size();
  const double last = static_cast<double>(clip.frameCount() - 1);
  const double count = std::floor(last * rate / clip.rate + 1e-9) + 1.0;
  if (!(count <= 1e7)) throw Error(fmt::format("{}: resampling to {} Hz would make {:.3g} frames", clip.source, rate, count));
  const auto frames = static_cast<std::size_t>(count);
  out.rotations.reserve(frames * n);
  out.rootTranslations.reserve(frames);
  for (std::size_t k = 0; k < frames; ++k) {
    const double u = std::min(static_cast<double>(k) * clip.rate / rate, last);
    const auto i = std::min(static_cast<std::size_t>(std::floor(u)), clip.frameCount() - 1);
    const std::size_t i1 = std::min(i + 1, clip.frameCount() - 1);
    const double s = u - static_cast<double>(i);
    const auto a = clip.frameRotations(i);
    const auto b = clip.frameRotations(i1);
    for (std::size_t j = 0; j < n; ++j) out.rotations.push_back(slerp(a[j], b[j], s));
    out.rootTranslations.push_back((1.0 - s) * clip.rootTranslations[i] + s * clip.rootTranslations[i1]);
  }
  return out;
}

void bvhFramePose(const formats::BvhFile& bvh, const double* values, std::span<Quat> rotations, Vec3& root) {
  for (std::size_t j = 0; j < bvh.joints.size(); ++j) {
    const formats::BvhJoint& joint = bvh.joints[j];
    Quat q = Quat::Identity();
    Vec3 position = Vec3::Zero();
    for (std::size_t c = 0; c < joint.channels.size(); ++c) {
      const double v = values[joint.firstChannel + c];
      const int axis = positionAxis(joint.channels[c]);
      if (axis >= 0) {
        position[axis] = v;
      } else {
        q = q * axisRotation(joint.channels[c], v);  // file order composes left to right
      }
    }
    rotations[j] = q.normalized();
    if (joint.parent < 0 && j == 0) root = position;
  }
}

Clip clipFromBvh(const formats::BvhFile& bvh, const ClipLoadOptions& options, ClipLoadReport* report) {
  Clip clip;
  clip.source = bvh.source;
  clip.name = std::filesystem::path(bvh.source).stem().string();
  clip.rate = 1.0 / bvh.frameTime;
  for (const formats::BvhJoint& j : bvh.joints) clip.skeleton.joints.push_back({j.name, j.parent, j.offset, j.endSite});
  const std::size_t n = bvh.joints.size();
  clip.rotations.resize(bvh.frameCount * n);
  clip.rootTranslations.resize(bvh.frameCount);
  for (std::size_t f = 0; f < bvh.frameCount; ++f)
    bvhFramePose(bvh, bvh.frame(f), {clip.rotations.data() + f * n, n}, clip.rootTranslations[f]);
  UnitsGuess guess;
  const double scale = chooseScale(clip.skeleton.restExtent(), options, guess);
  finishClip(clip, scale, options, report, guess);
  return clip;
}

// Rotation about the axes of `order` (first letter applied first), angles per axis.
Quat eulerRotation(const std::string& order, const Vec3& anglesRad) {
  Quat q = Quat::Identity();
  for (char axis : order) {
    const int a = axis - 'X';
    q = Quat(Eigen::AngleAxisd(anglesRad[a], Vec3::Unit(a))) * q;
  }
  return q;
}

Clip clipFromAsfAmc(const formats::AsfSkeleton& asf, const formats::AmcMotion& amc, const ClipLoadOptions& options,
                    ClipLoadReport* report) {
  const double angleScale = asf.degrees ? M_PI / 180.0 : 1.0;
  Clip clip;
  clip.source = amc.source;
  clip.name = std::filesystem::path(amc.source).stem().string();
  clip.rate = amc.frameRate;
  // Joint 0 is the root; joint b+1 sits at the start of ASF bone b, which is the end of its
  // parent bone (or the root).
  clip.skeleton.joints.push_back({"root", -1, Vec3::Zero(), std::nullopt});
  for (const formats::AsfBone& b : asf.bones) {
    const Vec3 offset = b.parent < 0 ? Vec3::Zero()
                                     : Vec3(asf.bones[static_cast<std::size_t>(b.parent)].direction *
                                            asf.bones[static_cast<std::size_t>(b.parent)].length);
    clip.skeleton.joints.push_back({b.name, b.parent + 1, offset, std::nullopt});
  }
  // Leaf bones end in an end site at start + direction * length.
  std::vector<bool> hasChild(asf.bones.size(), false);
  for (const formats::AsfBone& b : asf.bones)
    if (b.parent >= 0) hasChild[static_cast<std::size_t>(b.parent)] = true;
  for (std::size_t b = 0; b < asf.bones.size(); ++b)
    if (!hasChild[b]) clip.skeleton.joints[b + 1].endSite = asf.bones[b].direction * asf.bones[b].length;

  std::vector<Quat> frames(asf.bones.size());
  std::vector<Quat> axisFrames(asf.bones.size());
  for (std::size_t b = 0; b < asf.bones.size(); ++b)
    axisFrames[b] = eulerRotation(asf.bones[b].axisOrder, asf.bones[b].axis * angleScale);
  const Quat rootAxis = eulerRotation(asf.rootAxisOrder, asf.rootOrientation * angleScale);
  const std::size_t n = clip.skeleton.size();
  clip.rotations.resize(amc.frameCount * n);
  clip.rootTranslations.resize(amc.frameCount);
  auto dofRotation = [&](const std::vector<formats::AcclaimDof>& dofs, const double* values, Vec3* translation) {
    std::string order;
    Vec3 angles = Vec3::Zero();
    for (std::size_t d = 0; d < dofs.size(); ++d) {
      const auto k = static_cast<int>(dofs[d]);
      if (k <= 2) {
        order += static_cast<char>('X' + k);
        angles[k] = values[d] * angleScale;
      } else if (k <= 5 && translation) {
        (*translation)[k - 3] = values[d];
      }
    }
    return eulerRotation(order, angles);
  };
  for (std::size_t f = 0; f < amc.frameCount; ++f) {
    const double* values = amc.frame(f);
    Vec3 t = Vec3::Zero();
    const Quat m = dofRotation(asf.rootOrder, values, &t);
    clip.rotations[f * n] = (rootAxis * m * rootAxis.conjugate()).normalized();
    clip.rootTranslations[f] = asf.rootPosition + t;
    for (std::size_t b = 0; b < asf.bones.size(); ++b) {
      const Quat mb = dofRotation(asf.bones[b].dofs, values + amc.boneFirstValue[b], nullptr);
      clip.rotations[f * n + b + 1] = (axisFrames[b] * mb * axisFrames[b].conjugate()).normalized();
    }
  }
  UnitsGuess guess;
  const double scale = chooseScale(clip.skeleton.restExtent(), options, guess);
  finishClip(clip, scale, options, report, guess);
  return clip;
}

Clip loadClip(const std::string& path, const ClipLoadOptions& options, ClipLoadReport* report) {
  const std::string ext = lowerExtension(path);
  if (ext == ".bvh") return clipFromBvh(formats::readBvh(path), options, report);
  if (ext == ".amc") {
    std::string asfPath = options.asfPath;
    if (asfPath.empty()) {
      // CMU names trials SUBJECT_TRIAL.amc next to SUBJECT.asf
      const std::filesystem::path p(path);
      std::filesystem::path candidate = p;
      candidate.replace_extension(".asf");
      if (!std::filesystem::exists(candidate)) {
        const std::string stem = p.stem().string();
        candidate = p.parent_path() / (stem.substr(0, stem.rfind('_')) + ".asf");
      }
      asfPath = candidate.string();
    }
    if (!std::filesystem::exists(asfPath))
      throw Error(fmt::format("{}: no ASF skeleton found next to it (looked for {}); name one with --asf", path, asfPath));
    const formats::AsfSkeleton asf = formats::readAsf(asfPath);
    return clipFromAsfAmc(asf, formats::readAmc(path, asf), options, report);
  }
  if (ext == ".asf")  // the Acclaim pair's skeleton half: the motion is in its .amc files
    throw Error(fmt::format("{}: an ASF file holds a skeleton, not motion; give one of its .amc motions (drape "
                            "reads the .asf beside it, or the one --asf names)",
                            path));
  throw Error(fmt::format("{}: unknown motion format '{}' (expected .bvh or .amc, or a glTF avatar's own .glb or .gltf)", path, ext));
}

}  // namespace drape::motion
