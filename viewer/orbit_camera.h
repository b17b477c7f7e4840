// OrbitCamera: turns around a target point (drag to rotate, wheel to zoom), for looking at
// the scene, or at a frozen LOD result, from outside.
#pragma once
#include <glm/glm.hpp>

#include "runtime/view.h"

namespace lod::viewer {

class OrbitCamera {
 public:
  // Keeps `view`'s eye, orbiting around its target.
  void look_like(const View& view);
  void rotate(float dx_pixels, float dy_pixels);
  void zoom(float wheel_steps);  // positive = closer
  View view(const View& lens) const;

  glm::vec3 target{0, 0, 0};
  float distance = 400;
  float azimuth = 0;      // radians about +y
  float elevation = 0.3f; // radians above the horizon
  float radians_per_pixel = 0.005f;

  glm::vec3 eye() const;
};

}  // namespace lod::viewer
