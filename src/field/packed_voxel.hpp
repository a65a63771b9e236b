#pragma once
// Voxel coordinates packed in one word (x | y << 10 | z << 20): the propagation's sets and
// the exact transform's features hold voxels this way, a third of the memory of three ints.
// Private to the field module.

#include <cstdint>

namespace drape::field::packed {

inline std::uint32_t pack(int x, int y, int z) {
  return static_cast<std::uint32_t>(x) | (static_cast<std::uint32_t>(y) << 10) | (static_cast<std::uint32_t>(z) << 20);
}
inline int px(std::uint32_t p) { return static_cast<int>(p & 1023u); }
inline int py(std::uint32_t p) { return static_cast<int>((p >> 10) & 1023u); }
inline int pz(std::uint32_t p) { return static_cast<int>(p >> 20); }

}  // namespace drape::field::packed
