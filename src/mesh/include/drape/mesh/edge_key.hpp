#pragma once
// An undirected edge as one sortable, hashable word: (lower vertex << 32) | higher vertex.

#include <algorithm>
#include <cstdint>

namespace drape::mesh {

inline std::uint64_t edgeKey(std::uint32_t a, std::uint32_t b) {
  return (std::uint64_t{std::min(a, b)} << 32) | std::max(a, b);
}

}  // namespace drape::mesh
