// Visibility: frustum test of world bounding spheres, and the maximum draw distance.
#pragma once
#include <cstddef>
#include <cstdint>
#include <span>

#include "runtime/view.h"

namespace lod {

// Writes visible[i] = 1 when sphere i touches the frustum, else 0; returns the count visible.
// Sub-ranges give the same result as the whole range, so callers may split it freely.
size_t cull_spheres(std::span<uint8_t> visible, std::span<const float> cx, std::span<const float> cy,
                    std::span<const float> cz, std::span<const float> radius, const Frustum& frustum);

// lod.max_distance: clears visible[i] for spheres whose nearest point is farther than
// `max_distance` from `eye` (those are not drawn). Returns how many visible ones it cleared.
// Sub-range safe.
size_t cull_beyond_distance(std::span<uint8_t> visible, std::span<const float> cx, std::span<const float> cy,
                            std::span<const float> cz, std::span<const float> radius, const glm::vec3& eye,
                            float max_distance);

}  // namespace lod
