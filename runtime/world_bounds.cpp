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

void normalized_rotation(const Transform& t, float q[4]) {
  const float len2 = t.rotation[0] * t.rotation[0] + t.rotation[1] * t.rotation[1] + t.rotation[2] * t.rotation[2] +
                     t.rotation[3] * t.rotation[3];
  const float inv = len2 > 0 ? 1.0f / std::sqrt(len2) : 0.0f;
  for (int k = 0; k < 3; ++k) q[k] = t.rotation[k] * inv;
  q[3] = len2 > 0 ? t.rotation[3] * inv : 1.0f;
}

Sphere world_sphere(const Transform& t, const Sphere& s) {
  float q[4];
  normalized_rotation(t, q);
  float c[3];
  rotate_by_quaternion(q, s.center, c);
  Sphere w;
  for (int k = 0; k < 3; ++k) w.center[k] = t.position[k] + t.scale * c[k];
  w.radius = s.radius * t.scale;
  return w;
}

}  // namespace lod
