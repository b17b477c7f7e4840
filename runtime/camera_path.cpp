// Camera paths: the view at frame n depends on n alone, so runs are reproducible and a
// consumer can seek.
#include "runtime/camera_path.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>

namespace lod {

namespace {

// Phase in [0, 2 pi) of `frame` along a loop of `period` frames; double keeps long runs exact.
double loop_phase(uint32_t frame, uint32_t period) {
  const uint32_t p = period > 0 ? period : 1;
  return 2.0 * std::numbers::pi * static_cast<double>(frame % p) / static_cast<double>(p);
}

View orbit_view(const CameraPath& path, uint32_t frame) {
  const double a = loop_phase(frame, path.period_frames);
  View v = path.lens;
  v.eye = path.center + glm::vec3(static_cast<float>(path.radius * std::cos(a)), path.height_above,
                                  static_cast<float>(path.radius * std::sin(a)));
  v.target = path.center;
  return v;
}

View flythrough_view(const CameraPath& path, uint32_t frame) {
  // Lemniscate of Gerono: x = r sin t, z = r sin t cos t. Its tangent (r cos t, r cos 2t)
  // never vanishes, so the look direction is always defined.
  const double t = loop_phase(frame, path.period_frames);
  const double r = path.radius;
  View v = path.lens;
  v.eye = path.center + glm::vec3(static_cast<float>(r * std::sin(t)), path.height_above,
                                  static_cast<float>(r * std::sin(t) * std::cos(t)));
  const glm::vec3 tangent(static_cast<float>(std::cos(t)), 0.f, static_cast<float>(std::cos(2.0 * t)));
  v.target = v.eye + glm::normalize(tangent);
  return v;
}

View keyframe_view(const CameraPath& path, uint32_t frame) {
  const std::vector<CameraKeyframe>& keys = path.keyframes;
  View v = path.lens;
  assert(!keys.empty() && "a keyframes path needs at least one key");
  if (keys.empty()) return v;
  // First key after `frame`; the segment is [next - 1, next].
  const auto next = std::upper_bound(keys.begin(), keys.end(), frame,
                                     [](uint32_t f, const CameraKeyframe& k) { return f < k.frame; });
  if (next == keys.begin()) {
    v.eye = keys.front().position;
    v.target = keys.front().look_at;
  } else if (next == keys.end()) {
    v.eye = keys.back().position;
    v.target = keys.back().look_at;
  } else {
    const CameraKeyframe& a = *(next - 1);
    const CameraKeyframe& b = *next;
    if (frame == a.frame) {  // exactly on a key: no interpolation rounding
      v.eye = a.position;
      v.target = a.look_at;
    } else {
      const float t = static_cast<float>(frame - a.frame) / static_cast<float>(b.frame - a.frame);
      v.eye = glm::mix(a.position, b.position, t);
      v.target = glm::mix(a.look_at, b.look_at, t);
    }
  }
  return v;
}

// A view direction (nearly) parallel to the lens's up vector (a keyframe looking straight
// down or up) has no basis: glm::lookAt gave NaN planes and Service::set_view refuses it, so
// every frame saw 0 objects. Such views get the up vector front_view_of falls back to
// (perpendicular to the view direction), the same on every frame.
View with_stable_up(View v) {
  const glm::dvec3 d = glm::dvec3(v.target) - glm::dvec3(v.eye);
  const glm::dvec3 up(v.up);
  if (glm::length(d) == 0 || glm::length(up) == 0) return v;
  const glm::dvec3 f = glm::normalize(d);
  if (glm::length(glm::cross(f, glm::normalize(up))) >= 1e-3) return v;
  const glm::dvec3 right = glm::normalize(glm::cross(f, std::abs(f.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0)));
  v.up = glm::vec3(glm::cross(right, f));
  return v;
}

}  // namespace

View view_at(const CameraPath& path, uint32_t frame) {
  switch (path.kind) {
    case PathKind::orbit: return with_stable_up(orbit_view(path, frame));
    case PathKind::flythrough: return with_stable_up(flythrough_view(path, frame));
    case PathKind::keyframes: return with_stable_up(keyframe_view(path, frame));
  }
  return path.lens;
}

}  // namespace lod
