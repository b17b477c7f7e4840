// Box-shaped chains with real geometry, for occlusion tests and benchmarks.
#pragma once
#include <cmath>
#include <string>

#include "runtime/lod_chain.h"

namespace lod::test {

// An axis-aligned box chain of one level: half sizes hx, hy, hz, resting on y = 0.
inline LodChain box_chain(const std::string& name, float hx, float hy, float hz) {
  LodChain c;
  c.name = name;
  for (int k = 0; k < 8; ++k) {
    c.positions.push_back(k & 1 ? hx : -hx);
    c.positions.push_back(k & 2 ? 2 * hy : 0);
    c.positions.push_back(k & 4 ? hz : -hz);
  }
  c.normals.assign(c.positions.size(), 0.f);
  const uint32_t faces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  for (const auto& f : faces) c.indices.insert(c.indices.end(), f, f + 3);
  LodLevel l;
  l.index_count = 36;
  l.vertex_count = 8;
  l.level = level_of_triangles(12);
  l.bounds.center[1] = hy;
  l.bounds.radius = std::sqrt(hx * hx + hy * hy + hz * hz);
  c.levels.push_back(l);
  return c;
}

}  // namespace lod::test
