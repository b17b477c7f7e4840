// Motion paths: where a moving instance is at time t, in closed form (no state, so any frame
// can be computed directly and 1 or N threads agree).
//   wander  straight at `speed` along a heading drawn from the object's seed, bouncing off the
//           walls of its box (a triangle wave per axis); faces where it goes
//   orbit   around the vertical axis through the box centre at its starting radius, `speed`
//           along the circle; faces along the tangent
#pragma once
#include <cstdint>

#include "lodkit/types.hpp"

namespace lod {

enum class MotionKind : uint8_t { none, wander, orbit };

struct MotionSpec {
  MotionKind kind = MotionKind::none;
  float speed = 0;  // world units per second
};

// `seed` picks the wander heading; box_min/box_max bound the wander (y is kept).
Transform motion_at(const MotionSpec& m, const Transform& start, const float box_min[3], const float box_max[3],
                    uint64_t seed, double t);

}  // namespace lod
