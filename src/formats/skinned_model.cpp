#include "drape/formats/skinned_model.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include <Eigen/SVD>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drape/core/error.hpp"
#include "plain_data.hpp"

namespace drape::formats {
using detail::Cursor;
using detail::put;
using detail::putVector;

std::string serialise(const SkinnedModel& model) {
  std::string s;
  put<std::uint64_t>(s, model.joints.size());
  for (const SkinnedJoint& j : model.joints) {
    putVector(s, std::vector<char>(j.name.begin(), j.name.end()));
    put<std::int32_t>(s, j.parent);
    for (int i = 0; i < 16; ++i) put<double>(s, j.restWorld(i % 4, i / 4));
  }
  std::vector<double> xyz;
  for (const Vec3& p : model.positions) xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
  putVector(s, xyz);
  putVector(s, model.triangles);
  putVector(s, model.vertexJoints);
  putVector(s, model.vertexWeights);
  detail::putStrings(s, model.animations);
  detail::putStrings(s, model.meshes);
  detail::putStrings(s, model.meshesRead);
  return s;
}

SkinnedModel deserialiseSkinnedModel(std::string_view bytes, const std::string& name) {
  Cursor c{bytes, 0, name};
  SkinnedModel model;
  model.source = name;
  const auto joints = c.get<std::uint64_t>();
  if (joints > 65535) throw Error(fmt::format("{}: the reader returned bad data", name));
  for (std::uint64_t k = 0; k < joints; ++k) {
    SkinnedJoint j;
    const std::vector<char> chars = c.getVector<char>();
    j.name.assign(chars.begin(), chars.end());
    j.parent = c.get<std::int32_t>();
    for (int i = 0; i < 16; ++i) j.restWorld(i % 4, i / 4) = c.get<double>();
    model.joints.push_back(std::move(j));
  }
  const std::vector<double> xyz = c.getVector<double>();
  for (std::size_t i = 0; i + 2 < xyz.size(); i += 3) model.positions.emplace_back(xyz[i], xyz[i + 1], xyz[i + 2]);
  model.triangles = c.getVector<mesh::Triangle>();
  model.vertexJoints = c.getVector<std::array<std::uint16_t, 4>>();
  model.vertexWeights = c.getVector<std::array<float, 4>>();
  model.animations = c.getStrings();
  model.meshes = c.getStrings();
  model.meshesRead = c.getStrings();
  return model;
}

std::string serialise(const SkinnedJointMotion& m) {
  std::string s;
  putVector(s, std::vector<char>(m.animation.begin(), m.animation.end()));
  put<std::uint64_t>(s, m.animationNames.size());
  for (const std::string& a : m.animationNames) putVector(s, std::vector<char>(a.begin(), a.end()));
  put(s, m.rate);
  put(s, m.start_s);
  put(s, m.end_s);
  put(s, m.floor_m);
  put<std::uint64_t>(s, m.joints.size());
  for (const std::string& j : m.joints) putVector(s, std::vector<char>(j.begin(), j.end()));
  putVector(s, std::vector<std::int32_t>(m.parents.begin(), m.parents.end()));
  std::vector<double> numbers;
  for (const Vec3& c : m.restCenters) numbers.insert(numbers.end(), {c.x(), c.y(), c.z()});
  putVector(s, numbers);
  numbers.clear();
  for (const RigidTransform& t : m.frames)
    numbers.insert(numbers.end(), {t.rotation.w(), t.rotation.x(), t.rotation.y(), t.rotation.z(), t.translation.x(),
                                   t.translation.y(), t.translation.z()});
  putVector(s, numbers);
  return s;
}

SkinnedJointMotion deserialiseJointMotion(std::string_view bytes, const std::string& name) {
  Cursor c{bytes, 0, name};
  SkinnedJointMotion m;
  const std::vector<char> animation = c.getVector<char>();
  m.animation.assign(animation.begin(), animation.end());
  const auto names = c.get<std::uint64_t>();
  if (names > 1'000'000) throw Error(fmt::format("{}: the reader returned bad data", name));
  for (std::uint64_t k = 0; k < names; ++k) {
    const std::vector<char> chars = c.getVector<char>();
    m.animationNames.emplace_back(chars.begin(), chars.end());
  }
  m.rate = c.get<double>();
  m.start_s = c.get<double>();
  m.end_s = c.get<double>();
  m.floor_m = c.get<double>();
  const auto joints = c.get<std::uint64_t>();
  if (joints > 65535) throw Error(fmt::format("{}: the reader returned bad data", name));
  for (std::uint64_t k = 0; k < joints; ++k) {
    const std::vector<char> chars = c.getVector<char>();
    m.joints.emplace_back(chars.begin(), chars.end());
  }
  const std::vector<std::int32_t> parents = c.getVector<std::int32_t>();
  m.parents.assign(parents.begin(), parents.end());
  for (std::size_t k = 0; k < m.parents.size(); ++k)
    if (m.parents[k] >= static_cast<int>(k) || m.parents[k] < -1) throw Error(fmt::format("{}: the reader returned bad data", name));
  const std::vector<double> centres = c.getVector<double>();
  const std::vector<double> frames = c.getVector<double>();
  if (m.parents.size() != joints || centres.size() != 3 * joints || (joints > 0 && frames.size() % (7 * joints) != 0))
    throw Error(fmt::format("{}: the reader returned bad data", name));
  for (std::size_t i = 0; i + 2 < centres.size(); i += 3) m.restCenters.emplace_back(centres[i], centres[i + 1], centres[i + 2]);
  for (std::size_t i = 0; i + 6 < frames.size(); i += 7)
    m.frames.push_back({Quat(frames[i], frames[i + 1], frames[i + 2], frames[i + 3]),
                        Vec3(frames[i + 4], frames[i + 5], frames[i + 6])});
  return m;
}


std::string serialise(const std::vector<SkinnedJointMotion>& motions) {
  std::string s;
  put<std::uint64_t>(s, motions.size());
  for (const SkinnedJointMotion& m : motions) {
    const std::string one = serialise(m);
    putVector(s, std::vector<char>(one.begin(), one.end()));
  }
  return s;
}

std::vector<SkinnedJointMotion> deserialiseJointMotions(std::string_view bytes, const std::string& name) {
  Cursor c{bytes, 0, name};
  const auto count = c.get<std::uint64_t>();
  if (count > 1'000'000) throw Error(fmt::format("{}: the reader returned bad data", name));
  std::vector<SkinnedJointMotion> motions;
  for (std::uint64_t k = 0; k < count; ++k) {
    const std::vector<char> one = c.getVector<char>();
    motions.push_back(deserialiseJointMotion(std::string_view(one.data(), one.size()), name));
  }
  return motions;
}

namespace detail {

std::string animationName(const std::string& own, std::size_t index) {
  return own.empty() ? fmt::format("animation {}", index) : own;
}

std::size_t chooseAnimation(const std::vector<std::string>& names, const std::string& which, const std::string& file) {
  if (names.empty()) throw Error(fmt::format("{}: has no animation", file));
  if (which.empty()) return 0;
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == which) return i;
  const bool digits = which.size() <= 9 && std::all_of(which.begin(), which.end(), [](char c) { return c >= '0' && c <= '9'; });
  if (digits && std::stoul(which) < names.size()) return std::stoul(which);
  std::vector<std::string> listed;
  for (std::size_t i = 0; i < names.size(); ++i) listed.push_back(fmt::format("{} '{}'", i, names[i]));
  throw Error(fmt::format("{}: has no animation '{}' (it has {}: {})", file, which, names.size(), fmt::join(listed, ", ")));
}

std::size_t motionFrameCount(double start_s, double end_s, double rate, std::size_t joints, const std::string& animation,
                             const std::string& file) {
  if (!(rate > 0) || !std::isfinite(rate)) throw Error(fmt::format("{}: a motion rate of {} frames per second", file, rate));
  // Key times are single precision in every format read here: an animation of 140 frames at
  // 30 Hz ends at 4.6666665 s. A thousandth of a frame of slack keeps its last frame (past
  // the last key, which then holds).
  const double frames = std::floor((end_s - start_s) * rate + 1e-3) + 1.0;
  if (!std::isfinite(frames) || frames * static_cast<double>(joints) > static_cast<double>(kMaxMotionTransforms))
    throw Error(fmt::format("{}: animation '{}' lasts {:g} s: {:g} frames of {} joints at {:g} Hz are more than drape "
                            "samples ({})",
                            file, animation, end_s - start_s, frames, joints, rate, kMaxMotionTransforms));
  return static_cast<std::size_t>(frames);
}

void appendWithinCap(std::vector<SkinnedJointMotion>& motions, SkinnedJointMotion motion, const std::string& file,
                     std::size_t cap) {
  std::size_t total = motion.frames.size();
  for (const SkinnedJointMotion& m : motions) total += m.frames.size();
  if (total > cap)
    throw Error(fmt::format("{}: its animations together hold more than the {} joint transforms drape samples at {:g} Hz",
                            file, cap, motion.rate));
  motions.push_back(std::move(motion));
}

double lowestOf(const std::vector<Vec3>& positions, const std::vector<Vec3>& joints) {
  double lowest = std::numeric_limits<double>::infinity();
  for (const Vec3& p : positions.empty() ? joints : positions) lowest = std::min(lowest, p.y());
  return std::isfinite(lowest) ? lowest : 0.0;
}

RigidTransform jointMotionOf(const Eigen::Matrix4d& world, const Eigen::Matrix4d& restInverse) {
  const Eigen::Matrix3d m = (world * restInverse).topLeftCorner<3, 3>();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d r = svd.matrixU() * svd.matrixV().transpose();
  if (r.determinant() < 0) {
    Eigen::Matrix3d u = svd.matrixU();
    u.col(2) = -u.col(2);
    r = u * svd.matrixV().transpose();
  }
  return {Quat(r).normalized(), world.block<3, 1>(0, 3)};
}

}  // namespace detail
}  // namespace drape::formats
