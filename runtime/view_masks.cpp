// Several views folded into one decision per object.
#include "runtime/view_masks.h"

#include <algorithm>
#include <cassert>

namespace lod {

size_t combine_view_masks(std::span<uint8_t> mask, std::span<const std::span<uint8_t>> visible,
                          std::span<const uint8_t> never_cull) {
  const size_t n = mask.size();
  assert(never_cull.size() == n && !visible.empty() && visible.size() <= 8);
  const uint8_t all = static_cast<uint8_t>((1u << visible.size()) - 1u);
  size_t count = 0;
  if (visible.size() == 1) {  // the usual case, branch-free so that it vectorizes
    uint8_t* __restrict v = visible[0].data();
    uint8_t* __restrict m = mask.data();
    const uint8_t* __restrict nc = never_cull.data();
    for (size_t i = 0; i < n; ++i) {
      const uint8_t seen = static_cast<uint8_t>((v[i] != 0) | (nc[i] != 0));
      v[i] = seen;
      m[i] = seen;
      count += seen;
    }
    return count;
  }
  for (size_t i = 0; i < n; ++i) {
    uint8_t m = 0;
    for (size_t v = 0; v < visible.size(); ++v) m |= static_cast<uint8_t>((visible[v][i] != 0) << v);
    if (never_cull[i]) {
      m = all;
      for (size_t v = 0; v < visible.size(); ++v) visible[v][i] = 1;
    }
    mask[i] = m;
    count += m != 0;
  }
  return count;
}

void combine_view_choice(std::span<uint8_t> level, std::span<float> weight, std::span<uint8_t> visible,
                         std::span<const uint8_t> other_level, std::span<const float> other_weight,
                         std::span<const uint8_t> other_visible) {
  const size_t n = visible.size();
  assert(level.size() == n && weight.size() == n && other_level.size() == n && other_weight.size() == n &&
         other_visible.size() == n);
  for (size_t i = 0; i < n; ++i) {
    if (!other_visible[i]) continue;
    const bool both = visible[i] != 0;
    level[i] = both ? std::min(level[i], other_level[i]) : other_level[i];
    weight[i] = both ? std::min(weight[i], other_weight[i]) : other_weight[i];
    visible[i] = 1;
  }
}

}  // namespace lod
