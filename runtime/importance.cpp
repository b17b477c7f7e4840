// Importance (R0, eqs. 4-6): relative distance d = D_nearest / D_current and relative
// projected area S = PA_current / PA_smallest over the visible set. f = d * SLC / S is split
// as weight = d / S (per object, per frame) times the SLC of the step selection considers.
#include "runtime/importance.h"

#include <algorithm>
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

ViewMinima measure_objects(std::span<float> distance, std::span<float> area,
                           std::span<const uint8_t> visible, std::span<const float> cx,
                           std::span<const float> cy, std::span<const float> cz,
                           std::span<const float> radius, const glm::vec3& eye, float focal_px) {
  const size_t n = visible.size();
  assert(distance.size() == n && area.size() == n && cx.size() == n && cy.size() == n &&
         cz.size() == n && radius.size() == n);
  const float inf = std::numeric_limits<float>::infinity();
  const float pi_f2 = std::numbers::pi_v<float> * focal_px * focal_px;
  float nearest = inf, smallest = inf;
  size_t count = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!visible[i]) continue;
    const float dx = cx[i] - eye.x, dy = cy[i] - eye.y, dz = cz[i] - eye.z;
    const float r = radius[i];
    // A camera inside the sphere sees it as if from its surface: D >= r keeps area finite.
    const float d = std::max(std::max(std::sqrt(dx * dx + dy * dy + dz * dz), r), kMinDistance);
    const float a = std::max(pi_f2 * (r * r) / (d * d), kMinArea);  // pi * (r * focal / D)^2
    distance[i] = d;
    area[i] = a;
    nearest = std::min(nearest, d);
    smallest = std::min(smallest, a);
    ++count;
  }
  return {nearest, smallest, count};
}

size_t importance_weights(std::span<float> weight, std::span<const uint8_t> visible,
                          std::span<const float> distance, std::span<const float> area,
                          const ViewMinima& minima) {
  const size_t n = visible.size();
  assert(weight.size() == n && distance.size() == n && area.size() == n);
  // weight = d / S = (D_nearest / D) / (PA / PA_smallest) = (D_nearest * PA_smallest) / (D * PA)
  const float numerator = minima.nearest_distance * minima.smallest_area;
  size_t count = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!visible[i]) continue;
    weight[i] = numerator / (distance[i] * area[i]);
    ++count;
  }
  return count;
}

}  // namespace lod
