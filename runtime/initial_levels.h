// Initial levels: before the budget, each visible object takes the coarsest level whose
// object-space error projects to at most `pixel_error` pixels. Hysteresis: an object keeps
// last frame's level while that level's projected error stays within [pixel_error / (1 + h),
// pixel_error * (1 + h)]-band, so levels do not flicker at a threshold.
#pragma once
#include <cstddef>
#include <cstdint>
#include <span>

#include "runtime/model_table.h"

namespace lod {

struct InitialLevelParams {
  float focal_px = 1000;      // focal_pixels(view)
  float pixel_error = 1.0f;   // screen-space error threshold, pixels
  float hysteresis = 0.25f;   // relative band around the threshold
};

// Writes level[i] for visible objects only. Sub-range safe. Returns the count written.
size_t choose_initial_levels(std::span<uint8_t> level, std::span<const uint8_t> visible,
                             std::span<const uint8_t> prev_level, std::span<const uint8_t> was_visible,
                             std::span<const float> distance, std::span<const float> scale,
                             std::span<const uint32_t> model, const ModelTable& models,
                             const InitialLevelParams& params);

}  // namespace lod
