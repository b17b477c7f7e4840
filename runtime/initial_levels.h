// Initial levels: before the budget, each visible object takes the coarsest level whose
// object-space error projects (error * scale * focal / distance) to at most `pixel_error`
// pixels: k_fine. Hysteresis: k_coarse is the coarsest level within pixel_error * (1 + h);
// an object visible last frame keeps its level clamped into [k_fine, k_coarse], so it refines
// only once its level's error exceeds the threshold by the band, and levels do not flicker
// at a threshold. Level 0 always qualifies.
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
