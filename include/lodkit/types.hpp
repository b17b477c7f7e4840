// lodkit's public value types: handles, transforms, per-object options, cameras.
// Plain structs of floats and integers, laid out exactly like their C twins in lodkit.h.
#pragma once
#include <cstdint>

namespace lod {

// An object: generation (high 32 bits) and slot (low 32 bits). 0 is never a valid handle;
// a destroyed object's handle is refused forever after (until 2^32 reuses of its slot).
using ObjectHandle = uint64_t;
// A model (one baked LOD chain), numbered from 0 in the order models were added.
using ModelId = uint32_t;

inline constexpr uint32_t kMaxViews = 8;

// The vertical field of view a Camera may have, degrees, both ends included. Culling is
// exact over the whole range (and for far_z up to float's limit); a view outside it is refused.
inline constexpr float kMinFovYDeg = 0.001f;
inline constexpr float kMaxFovYDeg = 179.0f;

// World placement of an object: p_world = position + scale * rotate(rotation, p_model).
struct Transform {
  float position[3] = {0, 0, 0};
  float rotation[4] = {0, 0, 0, 1};  // quaternion x y z w; used normalised, given back in frames as set
  float scale = 1;                   // uniform, > 0
};

// Per-object control; the defaults leave the object to the budget.
struct ObjectOptions {
  float lod_bias = 0;          // the object tolerates pixel_error * 2^lod_bias (+1: coarser, -1: finer)
  uint8_t min_level = 0;       // finest level allowed (0 = full detail)
  uint8_t max_level = 255;     // coarsest level allowed (clamped to the model's last level)
  float priority = 1;          // > 0; importance is divided by it: 4 keeps detail longer under M
  int16_t forced_level = -1;   // >= 0: always this level (clamped to the chain), still counted in M
  bool never_cull = false;     // visible to every view whatever its frustum (e.g. shadow casters)
};

// One view of a frame. forward need not be normalised; up must not be parallel to it.
struct Camera {
  float eye[3] = {0, 0, 0};
  float forward[3] = {0, 0, -1};
  float up[3] = {0, 1, 0};
  float fov_y_deg = 60;       // [kMinFovYDeg, kMaxFovYDeg] = [0.001, 179]
  uint32_t width = 1280;      // pixels; projected areas and screen-space errors use them
  uint32_t height = 720;
  float near_z = 0.5f;        // 0 < near_z < far_z, far_z finite
  float far_z = 5000.f;
};

}  // namespace lod
