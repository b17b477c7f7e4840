// Frustum culling of bounding spheres: a sphere is visible unless it lies entirely on the
// outer side of one of the six normalized planes. Conservative near frustum corners (a sphere
// just outside two planes at once may pass), which only costs a few extra objects.
#include "runtime/visibility.h"

#include <cassert>

namespace lod {

size_t cull_spheres(std::span<uint8_t> visible, std::span<const float> cx, std::span<const float> cy,
                    std::span<const float> cz, std::span<const float> radius, const Frustum& frustum) {
  const size_t n = visible.size();
  assert(cx.size() == n && cy.size() == n && cz.size() == n && radius.size() == n);
  // Planes in scalars so the loop body is straight-line arithmetic the compiler vectorizes;
  // testing all six planes without an early exit is cheaper than a branch per plane.
  float a[6], b[6], c[6], d[6];
  for (int p = 0; p < 6; ++p) {
    a[p] = frustum.planes[p].x;
    b[p] = frustum.planes[p].y;
    c[p] = frustum.planes[p].z;
    d[p] = frustum.planes[p].w;
  }
  const float* __restrict px = cx.data();
  const float* __restrict py = cy.data();
  const float* __restrict pz = cz.data();
  const float* __restrict pr = radius.data();
  uint8_t* __restrict out = visible.data();
  size_t count = 0;
  for (size_t i = 0; i < n; ++i) {
    const float x = px[i], y = py[i], z = pz[i], nr = -pr[i];
    const bool in0 = a[0] * x + b[0] * y + c[0] * z + d[0] >= nr;
    const bool in1 = a[1] * x + b[1] * y + c[1] * z + d[1] >= nr;
    const bool in2 = a[2] * x + b[2] * y + c[2] * z + d[2] >= nr;
    const bool in3 = a[3] * x + b[3] * y + c[3] * z + d[3] >= nr;
    const bool in4 = a[4] * x + b[4] * y + c[4] * z + d[4] >= nr;
    const bool in5 = a[5] * x + b[5] * y + c[5] * z + d[5] >= nr;
    const uint8_t v = static_cast<uint8_t>(in0 & in1 & in2 & in3 & in4 & in5);
    out[i] = v;
    count += v;
  }
  return count;
}

size_t cull_beyond_distance(std::span<uint8_t> visible, std::span<const float> cx, std::span<const float> cy,
                            std::span<const float> cz, std::span<const float> radius, const glm::vec3& eye,
                            float max_distance) {
  const size_t n = visible.size();
  assert(cx.size() == n && cy.size() == n && cz.size() == n && radius.size() == n && max_distance > 0);
  size_t cleared = 0;
  for (size_t i = 0; i < n; ++i) {
    const float dx = cx[i] - eye.x, dy = cy[i] - eye.y, dz = cz[i] - eye.z;
    // |c - eye| - r > D  <=>  |c - eye| > D + r (both sides >= 0): no square root.
    const float reach = max_distance + radius[i];
    const bool far = dx * dx + dy * dy + dz * dz > reach * reach;
    cleared += visible[i] & far;
    visible[i] = static_cast<uint8_t>(visible[i] & !far);
  }
  return cleared;
}

}  // namespace lod
