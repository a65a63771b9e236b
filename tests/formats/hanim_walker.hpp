#pragma once
// A two-joint H-Anim humanoid with a motion, for the writer's and the motion reader's tests:
// the root walks along z and turns about y, its child swings about x, keyed at 25 frames
// per second.

#include <string>

#include "drape/formats/hanim_writer.hpp"

namespace drape::formats::testing {

inline HanimHumanoidData twoJointWalker(std::size_t frames, const std::string& childName) {
  HanimHumanoidData h;
  h.name = "walker";
  h.joints.push_back({"root", -1, Vec3(0, 1, 0), {}});
  h.joints.push_back({childName, 0, Vec3(0, 0.5, 0), {}});
  h.joints[1].segments.push_back({"shin", {{0, 0.5, 0}, {0.1, 0.1, 0}, {0, 0.1, 0.1}}, {{0, 1, 2}}});
  HanimMotion m;
  m.name = "walk";
  m.frameRate = 25.0;
  for (std::size_t f = 0; f < frames; ++f) {
    const double a = 0.05 * static_cast<double>(f);
    m.frames.push_back({{Quat(Eigen::AngleAxisd(a, Vec3::UnitY())), Vec3(0, 0, 0.04 * static_cast<double>(f))},
                        {Quat(Eigen::AngleAxisd(-2 * a, Vec3::UnitX())), Vec3::Zero()}});
  }
  h.motion = m;
  return h;
}

}  // namespace drape::formats::testing
