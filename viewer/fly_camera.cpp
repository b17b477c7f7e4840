#include "viewer/fly_camera.h"

#include <algorithm>
#include <cmath>

namespace lod::viewer {

namespace {
constexpr float kMaxPitch = 1.55f;  // just under pi/2
}

glm::vec3 FlyCamera::forward() const {
  return {std::cos(pitch) * std::sin(yaw), std::sin(pitch), -std::cos(pitch) * std::cos(yaw)};
}

void FlyCamera::look_like(const View& view) {
  position = view.eye;
  glm::vec3 d = view.target - view.eye;
  const float len = glm::length(d);
  if (!(len > 0)) return;  // keep the old direction for a degenerate view
  d /= len;
  pitch = std::clamp(std::asin(std::clamp(d.y, -1.f, 1.f)), -kMaxPitch, kMaxPitch);
  yaw = std::atan2(d.x, -d.z);
}

void FlyCamera::update(const FlyInput& input, float dt_seconds) {
  yaw += input.look_dx * mouse_radians_per_pixel;
  pitch = std::clamp(pitch - input.look_dy * mouse_radians_per_pixel, -kMaxPitch, kMaxPitch);
  const glm::vec3 f = forward();
  const glm::vec3 r = glm::normalize(glm::cross(f, glm::vec3(0, 1, 0)));
  position += (f * input.forward + r * input.right + glm::vec3(0, 1, 0) * input.up) * speed * dt_seconds;
}

View FlyCamera::view(const View& lens) const {
  View v = lens;
  v.eye = position;
  v.target = position + forward();
  v.up = {0, 1, 0};
  return v;
}

}  // namespace lod::viewer
