// Object controls: options folded into per-frame columns.
#include "runtime/object_controls.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace lod {

bool options_valid(const ObjectOptions& o) {
  return std::isfinite(o.lod_bias) && std::isfinite(o.priority) && o.priority > 0;
}

ObjectControl control_of(const ObjectOptions& o, float scale, uint32_t model, const LevelCaps& caps) {
  const uint32_t last = caps.rows.level_count[model] - 1u;
  uint32_t finest = std::min<uint32_t>(o.min_level, last);
  uint32_t coarsest = std::clamp<uint32_t>(o.max_level, finest, last);
  if (o.forced_level >= 0) finest = coarsest = std::min<uint32_t>(uint32_t(o.forced_level), last);
  ObjectControl c;
  c.row = caps.row(model, coarsest);
  c.min_level = static_cast<uint8_t>(finest);
  // Bias is clamped to +-30 octaves so that 2^-bias stays a normal float.
  c.error_scale = o.lod_bias == 0 ? scale : scale * std::exp2(-std::clamp(o.lod_bias, -30.f, 30.f));
  c.inv_priority = o.priority > 0 ? 1.0f / o.priority : 1.0f;
  c.never_cull = o.never_cull ? 1 : 0;
  return c;
}

void apply_object_controls(std::span<uint8_t> level, std::span<float> weight, std::span<const uint8_t> visible,
                           std::span<const uint8_t> min_level, std::span<const float> inv_priority) {
  const size_t n = visible.size();
  assert(level.size() == n && weight.size() == n && min_level.size() == n && inv_priority.size() == n);
  // Branch-free so that it vectorizes: an invisible object's level and weight are not read.
  uint8_t* __restrict l = level.data();
  float* __restrict w = weight.data();
  for (size_t i = 0; i < n; ++i) {
    l[i] = std::max(l[i], min_level[i]);
    w[i] *= inv_priority[i];
  }
}

}  // namespace lod
