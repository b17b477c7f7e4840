// Synthetic HLOD trees for selection and streaming tests: boxes, bounds, layer errors,
// triangle counts and payload sizes, no geometry (the selection never reads any).
#pragma once
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "runtime/hlod_tree.h"

namespace lod::test {

struct OctreeSpec {
  uint32_t depth = 4;         // levels below the root
  float half = 64;            // root cell half edge
  float root_error = 8;       // the root's coarsest error; halves per depth
  uint32_t triangles = 1000;  // finest layer of every node; then 1/2, 1/4
  uint64_t bytes_per_triangle = 64;
};

inline void set_layers(HlodNode& n, uint32_t triangles, const float errors[3], uint32_t count) {
  n.layer_count = uint8_t(count);
  for (uint32_t l = 0; l < count; ++l) {
    n.layers[l].triangles = triangles >> l;
    n.layers[l].vertices = (triangles >> l) / 2 + 3;
    n.layers[l].error = errors[l];
  }
}

inline void place_child(HlodNode& c, const HlodNode& p, uint32_t octant) {
  c.box_half = p.box_half / 2;
  for (int k = 0; k < 3; ++k)
    c.box_center[k] = p.box_center[k] + ((octant >> k) & 1 ? c.box_half : -c.box_half);
  for (int k = 0; k < 3; ++k) c.bounds.center[k] = c.box_center[k];
  c.bounds.radius = c.box_half * std::sqrt(3.0f);
  c.depth = uint8_t(p.depth + 1);
}

inline void set_payload(HlodNode& n, uint64_t bytes_per_triangle) {
  uint64_t t = n.boundary_triangles;
  for (uint32_t l = 0; l < n.layer_count; ++l) t += n.layers[l].triangles;
  n.resident_bytes = n.payload_size = t * bytes_per_triangle;
}

// A full octree over a cube centred at the origin, breadth-first; a node at depth k has
// layer errors root_error * 2^-k * {1/2, 3/4, 1} (leaves: {0, ...}), so every node's
// finest error equals its children's coarsest (monotonic up the tree). Children's bounds
// nest in their parent's.
inline HlodTree full_octree(const OctreeSpec& spec) {
  HlodTree t;
  t.name = "octree";
  t.box_half = spec.half;
  HlodNode root;
  root.box_half = spec.half;
  root.bounds.radius = spec.half * std::sqrt(3.0f);
  t.nodes.push_back(root);
  for (size_t i = 0; i < t.nodes.size(); ++i) {
    if (t.nodes[i].depth == spec.depth) continue;
    t.nodes[i].first_child = uint32_t(t.nodes.size());
    t.nodes[i].child_count = 8;
    t.nodes[i].child_mask = 0xff;
    for (uint32_t o = 0; o < 8; ++o) {
      HlodNode c;
      place_child(c, t.nodes[i], o);
      c.parent = int32_t(i);
      t.nodes.push_back(c);
    }
  }
  for (HlodNode& n : t.nodes) {
    const float e = spec.root_error / float(1u << n.depth);
    const float errors[3] = {n.leaf() ? 0.0f : e / 2, 3 * e / 4, e};
    set_layers(n, spec.triangles, errors, 3);
    n.boundary_triangles = n.leaf() ? 0 : spec.triangles / 8;
    set_payload(n, spec.bytes_per_triangle);
  }
  return t;
}

// A random octree: random non-empty octants, random depth, 1-3 layers, errors monotonic up
// the tree (a node's finest >= its children's coarsest), bounds that bulge past the cell.
inline HlodTree random_octree(uint32_t seed, uint32_t max_nodes = 800, uint32_t max_depth = 5) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, 1);
  HlodTree t;
  t.name = "random";
  t.box_half = 32;
  HlodNode root;
  root.box_half = 32;
  root.bounds.radius = 32 * std::sqrt(3.0f) * (0.8f + 0.4f * u(rng));
  t.nodes.push_back(root);
  std::vector<float> finest{4 + 8 * u(rng)};  // the finest error each node allows its children
  for (size_t i = 0; i < t.nodes.size(); ++i) {
    HlodNode& n = t.nodes[i];
    const bool split =
        n.depth < max_depth && t.nodes.size() + 8 < max_nodes && (n.depth < 2 || u(rng) < 0.6f);
    uint32_t count = 1 + rng() % 3;
    float errors[3];
    float e = finest[i] * (0.3f + 0.7f * u(rng));
    for (int l = int(count) - 1; l >= 0; --l, e *= 0.3f + 0.7f * u(rng)) errors[l] = e;
    if (!split && u(rng) < 0.5f) errors[0] = 0;
    set_layers(n, 50 + rng() % 2000, errors, count);
    if (!split) {
      set_payload(n, 16 + rng() % 64);
      continue;
    }
    const uint32_t mask = 1 + rng() % 255;
    n.child_mask = uint8_t(mask);
    n.first_child = uint32_t(t.nodes.size());
    n.boundary_triangles = rng() % 200;
    set_payload(n, 16 + rng() % 64);
    const HlodNode parent = n;  // push_back below may move n
    for (uint32_t o = 0; o < 8; ++o) {
      if (!(mask >> o & 1)) continue;
      HlodNode c;
      place_child(c, parent, o);
      c.bounds.radius *= 0.8f + 0.4f * u(rng);
      c.parent = int32_t(i);
      t.nodes.push_back(c);
      finest.push_back(errors[0]);
      ++t.nodes[i].child_count;
    }
  }
  return t;
}

}  // namespace lod::test
