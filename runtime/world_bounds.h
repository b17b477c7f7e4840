// World bounds: each object's bounding sphere in world space from its transform and its
// model's object-space sphere. c_world = position + scale * rotate(q, c_model), r = scale * r_model,
// q normalised here (a zero quaternion counts as no rotation).
#pragma once
#include <cstdint>

#include "lodkit/types.hpp"
#include "runtime/lod_chain.h"

namespace lod {

// The sphere holding every level of a chain (coarser levels may bulge past level 0).
Sphere chain_sphere(const LodChain& chain);

// rotate(q, v) for a unit quaternion q = x y z w.
void rotate_by_quaternion(const float q[4], const float v[3], float out[3]);

// The transform's rotation as a unit quaternion (a zero quaternion counts as no rotation).
void normalized_rotation(const Transform& t, float q[4]);

// One object's world sphere.
Sphere world_sphere(const Transform& t, const Sphere& model_sphere);

}  // namespace lod
