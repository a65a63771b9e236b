#pragma once
// Acclaim ASF (skeleton) and AMC (motion), the format of the original CMU motion capture
// database, read by hand. Syntax only: lengths stay in file units, angles in the file's
// unit (degrees unless ":units angle rad"). motion/ converts them to a Clip.
//
// Conventions (those of CMU's own viewer): every bone's `direction` is a unit vector in
// world axes at rest, its `axis` angles define a frame C (for "axis ... XYZ":
// C = Rz * Ry * Rx), its dof angles a rotation M composed the same way (listed "rx ry rz":
// M = Rz * Ry * Rx); the bone's world rotation is parent * C * M * C^-1 and its end is
// start + rotation * direction * length.

#include <string>
#include <string_view>
#include <vector>

#include "drape/core/math.hpp"

namespace drape::formats {

enum class AcclaimDof : std::uint8_t { RX, RY, RZ, TX, TY, TZ, L };

struct AsfBone {
  std::string name;
  int parent = -1;                    ///< index into AsfSkeleton::bones; -1: attached to the root
  Vec3 direction = Vec3::UnitY();     ///< unit vector, world axes at rest
  double length = 0.0;                ///< file units
  Vec3 axis = Vec3::Zero();           ///< angles of the bone frame C (file angle unit)
  std::string axisOrder = "XYZ";      ///< order of the axis angles (first applied first)
  std::vector<AcclaimDof> dofs;       ///< channels in AMC value order
  int line = 0;                       ///< line of the bone's "begin", for messages
};

struct AsfSkeleton {
  std::string source;
  std::string name;
  double lengthScale = 1.0;           ///< ":units length" (CMU: 0.45, meaning 1 unit = 1/0.45 inch)
  bool degrees = true;                ///< ":units angle deg" (default) or "rad"
  std::vector<AcclaimDof> rootOrder;  ///< root channels in AMC value order (e.g. TX TY TZ RX RY RZ)
  std::string rootAxisOrder = "XYZ";
  Vec3 rootPosition = Vec3::Zero();
  Vec3 rootOrientation = Vec3::Zero();
  std::vector<AsfBone> bones;         ///< parents first (reordered from the hierarchy section)

  [[nodiscard]] int find(std::string_view bone) const;
};

struct AmcMotion {
  std::string source;
  std::size_t frameCount = 0;
  std::size_t valuesPerFrame = 0;     ///< rootOrder.size() + every bone's dofs.size()
  std::vector<std::size_t> boneFirstValue;  ///< per ASF bone, index of its first value in a frame
  std::vector<double> values;         ///< frameCount x valuesPerFrame; bones absent from a frame keep 0
  double frameRate = 120.0;           ///< AMC files carry no rate; CMU captured at 120 Hz

  [[nodiscard]] const double* frame(std::size_t f) const { return values.data() + f * valuesPerFrame; }
};

inline constexpr std::size_t kMaxAmcFrames = 1'000'000;

/// Parses ASF text; throws drape::Error "name:line:column: ..." on bad input.
[[nodiscard]] AsfSkeleton parseAsf(std::string_view text, const std::string& name);
[[nodiscard]] AsfSkeleton readAsf(const std::string& path);
/// Parses AMC text against its skeleton (bone names and value counts are checked).
[[nodiscard]] AmcMotion parseAmc(std::string_view text, const std::string& name, const AsfSkeleton& skeleton);
[[nodiscard]] AmcMotion readAmc(const std::string& path, const AsfSkeleton& skeleton);

}  // namespace drape::formats
