// Motion paths in closed form.
#include "runtime/motion_path.h"

#include <cmath>
#include <numbers>

namespace lod {

namespace {

// Position at distance s from x0 moving right inside [lo, hi], bouncing: a triangle wave.
// Returns the position and whether the object is moving right at that point.
double bounce(double lo, double hi, double x0, double s, bool* right) {
  const double w = hi - lo;
  if (!(w > 0)) {
    *right = true;
    return lo;
  }
  double u = std::fmod(x0 - lo + s, 2 * w);
  if (u < 0) u += 2 * w;
  *right = u < w;
  return *right ? lo + u : hi - (u - w);
}

// A heading in [0, 2 pi) from a seed (splitmix64), the same on every platform.
double heading_of(uint64_t seed) {
  uint64_t z = seed + 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  z ^= z >> 31;
  return double(z >> 11) * 0x1.0p-53 * 2 * std::numbers::pi;
}

void set_yaw(Transform& t, double yaw) {
  t.rotation[0] = 0;
  t.rotation[1] = static_cast<float>(std::sin(0.5 * yaw));
  t.rotation[2] = 0;
  t.rotation[3] = static_cast<float>(std::cos(0.5 * yaw));
}

}  // namespace

Transform motion_at(const MotionSpec& m, const Transform& start, const float box_min[3], const float box_max[3],
                    uint64_t seed, double t) {
  Transform out = start;
  if (m.kind == MotionKind::none || !(m.speed > 0)) return out;
  if (m.kind == MotionKind::wander) {
    const double h = heading_of(seed);
    const double dx = std::cos(h), dz = std::sin(h), s = m.speed * t;
    bool rx = true, rz = true;
    // Moving left is moving right from the mirrored start.
    const double sx = dx >= 0 ? s * dx : -s * dx, sz = dz >= 0 ? s * dz : -s * dz;
    double x = dx >= 0 ? bounce(box_min[0], box_max[0], start.position[0], sx, &rx)
                       : box_min[0] + box_max[0] - bounce(box_min[0], box_max[0], box_min[0] + box_max[0] - start.position[0], sx, &rx);
    double z = dz >= 0 ? bounce(box_min[2], box_max[2], start.position[2], sz, &rz)
                       : box_min[2] + box_max[2] - bounce(box_min[2], box_max[2], box_min[2] + box_max[2] - start.position[2], sz, &rz);
    const double vx = (dx >= 0) == rx ? std::abs(dx) : -std::abs(dx);
    const double vz = (dz >= 0) == rz ? std::abs(dz) : -std::abs(dz);
    out.position[0] = static_cast<float>(x);
    out.position[2] = static_cast<float>(z);
    // Model +z faces forward: yaw turns +z towards the velocity (R_y(yaw) (0,0,1) = (sin, 0, cos)).
    set_yaw(out, std::atan2(vx, vz));
    return out;
  }
  const double cx = 0.5 * (double(box_min[0]) + box_max[0]), cz = 0.5 * (double(box_min[2]) + box_max[2]);
  const double ox = start.position[0] - cx, oz = start.position[2] - cz;
  const double r = std::sqrt(ox * ox + oz * oz);
  if (r < 1e-6) return out;
  const double a = std::atan2(oz, ox) + m.speed * t / r;
  out.position[0] = static_cast<float>(cx + r * std::cos(a));
  out.position[2] = static_cast<float>(cz + r * std::sin(a));
  // Counter-clockwise in (x, z): the tangent is (-sin a, cos a).
  set_yaw(out, std::atan2(-std::sin(a), std::cos(a)));
  return out;
}

}  // namespace lod
