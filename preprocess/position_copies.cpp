// Position copies through an open-addressing hash of the positions' bits.
#include "preprocess/position_copies.h"

#include <cassert>
#include <cstring>
#include <vector>

namespace lod {

void find_position_copies(std::span<uint32_t> first, std::span<uint32_t> copies, const float* positions,
                          size_t vertex_count, const uint8_t* usable) {
  assert(first.size() == vertex_count && (copies.empty() || copies.size() == vertex_count));
  size_t cap = 16;
  while (cap < 2 * vertex_count) cap *= 2;
  std::vector<uint32_t> table(cap, kNoCopy);
  std::vector<uint32_t> count(vertex_count, 0);
  for (size_t v = 0; v < vertex_count; ++v) {
    first[v] = kNoCopy;
    if (usable && !usable[v]) continue;
    const float* p = positions + 3 * v;
    uint32_t h[3];
    std::memcpy(h, p, 12);
    size_t slot = (h[0] * 73856093u ^ h[1] * 19349663u ^ h[2] * 83492791u) & (cap - 1);
    for (;;) {
      const uint32_t o = table[slot];
      if (o == kNoCopy) {
        table[slot] = uint32_t(v);
        first[v] = uint32_t(v);
        break;
      }
      if (std::memcmp(positions + 3 * size_t(o), p, 12) == 0) {
        first[v] = o;
        break;
      }
      slot = (slot + 1) & (cap - 1);
    }
    count[first[v]]++;
  }
  if (copies.empty()) return;
  for (size_t v = 0; v < vertex_count; ++v) copies[v] = first[v] == kNoCopy ? 0 : count[first[v]];
}

}  // namespace lod
