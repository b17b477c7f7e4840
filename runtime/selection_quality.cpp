// Selection quality: one pass over the entries, the oracle's benefit and the pixel error.
#include "runtime/selection_quality.h"

#include <algorithm>
#include <cassert>

namespace lod {

SelectionQuality measure_selection_quality(std::span<const uint32_t> ids, std::span<const uint8_t> level,
                                           std::span<const uint32_t> model,
                                           std::span<const uint8_t> view_mask, uint8_t view_bit,
                                           std::span<const float> distance, std::span<const float> area,
                                           std::span<const float> error_scale, const ModelTable& models,
                                           float focal_px) {
  const size_t n = ids.size();
  assert(level.size() == n && model.size() == n);
  SelectionQuality q;
  for (size_t k = 0; k < n; ++k) {
    const uint32_t i = ids[k];
    if (!(view_mask[i] & view_bit)) continue;
    const uint32_t m = model[k], first = models.first_level[m], last = first + models.level_count[m] - 1u;
    assert(level[k] < models.level_count[m]);
    const double px = double(error_scale[i]) * focal_px / std::max(double(distance[i]), 1e-9);
    const double err = double(models.error[first + level[k]]) * px;
    q.benefit += double(area[i]) * std::max(0.0, double(models.error[last]) * px - err);
    q.pixel_error_sum += err;
    q.pixel_error_max = std::max(q.pixel_error_max, float(err));
    ++q.measured;
  }
  return q;
}

SelectionQuality merge_quality(const SelectionQuality& a, const SelectionQuality& b) {
  return {a.benefit + b.benefit, a.pixel_error_sum + b.pixel_error_sum,
          std::max(a.pixel_error_max, b.pixel_error_max), a.measured + b.measured};
}

}  // namespace lod
