// Selection quality: one pass over the entries, the oracle's benefit and the pixel error.
#include "runtime/selection_quality.h"

#include <algorithm>
#include <cassert>

namespace lod {

SelectionQuality measure_selection_quality(std::span<const uint32_t> ids, std::span<const uint8_t> level,
                                           std::span<const uint32_t> model, std::span<const uint8_t> view_mask,
                                           uint8_t view_bit, std::span<const float> distance,
                                           std::span<const float> area, std::span<const float> error_scale,
                                           const ModelTable& models, float focal_px) {
  const size_t n = ids.size();
  assert(level.size() == n && model.size() == n);
  const uint32_t* first_level = models.first_level.data();
  const uint8_t* counts = models.level_count.data();
  const float* error = models.error.data();
  // Per entry in float and without branches (publish runs it over every entry); sums in double.
  double benefit = 0, error_sum = 0;
  float error_max = 0;
  uint32_t measured = 0;
  for (size_t k = 0; k < n; ++k) {
    const uint32_t i = ids[k];
    const bool seen = (view_mask[i] & view_bit) != 0;
    const uint32_t first = first_level[model[k]];
    assert(level[k] < counts[model[k]]);
    const float px = error_scale[i] * focal_px / std::max(distance[i], 1e-9f);
    const float err = error[first + level[k]] * px;
    const float coarsest = error[first + counts[model[k]] - 1u] * px;
    benefit += seen ? double(area[i] * std::max(0.f, coarsest - err)) : 0.0;
    error_sum += seen ? double(err) : 0.0;
    error_max = seen ? std::max(error_max, err) : error_max;
    measured += seen;
  }
  return {benefit, error_sum, error_max, measured};
}

SelectionQuality merge_quality(const SelectionQuality& a, const SelectionQuality& b) {
  return {a.benefit + b.benefit, a.pixel_error_sum + b.pixel_error_sum,
          std::max(a.pixel_error_max, b.pixel_error_max), a.measured + b.measured};
}

}  // namespace lod
