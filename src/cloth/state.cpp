#include "drape/cloth/state.hpp"

#include <algorithm>
#include <cstring>

#include "drape/cloth/model.hpp"

namespace drape::cloth {

ClothState ClothState::atRest(const ClothModel& model) {
  ClothState s;
  const std::size_t n = model.vertexCount();
  s.x = model.restX();
  s.y = model.restY();
  s.z = model.restZ();
  s.vx.assign(n, 0.0);
  s.vy.assign(n, 0.0);
  s.vz.assign(n, 0.0);
  s.fx.assign(n, 0.0);
  s.fy.assign(n, 0.0);
  s.fz.assign(n, 0.0);
  s.work.assign(std::max(9 * model.membrane().size(), 12 * model.bending().size()), 0.0);
  return s;
}

void ClothState::copyPositions(std::vector<Vec3>& out) const {
  out.resize(size());
  for (std::size_t i = 0; i < size(); ++i) out[i] = Vec3(x[i], y[i], z[i]);
}

std::uint64_t ClothState::hash() const {
  std::uint64_t h = 1469598103934665603ull;
  for (const std::vector<double>* a : {&x, &y, &z, &vx, &vy, &vz}) {
    for (double d : *a) {
      std::uint64_t bits;
      std::memcpy(&bits, &d, sizeof bits);
      for (int b = 0; b < 8; ++b) {
        h ^= (bits >> (8 * b)) & 0xffu;
        h *= 1099511628211ull;
      }
    }
  }
  return h;
}

}  // namespace drape::cloth
