// FlyCamera: first-person camera (WASD + mouse look); yaw about +y, pitch clamped short of
// the poles so the up vector stays valid.
#pragma once
#include <glm/glm.hpp>

#include "runtime/view.h"

namespace lod::viewer {

struct FlyInput {
  float forward = 0;  // -1..1 (W/S)
  float right = 0;    // -1..1 (D/A)
  float up = 0;       // -1..1 (E/Q)
  float look_dx = 0;  // mouse pixels
  float look_dy = 0;
};

class FlyCamera {
 public:
  // Takes position and direction from `view` (eye -> target).
  void look_like(const View& view);
  void update(const FlyInput& input, float dt_seconds);
  // `lens` gives fov, size and planes; eye/target/up are set from the camera.
  View view(const View& lens) const;

  glm::vec3 position{0, 0, 0};
  float yaw = 0;         // radians; 0 looks along -z
  float pitch = 0;       // radians
  float speed = 100;     // world units per second
  float mouse_radians_per_pixel = 0.003f;

  glm::vec3 forward() const;
};

}  // namespace lod::viewer
