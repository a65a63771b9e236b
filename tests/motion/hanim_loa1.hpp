#pragma once
// A humanoid of H-Anim 1.1's first level of articulation as the standard lays it out: its
// 18 Joints near the suggested centres (Annex A, rounded to millimetres), facing +Z with
// the arms down at the sides, a sacroiliac between the root and the hips and the shoulders
// on vt10. No segments: the retargeting tests measure its joints.

#include <string>

#include "drape/scene/avatar.hpp"

namespace drape::motion {

inline scene::Avatar hanimLoa1() {
  scene::Avatar loa1;
  loa1.name = "LOA1";
  const auto joint = [&](const char* name, const char* parent, double x, double y, double z) {
    loa1.joints.push_back({name, *parent ? loa1.findJoint(parent) : -1, Vec3(x, y, z), Quat::Identity()});
  };
  joint("HumanoidRoot", "", 0.0, 0.824, 0.028);
  joint("sacroiliac", "HumanoidRoot", 0.0, 0.915, 0.002);
  for (const double side : {1.0, -1.0}) {
    const std::string s = side > 0 ? "l_" : "r_";
    joint((s + "hip").c_str(), "sacroiliac", side * 0.096, 0.912, 0.0);
    joint((s + "knee").c_str(), (s + "hip").c_str(), side * 0.104, 0.487, 0.031);
    joint((s + "ankle").c_str(), (s + "knee").c_str(), side * 0.097, 0.070, -0.027);
  }
  joint("vl5", "HumanoidRoot", 0.003, 1.057, -0.078);
  joint("vt10", "vl5", 0.006, 1.285, -0.082);
  joint("vc4", "vt10", 0.007, 1.544, -0.025);
  joint("skullbase", "vc4", 0.004, 1.621, 0.024);
  for (const double side : {1.0, -1.0}) {
    const std::string s = side > 0 ? "l_" : "r_";
    joint((s + "shoulder").c_str(), "vt10", side * 0.191, 1.441, -0.033);
    joint((s + "elbow").c_str(), (s + "shoulder").c_str(), side * 0.195, 1.139, -0.062);
    joint((s + "wrist").c_str(), (s + "elbow").c_str(), side * 0.196, 0.869, -0.052);
  }
  return loa1;
}

}  // namespace drape::motion
