// Initial levels from screen-space error, with a hysteresis band so that an object sitting at
// a threshold distance does not switch levels every frame.
#include "runtime/initial_levels.h"

#include <algorithm>
#include <cassert>

namespace lod {

namespace {

// The coarsest level k with error[k] * pixels_per_unit <= limit, searched from `k`.
inline uint32_t last_within(const float* error, uint32_t count, uint32_t k, float pixels_per_unit,
                            float limit) {
  while (k + 1 < count && error[k + 1] * pixels_per_unit <= limit) ++k;
  while (k > 0 && error[k] * pixels_per_unit > limit) --k;
  return k;
}

}  // namespace

size_t choose_initial_levels(std::span<uint8_t> level, std::span<const uint8_t> visible,
                             std::span<const uint8_t> prev_level, std::span<const uint8_t> was_visible,
                             std::span<const float> distance, std::span<const float> scale,
                             std::span<const uint32_t> model, const ModelTable& models,
                             const InitialLevelParams& params) {
  const size_t n = visible.size();
  assert(level.size() == n && prev_level.size() == n && was_visible.size() == n &&
         distance.size() == n && scale.size() == n && model.size() == n);
  const float fine_limit = params.pixel_error;
  // A negative hysteresis would invert the band; it means "none".
  const float coarse_limit = std::max(fine_limit, params.pixel_error * (1.0f + params.hysteresis));
  const uint32_t* first = models.first_level.data();
  const uint8_t* counts = models.level_count.data();
  const float* error = models.error.data();
  size_t written = 0;
  // Visibility is data the branch predictor cannot learn, so each block first lists its
  // visible objects without branching, then walks only those.
  constexpr size_t kBlock = 256;
  uint32_t listed[kBlock];
  for (size_t block = 0; block < n; block += kBlock) {
    const size_t end = std::min(n, block + kBlock);
    size_t count_listed = 0;
    for (size_t i = block; i < end; ++i) {
      listed[count_listed] = static_cast<uint32_t>(i);
      count_listed += visible[i] != 0;
    }
    for (size_t j = 0; j < count_listed; ++j) {
      const size_t i = listed[j];
      const uint32_t m = model[i];
      assert(m < models.model_count());
      const float* e = error + first[m];
      const uint32_t count = counts[m];
      const float pixels_per_unit = scale[i] * params.focal_px / distance[i];
      // Errors grow with the level index (validate_chain), so the levels within a limit are
      // a prefix and the answer is its last level. Walk there from last frame's level:
      // between frames that is zero or one step, so the branches stay predictable; level 0
      // always qualifies.
      const uint32_t prev = prev_level[i] < count ? prev_level[i] : count - 1u;
      const uint32_t k_fine = last_within(e, count, prev, pixels_per_unit, fine_limit);
      const uint32_t k_coarse = last_within(e, count, k_fine, pixels_per_unit, coarse_limit);
      // Last frame's level survives while it stays inside [k_fine, k_coarse]: refine only
      // when its error exceeds the threshold by the band, coarsen as soon as a coarser level
      // fits.
      const uint32_t kept = std::clamp<uint32_t>(prev_level[i], k_fine, k_coarse);
      level[i] = static_cast<uint8_t>(was_visible[i] ? kept : k_fine);
    }
    written += count_listed;
  }
  return written;
}

}  // namespace lod
