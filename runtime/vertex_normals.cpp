// Area-weighted smooth vertex normals (runtime/vertex_normals.h).
#include "runtime/vertex_normals.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace lod {

namespace {

// Each face's cross product added to its three corners (restrict: the stores cannot change the
// positions, so the loads are not repeated after them).
void accumulate_face_normals(std::span<float> normals, std::span<const float> positions,
                             std::span<const uint32_t> indices) {
  float* __restrict out = normals.data();
  const float* __restrict p = positions.data();
  const uint32_t* __restrict idx = indices.data();
  const size_t n = indices.size() - indices.size() % 3;
  for (size_t t = 0; t < n; t += 3) {
    const size_t i0 = 3 * size_t(idx[t]), i1 = 3 * size_t(idx[t + 1]), i2 = 3 * size_t(idx[t + 2]);
    assert(std::max({i0, i1, i2}) + 2 < positions.size());
    const float ax = p[i0], ay = p[i0 + 1], az = p[i0 + 2];
    const float e0x = p[i1] - ax, e0y = p[i1 + 1] - ay, e0z = p[i1 + 2] - az;
    const float e1x = p[i2] - ax, e1y = p[i2 + 1] - ay, e1z = p[i2 + 2] - az;
    const float nx = e0y * e1z - e0z * e1y, ny = e0z * e1x - e0x * e1z, nz = e0x * e1y - e0y * e1x;
    out[i0] += nx, out[i0 + 1] += ny, out[i0 + 2] += nz;
    out[i1] += nx, out[i1 + 1] += ny, out[i1 + 2] += nz;
    out[i2] += nx, out[i2 + 1] += ny, out[i2 + 2] += nz;
  }
}

// Sums to unit length; a zero (or non-finite) sum stays (0, 0, 0).
uint32_t normalize_sums(std::span<float> normals) {
  uint32_t unit = 0;
  for (size_t v = 0; v + 2 < normals.size(); v += 3) {
    float* n = &normals[v];
    const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const bool usable = len > 0 && std::isfinite(len);
    for (int k = 0; k < 3; ++k) n[k] = usable ? n[k] / len : 0.f;
    unit += usable;
  }
  return unit;
}

}  // namespace

uint32_t area_weighted_normals(std::span<float> normals, std::span<const float> positions,
                               std::span<const uint32_t> indices) {
  assert(normals.size() == positions.size());
  std::fill(normals.begin(), normals.end(), 0.f);
  accumulate_face_normals(normals, positions, indices);
  return normalize_sums(normals);
}

uint32_t renormalise(std::span<float> normals) {
  uint32_t unit = 0;
  for (size_t v = 0; v + 2 < normals.size(); v += 3) {
    float* n = &normals[v];
    const float len2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    if (len2 > 0 && std::isfinite(len2)) {
      const float inv = 1.f / std::sqrt(len2);
      n[0] *= inv, n[1] *= inv, n[2] *= inv;
      ++unit;
    } else {
      n[0] = n[1] = n[2] = 0;
    }
  }
  return unit;
}

}  // namespace lod
