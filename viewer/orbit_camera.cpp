#include "viewer/orbit_camera.h"

#include <algorithm>
#include <cmath>

namespace lod::viewer {

namespace {
constexpr float kMaxElevation = 1.55f;
constexpr float kMinDistance = 0.01f;
constexpr float kMaxDistance = 1e7f;  // a wheel spun far stays finite
}  // namespace

glm::vec3 OrbitCamera::eye() const {
  const float c = std::cos(elevation);
  return target + distance * glm::vec3(c * std::sin(azimuth), std::sin(elevation), c * std::cos(azimuth));
}

void OrbitCamera::look_like(const View& view) {
  target = view.target;
  const glm::vec3 d = view.eye - view.target;
  distance = std::clamp(glm::length(d), kMinDistance, kMaxDistance);
  elevation = std::clamp(std::asin(std::clamp(d.y / distance, -1.f, 1.f)), -kMaxElevation, kMaxElevation);
  azimuth = std::atan2(d.x, d.z);
}

void OrbitCamera::rotate(float dx_pixels, float dy_pixels) {
  azimuth -= dx_pixels * radians_per_pixel;
  elevation = std::clamp(elevation + dy_pixels * radians_per_pixel, -kMaxElevation, kMaxElevation);
}

void OrbitCamera::zoom(float wheel_steps) {
  distance = std::clamp(distance * std::pow(0.9f, wheel_steps), kMinDistance, kMaxDistance);
}

View OrbitCamera::view(const View& lens) const {
  View v = lens;
  v.eye = eye();
  v.target = target;
  v.up = {0, 1, 0};
  return v;
}

}  // namespace lod::viewer
