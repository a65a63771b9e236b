#include "drape/formats/skinned_model.hpp"

#include <algorithm>
#include <cstring>

#include <fmt/format.h>

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
  return model;
}

}  // namespace drape::formats
