// Importance (Yu, Liang and Chen, eqs. 4-6): relative distance d = D_nearest / D_current and relative
// projected area S = PA_current / PA_smallest over the visible set. f = d * SLC / S is split
// as weight = d / S (per object, per frame) times the SLC of the step selection considers.
#include "runtime/importance.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <limits>
#include <numbers>

namespace lod {

namespace {
// Floors that keep every weight finite: a zero-radius object still has a positive distance
// and area, so no division ever sees 0.
constexpr float kMinDistance = 1e-6f;
constexpr float kMinArea = 1e-24f;
}  // namespace

ViewMinima empty_minima() {
  return {std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity(), 0};
}

ViewMinima merge_minima(const ViewMinima& a, const ViewMinima& b) {
  return {std::min(a.nearest_distance, b.nearest_distance), std::min(a.smallest_area, b.smallest_area),
          a.visible + b.visible};
}

namespace {

// The loop of measure_objects, with restrict pointers as parameters (where GCC honours them).
// Branch-free so it vectorizes: every object is computed, invisible ones keep their old values
// and send +inf to the minima. Distances and areas are positive, and positive floats order
// like their bit patterns as integers, whose min-reduction vectorizes where a float one would
// need -ffast-math.
ViewMinima measure_kernel(size_t n, float* __restrict out_d, float* __restrict out_a,
                          const uint8_t* __restrict vis, const float* __restrict px,
                          const float* __restrict py, const float* __restrict pz,
                          const float* __restrict pr, float ex, float ey, float ez, float focal_px) {
  const float pi_f2 = std::numbers::pi_v<float> * focal_px * focal_px;
  const int32_t inf_bits = std::bit_cast<int32_t>(std::numeric_limits<float>::infinity());
  int32_t nearest = inf_bits, smallest = inf_bits;
  uint32_t count = 0;
  for (size_t i = 0; i < n; ++i) {
    const float dx = px[i] - ex, dy = py[i] - ey, dz = pz[i] - ez;
    const float r = pr[i];
    // A camera inside the sphere sees it as if from its surface: D >= r keeps area finite.
    const float d = std::max(std::max(std::sqrt(dx * dx + dy * dy + dz * dz), r), kMinDistance);
    const float a = std::max(pi_f2 * (r * r) / (d * d), kMinArea);  // pi * (r * focal / D)^2
    const bool v = vis[i] != 0;
    const float old_d = out_d[i], old_a = out_a[i];
    out_d[i] = v ? d : old_d;
    out_a[i] = v ? a : old_a;
    // (Selects first, then min: GCC 12 vectorizes this form, not the nested one.)
    const int32_t dm = v ? std::bit_cast<int32_t>(d) : inf_bits;
    const int32_t am = v ? std::bit_cast<int32_t>(a) : inf_bits;
    nearest = std::min(nearest, dm);
    smallest = std::min(smallest, am);
    count += v;
  }
  return {std::bit_cast<float>(nearest), std::bit_cast<float>(smallest), count};
}

size_t weights_kernel(size_t n, float* __restrict weight, const uint8_t* __restrict vis,
                      const float* __restrict distance, const float* __restrict area, float numerator) {
  uint32_t count = 0;
  for (size_t i = 0; i < n; ++i) {
    const bool v = vis[i] != 0;
    // Computed for every object and blended, so the loop vectorizes; invisible objects may
    // hold stale distance/area and keep their old weight.
    const float w = numerator / (distance[i] * area[i]), old = weight[i];
    weight[i] = v ? w : old;
    count += v;
  }
  return count;
}

}  // namespace

ViewMinima measure_objects(std::span<float> distance, std::span<float> area,
                           std::span<const uint8_t> visible, std::span<const float> cx,
                           std::span<const float> cy, std::span<const float> cz,
                           std::span<const float> radius, const glm::vec3& eye, float focal_px) {
  const size_t n = visible.size();
  assert(distance.size() == n && area.size() == n && cx.size() == n && cy.size() == n &&
         cz.size() == n && radius.size() == n);
  return measure_kernel(n, distance.data(), area.data(), visible.data(), cx.data(), cy.data(), cz.data(),
                        radius.data(), eye.x, eye.y, eye.z, focal_px);
}

size_t importance_weights(std::span<float> weight, std::span<const uint8_t> visible,
                          std::span<const float> distance, std::span<const float> area,
                          const ViewMinima& minima) {
  const size_t n = visible.size();
  assert(weight.size() == n && distance.size() == n && area.size() == n);
  // weight = d / S = (D_nearest / D) / (PA / PA_smallest) = (D_nearest * PA_smallest) / (D * PA)
  return weights_kernel(n, weight.data(), visible.data(), distance.data(), area.data(),
                        minima.nearest_distance * minima.smallest_area);
}

}  // namespace lod
