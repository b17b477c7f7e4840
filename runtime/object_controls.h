// Object controls: what each object's ObjectOptions mean for this frame's stages, as columns.
//   row          selection row (LevelCaps) whose coarsest level is the object's max level,
//                or its forced level
//   min_level    finest level allowed (the forced level when forced)
//   error_scale  scale * 2^-lod_bias: initial levels see the error as this much larger
//   inv_priority 1 / priority: importance is multiplied by it (lowered later when < 1)
//   never_cull   1: visible to every view
#pragma once
#include <cstdint>
#include <span>

#include "lodkit/types.hpp"
#include "runtime/level_caps.h"

namespace lod {

struct ObjectControl {
  uint32_t row = 0;
  uint8_t min_level = 0;
  float error_scale = 1;
  float inv_priority = 1;
  uint8_t never_cull = 0;
};

// One object's controls; clamps what it reads, so any option values give valid columns.
ObjectControl control_of(const ObjectOptions& o, float scale, uint32_t model, const LevelCaps& caps);

// level[i] = max(level[i], min_level[i]) and weight[i] *= inv_priority[i], for every object
// (an invisible one's values are not read), so that the loop vectorizes. Sub-range safe.
void apply_object_controls(std::span<uint8_t> level, std::span<float> weight, std::span<const uint8_t> visible,
                           std::span<const uint8_t> min_level, std::span<const float> inv_priority);

// True when options are usable: finite bias, priority > 0 and finite.
bool options_valid(const ObjectOptions& o);

}  // namespace lod
