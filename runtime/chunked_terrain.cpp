// Chunked LOD: building the quadtree's nested errors and boxes, selecting chunks per view.
#include "runtime/chunked_terrain.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace lod {
namespace {

struct Grid {
  const RoamTerrain& t;
  float h(uint32_t x, uint32_t y) const { return t.positions[size_t(y) * t.size + x].y; }
  const glm::vec3& p(uint32_t x, uint32_t y) const { return t.positions[size_t(y) * t.size + x]; }
};

// Height of the patch surface at sample (x, y): the cell of `step` holding it, split on its
// (x0, y0)-(x1, y1) diagonal, interpolated linearly on the triangle.
float patch_height(const Grid& g, const ChunkedTerrain::Node& n, uint32_t patch, uint32_t x, uint32_t y) {
  const uint32_t x0 = n.x0, y0 = n.y0, step = n.step;
  const uint32_t cx = x0 + std::min((x - x0) / step, patch - 1) * step;  // the far edge is the last cell's
  const uint32_t cy = y0 + std::min((y - y0) / step, patch - 1) * step;
  const float u = float(x - cx) / float(step), v = float(y - cy) / float(step);
  const float h00 = g.h(cx, cy), h11 = g.h(cx + step, cy + step);
  if (u >= v) return h00 + u * (g.h(cx + step, cy) - h00) + v * (h11 - g.h(cx + step, cy));
  return h00 + v * (g.h(cx, cy + step) - h00) + u * (h11 - g.h(cx, cy + step));
}

// The node's own error and box, from every full-resolution sample it covers.
void measure(const Grid& g, ChunkedTerrain::Node& n, uint32_t patch) {
  const uint32_t span = patch * n.step;
  n.lo = glm::vec3(INFINITY), n.hi = glm::vec3(-INFINITY);
  float err = 0;
  for (uint32_t y = n.y0; y <= n.y0 + span; ++y)
    for (uint32_t x = n.x0; x <= n.x0 + span; ++x) {
      const glm::vec3& p = g.p(x, y);
      n.lo = glm::min(n.lo, p), n.hi = glm::max(n.hi, p);
      if (n.step > 1) err = std::max(err, std::abs(p.y - patch_height(g, n, patch, x, y)));
    }
  n.error = err;
}

void build(const Grid& g, ChunkedTerrain& c, uint32_t index) {
  measure(g, c.nodes[index], c.patch);
  const ChunkedTerrain::Node n = c.nodes[index];
  if (n.step == 1) return;
  const int32_t first = int32_t(c.nodes.size());
  c.nodes[index].first_child = first;
  const uint32_t half = c.patch * n.step / 2;
  for (uint32_t k = 0; k < 4; ++k) {
    ChunkedTerrain::Node child;
    child.x0 = n.x0 + (k & 1) * half, child.y0 = n.y0 + (k >> 1) * half, child.step = n.step / 2;
    c.nodes.push_back(child);
  }
  for (uint32_t k = 0; k < 4; ++k) {
    build(g, c, uint32_t(first) + k);
    ChunkedTerrain::Node& parent = c.nodes[index];
    parent.error = std::max(parent.error, c.nodes[size_t(first) + k].error);  // nested
  }
}

bool box_outside(const Frustum& f, const glm::vec3& lo, const glm::vec3& hi) {
  for (const glm::vec4& pl : f.planes) {
    const glm::vec3 n(pl);
    const glm::vec3 far(n.x >= 0 ? hi.x : lo.x, n.y >= 0 ? hi.y : lo.y, n.z >= 0 ? hi.z : lo.z);
    if (glm::dot(n, far) + pl.w < 0) return true;
  }
  return false;
}

struct Selector {
  const ChunkedTerrain& c;
  Frustum frustum;
  glm::vec3 eye;
  float focal, near_plane, tau;
  std::vector<uint32_t>& out;

  void visit(uint32_t i) {
    const ChunkedTerrain::Node& n = c.nodes[i];
    if (box_outside(frustum, n.lo, n.hi)) return;
    const float d = glm::length(glm::max(glm::max(n.lo - eye, eye - n.hi), glm::vec3(0)));
    const float projected = n.error * focal / std::max(d, near_plane);
    if (n.first_child < 0 || projected <= tau) {
      out.push_back(i);
      return;
    }
    for (int32_t k = 0; k < 4; ++k) visit(uint32_t(n.first_child + k));
  }
};

}  // namespace

bool chunked_size_valid(uint32_t size, uint32_t patch) {
  if (size < 2 || patch == 0 || (size - 1) % patch) return false;
  const uint32_t n = (size - 1) / patch;
  return (n & (n - 1)) == 0;
}

ChunkedTerrain build_chunked_terrain(const RoamTerrain& terrain, uint32_t patch) {
  assert(chunked_size_valid(terrain.size, patch));
  ChunkedTerrain c;
  c.patch = patch;
  c.size = terrain.size;
  ChunkedTerrain::Node root;
  root.step = (terrain.size - 1) / patch;
  c.nodes.push_back(root);
  build(Grid{terrain}, c, 0);
  return c;
}

ChunkedSelection select_chunks(std::vector<uint32_t>& out, const ChunkedTerrain& chunked, const View& view,
                               float pixel_error) {
  out.clear();
  Selector s{chunked, frustum_of(view), view.eye, focal_pixels(view), view.near_plane, pixel_error, out};
  s.visit(0);
  ChunkedSelection sel;
  sel.chunks = uint32_t(out.size());
  sel.triangles = uint64_t(sel.chunks) * chunk_triangles(chunked.patch);
  sel.skirt_triangles = uint64_t(sel.chunks) * 8 * chunked.patch;
  return sel;
}

}  // namespace lod
