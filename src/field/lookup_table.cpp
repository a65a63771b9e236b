// The DVDP lookup table (paper section 4.3.2, Figures 3-5, Table 1).

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>

#include "drape/field/propagation.hpp"

namespace drape::field {

TableOffset TableOffset::source() const {
  TableOffset s = *this;
  if (x == 0) return s;
  if (x > z) {
    s.x = static_cast<std::int16_t>(x - 1);
  } else if (y == 0) {
    s.x = static_cast<std::int16_t>(x - 1);
    s.z = static_cast<std::int16_t>(z - 1);
  } else {
    s.x = static_cast<std::int16_t>(x - 1);
    s.y = static_cast<std::int16_t>(y - 1);
    s.z = static_cast<std::int16_t>(z - 1);
  }
  s.length2 = s.x * s.x + s.y * s.y + s.z * s.z;
  s.connectivity = Connectivity::Face;
  return s;
}

LookupTable LookupTable::build(int radius) {
  LookupTable t;
  t.radius = radius;
  const int r2 = radius * radius;
  // All offsets of the tetrahedron y <= z <= x within the radius, with Table 1's rule.
  for (int x = 0; x <= radius; ++x)
    for (int z = 0; z <= x; ++z)
      for (int y = 0; y <= z; ++y) {
        const int l2 = x * x + y * y + z * z;
        if (l2 > r2) break;
        TableOffset o;
        o.x = static_cast<std::int16_t>(x);
        o.y = static_cast<std::int16_t>(y);
        o.z = static_cast<std::int16_t>(z);
        o.length2 = l2;
        o.connectivity = x > z ? Connectivity::Face : (y == 0 ? Connectivity::Edge : Connectivity::Corner);
        t.offsets.push_back(o);
      }
  std::sort(t.offsets.begin(), t.offsets.end(), [](const TableOffset& a, const TableOffset& b) {
    if (a.length2 != b.length2) return a.length2 < b.length2;
    if (a.x != b.x) return a.x < b.x;
    if (a.z != b.z) return a.z < b.z;
    return a.y < b.y;
  });

  // One iteration per distinct length.
  t.iterationOfLength2.assign(static_cast<std::size_t>(r2) + 1, -1);
  for (std::size_t i = 0; i < t.offsets.size(); ++i) {
    if (i == 0 || t.offsets[i].length2 != t.offsets[i - 1].length2) {
      t.iterationOfLength2[t.offsets[i].length2] = static_cast<int>(t.iterationLength2.size());
      t.iterationLength2.push_back(t.offsets[i].length2);
      t.iterationOffsetStart.push_back(static_cast<int>(i));
    }
  }
  t.iterationOffsetStart.push_back(static_cast<int>(t.offsets.size()));

  // Actions: the distinct (source iteration, connectivity) pairs of each iteration's offsets.
  const int n = t.iterationCount();
  t.actionStart.push_back(0);
  t.lastUse.assign(n, -1);
  for (int i = 0; i < n; ++i) {
    const std::size_t first = t.actions.size();
    for (int k = t.iterationOffsetStart[i]; k < t.iterationOffsetStart[i + 1]; ++k) {
      const TableOffset& d = t.offsets[k];
      if (d.length2 == 0) continue;
      const TableAction a{t.iterationOfLength2[d.source().length2], d.connectivity};
      const bool seen = std::any_of(t.actions.begin() + static_cast<std::ptrdiff_t>(first), t.actions.end(),
                                    [&](const TableAction& b) {
                                      return b.sourceIteration == a.sourceIteration && b.connectivity == a.connectivity;
                                    });
      if (!seen) t.actions.push_back(a);
    }
    // Sources in increasing order: the expansion then walks sets in the order they were made.
    std::sort(t.actions.begin() + static_cast<std::ptrdiff_t>(first), t.actions.end(),
              [](const TableAction& a, const TableAction& b) {
                return a.sourceIteration != b.sourceIteration ? a.sourceIteration < b.sourceIteration
                                                              : a.connectivity < b.connectivity;
              });
    for (std::size_t k = first; k < t.actions.size(); ++k) t.lastUse[t.actions[k].sourceIteration] = i;
    t.actionStart.push_back(static_cast<int>(t.actions.size()));
  }
  // A set's users lie within (|s| + sqrt(3))^2 of it; beyond the radius they are unknown.
  for (int j = 0; j < n; ++j) {
    const double reach = std::sqrt(static_cast<double>(t.iterationLength2[j])) + 2.0;
    if (reach * reach > r2) t.lastUse[j] = -1;
  }
  return t;
}

const LookupTable& LookupTable::forRadius(int radius) {
  // Tables are kept for the life of the process: propagations running on other threads may
  // hold a smaller one while a larger one is built.
  static std::mutex mutex;
  static std::vector<std::unique_ptr<LookupTable>> tables;
  const std::lock_guard<std::mutex> lock(mutex);
  for (const auto& t : tables)
    if (t->radius >= radius) return *t;
  int r = tables.empty() ? 32 : tables.back()->radius;
  while (r < radius) r *= 2;
  tables.push_back(std::make_unique<LookupTable>(build(r)));
  return *tables.back();
}

}  // namespace drape::field
