#include "inspect_humanoid.hpp"

#include <cmath>
#include <optional>

#include <fmt/ostream.h>
#include <fmt/ranges.h>

namespace drape::cli {
namespace {

/// The way a horizontal unit vector points, for a person: +x, -z, or [x z] between.
std::string facingText(const Vec3& f) {
  for (int axis : {0, 2})
    if (std::abs(f[axis]) > 0.995) return fmt::format("{}{}", f[axis] > 0 ? '+' : '-', axis == 0 ? 'x' : 'z');
  return fmt::format("[{:.2f} {:.2f}] in x and z", f.x(), f.z());
}

}  // namespace

void printHumanoid(std::ostream& out, const std::vector<std::string>& names, const std::vector<scene::JointAt>& joints) {
  std::string whyNot;
  const std::optional<scene::Upright> upright = scene::findUpright(joints, &whyNot);
  if (!upright) {
    fmt::print(out, "  humanoid   none by the skeleton's shape: {}\n", whyNot);
    return;
  }
  const scene::Humanoid& h = upright->humanoid;
  const auto chain = [&](const scene::JointChain& c) {
    if (c.empty()) return std::string("-");
    std::vector<std::string> n;
    for (int j : c) n.push_back(names[static_cast<std::size_t>(j)]);
    return fmt::format("{}", fmt::join(n, " + "));
  };
  if (upright->axis == "+y")
    fmt::print(out, "  humanoid   by the skeleton's shape, facing {}\n", facingText(h.forward));
  else
    fmt::print(out, "  humanoid   by the skeleton's shape, standing along {} (drape's scenes stand along +y: rotation {} "
                    "stands it up), then facing {}\n",
               upright->axis, upright->rotationText(), facingText(h.forward));
  fmt::print(out, "    pelvis     {}{}{}\n", names[static_cast<std::size_t>(h.pelvis)],
             h.abovePelvis.empty() ? "" : fmt::format(" (under {})", chain(h.abovePelvis)),
             h.hips.empty() ? "" : fmt::format(", the legs from {}", chain(h.hips)));
  fmt::print(out, "    spine      {} (chest {})\n", chain(h.spine), names[static_cast<std::size_t>(h.chest())]);
  if (h.head() < 0)
    fmt::print(out, "    neck       - (no head: nothing rises above where the arms leave)\n");
  else
    fmt::print(out, "    neck       {} (head {})\n", chain(h.neck), names[static_cast<std::size_t>(h.head())]);
  for (std::size_t s = 0; s < 2; ++s) {
    const char* side = s == 0 ? "left " : "right";
    const scene::HumanoidLimb& leg = h.legs[s];
    fmt::print(out, "    {} leg  hip bone {}, thigh {}, shin {}, foot {}, toe {}\n", side, chain(leg.base), chain(leg.upper),
               chain(leg.lower), chain(leg.end), chain(leg.tip));
  }
  for (std::size_t s = 0; s < 2; ++s) {
    const char* side = s == 0 ? "left " : "right";
    const scene::HumanoidLimb& arm = h.arms[s];
    fmt::print(out, "    {} arm  clavicle {}, upper arm {}, forearm {}, hand {}\n", side, chain(arm.base), chain(arm.upper),
               chain(arm.lower), arm.end.empty() ? "- (the arm ends at its elbow, whose part is the forearm and hand)" : chain(arm.end));
  }
}

}  // namespace drape::cli
