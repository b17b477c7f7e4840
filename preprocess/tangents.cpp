// Lengyel's tangent accumulation (see tangents.h), in double precision.
#include "preprocess/tangents.h"

#include <cmath>
#include <vector>

namespace lod {
namespace {

struct V3 {
  double x = 0, y = 0, z = 0;
};
V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V3 operator*(V3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double length(V3 a) { return std::sqrt(dot(a, a)); }
V3 load(const float* p, size_t i) { return {p[3 * i], p[3 * i + 1], p[3 * i + 2]}; }

V3 unit_normal(const float* normals, size_t v) {
  const V3 n = load(normals, v);
  const double len = length(n);
  return std::isfinite(len) && len > 1e-12 ? n * (1 / len) : V3{0, 0, 1};
}

// Any unit vector perpendicular to the unit n: n crossed with the axis least aligned with it.
V3 perpendicular(V3 n) {
  const V3 axis = std::fabs(n.x) < 0.6 ? V3{1, 0, 0} : (std::fabs(n.y) < 0.6 ? V3{0, 1, 0} : V3{0, 0, 1});
  const V3 t = cross(n, axis);
  return t * (1 / length(t));
}

}  // namespace

void compute_tangents(float* out, const float* positions, const float* normals, const float* uvs,
                      size_t vertex_count, const uint32_t* indices, size_t index_count) {
  std::vector<V3> du(vertex_count), dv(vertex_count);
  for (size_t t = 0; t + 2 < index_count; t += 3) {
    const uint32_t a = indices[t], b = indices[t + 1], c = indices[t + 2];
    const V3 e1 = load(positions, b) - load(positions, a), e2 = load(positions, c) - load(positions, a);
    const double u1 = double(uvs[2 * b]) - uvs[2 * a], v1 = double(uvs[2 * b + 1]) - uvs[2 * a + 1];
    const double u2 = double(uvs[2 * c]) - uvs[2 * a], v2 = double(uvs[2 * c + 1]) - uvs[2 * a + 1];
    const double det = u1 * v2 - u2 * v1;
    if (!std::isfinite(det) || std::fabs(det) < 1e-20) continue;  // no uv area: no direction
    const double r = 1 / det;
    const V3 s = (e1 * v2 - e2 * v1) * r;  // dP/du
    const V3 w = (e2 * u1 - e1 * u2) * r;  // dP/dv
    for (uint32_t v : {a, b, c}) du[v] = du[v] + s, dv[v] = dv[v] + w;
  }
  for (size_t v = 0; v < vertex_count; ++v) {
    const V3 n = unit_normal(normals, v);
    V3 t = du[v] - n * dot(n, du[v]);
    const double len = length(t);
    t = std::isfinite(len) && len > 1e-12 * (1 + length(du[v])) ? t * (1 / len) : perpendicular(n);
    // Up the image is decreasing v (origin top left), so the bitangent runs along -dP/dv.
    const double handed = dot(cross(n, t), dv[v] * -1.0);
    out[4 * v] = float(t.x);
    out[4 * v + 1] = float(t.y);
    out[4 * v + 2] = float(t.z);
    out[4 * v + 3] = handed < 0 ? -1.0f : 1.0f;
  }
}

}  // namespace lod
