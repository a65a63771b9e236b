#pragma once
// What scene::findUpright sees in a skeleton, for `drape inspect`: the axis it stands along
// and its bones, which joint maps by shape pair and make-skirt fits to.

#include <ostream>
#include <string>
#include <vector>

#include "drape/scene/humanoid.hpp"

namespace drape::cli {

/// "  humanoid   ..." and a line per bone; `names` are the joints' names, in `joints`' order.
void printHumanoid(std::ostream& out, const std::vector<std::string>& names, const std::vector<scene::JointAt>& joints);

}  // namespace drape::cli
