// Generated meshes for the view-dependent LOD tests and benchmarks: a closed UV sphere, an
// open bumpy grid, several components in one mesh, and 1-to-4 midpoint subdivision.
#pragma once
#include <cmath>
#include <cstdint>
#include <map>
#include <utility>

#include "preprocess/mesh.h"

namespace lod::test {

// Closed UV sphere with one vertex per pole; `rings` >= 2, `segments` >= 3.
inline MeshData vd_sphere(int rings, int segments, float radius = 1, float cx = 0, float cy = 0,
                          float cz = 0) {
  MeshData m;
  m.source = "sphere";
  auto put = [&](float x, float y, float z) {
    m.positions.push_back(cx + radius * x);
    m.positions.push_back(cy + radius * y);
    m.positions.push_back(cz + radius * z);
  };
  put(0, 1, 0);
  for (int r = 1; r < rings; ++r) {
    const double th = M_PI * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double ph = 2 * M_PI * s / segments;
      put(float(std::sin(th) * std::cos(ph)), float(std::cos(th)), float(std::sin(th) * std::sin(ph)));
    }
  }
  put(0, -1, 0);
  const uint32_t south = static_cast<uint32_t>(m.vertex_count() - 1);
  auto ring = [&](int r, int s) { return uint32_t(1 + (r - 1) * segments + (s % segments)); };
  auto face = [&](uint32_t a, uint32_t b, uint32_t c) {
    m.indices.push_back(a);
    m.indices.push_back(b);
    m.indices.push_back(c);
  };
  for (int s = 0; s < segments; ++s) face(0u, ring(1, s + 1), ring(1, s));
  for (int r = 1; r + 1 < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      face(ring(r, s), ring(r, s + 1), ring(r + 1, s + 1));
      face(ring(r, s), ring(r + 1, s + 1), ring(r + 1, s));
    }
  for (int s = 0; s < segments; ++s) face(south, ring(rings - 1, s), ring(rings - 1, s + 1));
  return m;
}

// Open grid of nx x ny quads in the xz plane (y up), with gentle bumps so quadrics differ.
inline MeshData vd_grid(int nx, int ny, float size = 1, float ox = 0, float oz = 0) {
  MeshData m;
  m.source = "grid";
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      const float x = size * i / nx, z = size * j / ny;
      m.positions.insert(m.positions.end(),
                         {ox + x, 0.05f * size * std::sin(7 * x / size) * std::cos(5 * z / size), oz + z});
    }
  auto id = [&](int i, int j) { return uint32_t(j * (nx + 1) + i); };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      m.indices.insert(m.indices.end(), {id(i, j), id(i, j + 1), id(i + 1, j + 1)});
      m.indices.insert(m.indices.end(), {id(i, j), id(i + 1, j + 1), id(i + 1, j)});
    }
  return m;
}

// b appended to a as another component.
inline MeshData vd_concat(MeshData a, const MeshData& b) {
  const uint32_t base = static_cast<uint32_t>(a.vertex_count());
  a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
  for (uint32_t i : b.indices) a.indices.push_back(base + i);
  a.source = a.source + "+" + b.source;
  return a;
}

// 1-to-4 midpoint subdivision (topology and orientation kept; closed stays closed).
inline MeshData vd_subdivide(const MeshData& in) {
  MeshData m;
  m.source = in.source;
  m.positions = in.positions;
  std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
  auto midpoint = [&](uint32_t a, uint32_t b) {
    const auto key = a < b ? std::make_pair(a, b) : std::make_pair(b, a);
    auto it = mid.find(key);
    if (it != mid.end()) return it->second;
    const uint32_t id = static_cast<uint32_t>(m.vertex_count());
    for (int k = 0; k < 3; ++k)
      m.positions.push_back(0.5f * (in.positions[3 * a + k] + in.positions[3 * b + k]));
    mid.emplace(key, id);
    return id;
  };
  for (size_t f = 0; f < in.triangle_count(); ++f) {
    const uint32_t a = in.indices[3 * f], b = in.indices[3 * f + 1], c = in.indices[3 * f + 2];
    const uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
    m.indices.insert(m.indices.end(), {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca});
  }
  return m;
}

}  // namespace lod::test
