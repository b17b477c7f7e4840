// World bounds: each object's bounding sphere in world space from its transform and its
// model's object-space sphere. c_world = position + scale * rotate(q, c_model), r = scale * r_model,
// q normalised here (a zero quaternion counts as no rotation).
#pragma once
#include <cstdint>
#include <span>

#include "lodkit/types.hpp"
#include "runtime/lod_chain.h"

namespace lod {

// The sphere holding every level of a chain (coarser levels may bulge past level 0).
Sphere chain_sphere(const LodChain& chain);

// rotate(q, v) for a unit quaternion q = x y z w.
void rotate_by_quaternion(const float q[4], const float v[3], float out[3]);

// One object's world sphere.
Sphere world_sphere(const Transform& t, const Sphere& model_sphere);

// Sub-range safe: run it on chunks.
void world_spheres(std::span<float> cx, std::span<float> cy, std::span<float> cz, std::span<float> radius,
                   std::span<const Transform> transform, std::span<const uint32_t> model,
                   std::span<const Sphere> model_sphere);

}  // namespace lod
