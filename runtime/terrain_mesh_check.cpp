#include "runtime/terrain_mesh_check.h"

#include <algorithm>
#include <cstdio>
#include <vector>

namespace lod {
namespace detail {

struct DirectedEdge {
  uint64_t from, to;
};

bool on_border(uint32_t a, uint32_t b, uint32_t size) {
  const uint32_t m = size - 1, ax = a % size, ay = a / size, bx = b % size, by = b / size;
  return (ax == bx && (ax == 0 || ax == m)) || (ay == by && (ay == 0 || ay == m));
}

void note(TerrainMeshCheck& c, std::string what) {
  if (c.first_problem.empty()) c.first_problem = std::move(what);
}

std::string edge_name(uint64_t a, uint64_t b, uint32_t size) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "edge (%u,%u)-(%u,%u)", unsigned(a % size), unsigned(a / size),
                unsigned(b % size), unsigned(b / size));
  return buf;
}

// Doubled signed areas in grid units, summed exactly in 64-bit integers.
int64_t doubled_area(uint32_t a, uint32_t b, uint32_t c, uint32_t size) {
  const int64_t ax = a % size, ay = a / size, bx = b % size, by = b / size, cx = c % size, cy = c / size;
  return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
}

// Sorted undirected edges: each must appear twice with opposite directions, or once on the border.
void check_edges(TerrainMeshCheck& c, std::vector<DirectedEdge>& edges, uint32_t size) {
  std::sort(edges.begin(), edges.end(), [](const DirectedEdge& x, const DirectedEdge& y) {
    const uint64_t kx = std::min(x.from, x.to) << 32 | std::max(x.from, x.to);
    const uint64_t ky = std::min(y.from, y.to) << 32 | std::max(y.from, y.to);
    return kx < ky;
  });
  for (size_t i = 0; i < edges.size();) {
    const uint64_t lo = std::min(edges[i].from, edges[i].to), hi = std::max(edges[i].from, edges[i].to);
    size_t j = i;
    while (j < edges.size() && std::min(edges[j].from, edges[j].to) == lo &&
           std::max(edges[j].from, edges[j].to) == hi)
      ++j;
    const size_t uses = j - i;
    if (uses == 1 && !on_border(uint32_t(lo), uint32_t(hi), size)) {
      ++c.open_edges;
      note(c, edge_name(lo, hi, size) + " is used by one triangle (crack or T-junction)");
    } else if (uses > 2 || (uses == 2 && edges[i].from == edges[i + 1].from)) {
      ++c.overshared_edges;
      note(c, edge_name(lo, hi, size) + " is used by " + std::to_string(uses) + " triangles");
    }
    i = j;
  }
}

}  // namespace detail

TerrainMeshCheck check_terrain_mesh(std::span<const uint32_t> indices, uint32_t size) {
  TerrainMeshCheck c;
  c.triangles = indices.size() / 3;
  const uint64_t samples = uint64_t(size) * size;
  std::vector<detail::DirectedEdge> edges;
  edges.reserve(indices.size());
  int64_t area = 0;
  for (size_t t = 0; t < c.triangles; ++t) {
    const uint32_t* v = &indices[3 * t];
    if (v[0] >= samples || v[1] >= samples || v[2] >= samples) {
      ++c.bad_indices;
      detail::note(c, "triangle " + std::to_string(t) + " indexes outside the grid");
      continue;
    }
    const int64_t a = detail::doubled_area(v[0], v[1], v[2], size);
    if (a <= 0) {
      ++c.flipped;
      detail::note(c, "triangle " + std::to_string(t) + " is clockwise or degenerate");
    }
    area += a;
    for (int k = 0; k < 3; ++k) edges.push_back({v[k], v[(k + 1) % 3]});
  }
  detail::check_edges(c, edges, size);
  const int64_t m = int64_t(size) - 1;
  c.covers_grid = area == 2 * m * m;
  if (!c.covers_grid) detail::note(c, "triangle areas do not add up to the grid's");
  return c;
}

}  // namespace lod
