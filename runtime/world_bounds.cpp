// World bounds: one quaternion rotation per object.
#include "runtime/world_bounds.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace lod {

Sphere chain_sphere(const LodChain& chain) {
  Sphere s;
  if (chain.levels.empty()) return s;
  s = chain.levels[0].bounds;
  for (const LodLevel& l : chain.levels) {
    const float dx = l.bounds.center[0] - s.center[0];
    const float dy = l.bounds.center[1] - s.center[1];
    const float dz = l.bounds.center[2] - s.center[2];
    s.radius = std::max(s.radius, std::sqrt(dx * dx + dy * dy + dz * dz) + l.bounds.radius);
  }
  return s;
}

void rotate_by_quaternion(const float q[4], const float v[3], float out[3]) {
  // v' = v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z): 15 multiplies, no matrix.
  const float ux = q[0], uy = q[1], uz = q[2], w = q[3];
  const float tx = 2 * (uy * v[2] - uz * v[1]);
  const float ty = 2 * (uz * v[0] - ux * v[2]);
  const float tz = 2 * (ux * v[1] - uy * v[0]);
  out[0] = v[0] + w * tx + (uy * tz - uz * ty);
  out[1] = v[1] + w * ty + (uz * tx - ux * tz);
  out[2] = v[2] + w * tz + (ux * ty - uy * tx);
}

Sphere world_sphere(const Transform& t, const Sphere& s) {
  const float len2 = t.rotation[0] * t.rotation[0] + t.rotation[1] * t.rotation[1] + t.rotation[2] * t.rotation[2] +
                     t.rotation[3] * t.rotation[3];
  const float inv = len2 > 0 ? 1.0f / std::sqrt(len2) : 0.0f;
  const float q[4] = {t.rotation[0] * inv, t.rotation[1] * inv, t.rotation[2] * inv,
                      len2 > 0 ? t.rotation[3] * inv : 1.0f};
  float c[3];
  rotate_by_quaternion(q, s.center, c);
  Sphere w;
  for (int k = 0; k < 3; ++k) w.center[k] = t.position[k] + t.scale * c[k];
  w.radius = s.radius * t.scale;
  return w;
}

void world_spheres(std::span<float> cx, std::span<float> cy, std::span<float> cz, std::span<float> radius,
                   std::span<const Transform> transform, std::span<const uint32_t> model,
                   std::span<const Sphere> model_sphere) {
  const size_t n = transform.size();
  assert(cx.size() == n && cy.size() == n && cz.size() == n && radius.size() == n && model.size() == n);
  for (size_t i = 0; i < n; ++i) {
    assert(model[i] < model_sphere.size());
    const Sphere w = world_sphere(transform[i], model_sphere[model[i]]);
    cx[i] = w.center[0], cy[i] = w.center[1], cz[i] = w.center[2], radius[i] = w.radius;
  }
}

}  // namespace lod
