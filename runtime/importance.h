// Importance (Yu, Liang and Chen): d = D_nearest / D_current, S = PA_current / PA_smallest,
// SLC(i -> j) = max(l_i, l_j) * |l_i - l_j|, f = d * SLC / S.
// Split into a measuring pass (parallel, sub-range safe, returns partial minima) and a
// weighting pass (parallel) once the global minima are known; selection multiplies the
// per-object weight d / S by the SLC of the step it considers.
#pragma once
#include <cstddef>
#include <cstdint>
#include <span>

#include "runtime/view.h"

namespace lod {

inline int32_t span_of_level_changed(int32_t from_l, int32_t to_l) {
  const int32_t hi = from_l > to_l ? from_l : to_l;
  const int32_t diff = from_l > to_l ? from_l - to_l : to_l - from_l;
  return hi * diff;
}

struct ViewMinima {
  float nearest_distance;  // D_nearest over visible objects
  float smallest_area;     // PA_smallest over visible objects (pixels)
  size_t visible;
};
ViewMinima merge_minima(const ViewMinima& a, const ViewMinima& b);
ViewMinima empty_minima();

// For visible objects: distance from eye to sphere centre (clamped to >= radius and > 0, so a
// camera inside a sphere does not divide by zero) and projected area pi * (r * focal / D)^2
// in pixels (> 0). Invisible objects are left untouched. Sub-range safe; merge the minima.
ViewMinima measure_objects(std::span<float> distance, std::span<float> area,
                           std::span<const uint8_t> visible, std::span<const float> cx,
                           std::span<const float> cy, std::span<const float> cz,
                           std::span<const float> radius, const glm::vec3& eye, float focal_px);

// weight[i] = d / S for visible objects. Sub-range safe. Returns the count weighted.
size_t importance_weights(std::span<float> weight, std::span<const uint8_t> visible,
                          std::span<const float> distance, std::span<const float> area,
                          const ViewMinima& minima);

}  // namespace lod
