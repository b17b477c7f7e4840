// Selection quality per frame: what the selected levels are worth and what error they leave.
// Benefit as the selection oracle defines it (runtime/selection_oracle.h, Funkhouser-
// Sequin benefit): b_i(k) = A_i * (s_i(L) - s_i(k)), A_i the projected area in pixels^2, s_i(k)
// = error_k * error_scale_i * focal / distance_i the level's error in pixels, L the model's
// coarsest level. The pixel error s_i(k) is the screen-space error a viewer sees (a culled
// level's error is its bounding diameter, so it counts as the object's size on screen).
// Sub-range safe over entries: sum the parts in a fixed order.
#pragma once
#include <cstdint>
#include <span>

#include "runtime/model_table.h"

namespace lod {

struct SelectionQuality {
  double benefit = 0;
  double pixel_error_sum = 0;
  float pixel_error_max = 0;
  uint32_t measured = 0;  // entries seen by the view
};

// For entries k whose object ids[k] the view sees (view_mask[ids[k]] & view_bit): benefit and pixel error
// of level[k] of model[k]. `distance`, `area` and `error_scale` are per object (importance's
// measure_objects and the object controls).
SelectionQuality measure_selection_quality(std::span<const uint32_t> ids, std::span<const uint8_t> level,
                                           std::span<const uint32_t> model,
                                           std::span<const uint8_t> view_mask, uint8_t view_bit,
                                           std::span<const float> distance, std::span<const float> area,
                                           std::span<const float> error_scale, const ModelTable& models,
                                           float focal_px);

SelectionQuality merge_quality(const SelectionQuality& a, const SelectionQuality& b);

}  // namespace lod
