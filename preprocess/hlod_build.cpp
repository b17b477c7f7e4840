// Model HLOD build (Zhou and Tian 3.1) in three steps, each node computed the same whichever
// step it falls in:
//
//   (a) plan: the root's cell, then the top of the octree split down to the frontier
//   (b) per frontier subtree, bottom-up (subtrees and children in parallel): count -> split
//       (children + patch) -> [children] -> layer 0 (leaf geometry, or children's coarsest
//       welded to the patch) -> two QEM halvings with ancestors' patch vertices locked ->
//       reference samples, bounds (beside it, the original's BVH); then each layer's distance
//       to the original; errors made monotonic; records and payloads (an HlodSubtree)
//   (c) the top's nodes the same way from the subtrees' roots, then the breadth-first splice.
//
// Per-vertex scratch arrays are shared by the tasks without locks: every vertex lies in
// exactly one cell per depth, tasks run on disjoint subtrees, and a node only touches its own
// cell's vertices after its children have finished, so no two tasks ever touch one vertex.
// An ancestor's patch (all the lock test `patch_depth < depth` sees) is always split before.
#include "preprocess/hlod_build.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <memory>
#include <mutex>
#include <ctime>
#include <string>

#include "preprocess/decimater_chain.h"  // compute_vertex_normals
#include "preprocess/material_runs.h"
#include "preprocess/surface_error.h"
#include "runtime/bytes_hasher.h"
#include "runtime/hlod_asset.h"  // hlod_resident_bytes
#include "runtime/lod_chain.h"

namespace lod {
namespace {

constexpr uint8_t kNoPatch = 0xff;

// The calling thread's CPU time (the BVH is built on one thread of the caller's: a report of
// where a bake's time goes, on machines shared with other work).
double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

struct Layer {
  std::vector<float> positions;
  std::vector<float> attributes;  // Attributes::count per vertex (uv, uv1, colour as the mesh has them)
  std::vector<uint32_t> indices;
  std::vector<uint32_t> source;  // original vertex each vertex descends from
  float error = 0;
  size_t triangles() const { return indices.size() / 3; }
  size_t vertices() const { return source.size(); }
};

struct BuildNode {
  uint8_t depth = 0;
  float center[3] = {0, 0, 0};
  float half = 0;
  std::vector<uint32_t> triangles;  // original triangles in the cell and in no ancestor's patch
  std::unique_ptr<BuildNode> children[8];
  int32_t subtree = -1;             // a frontier node: which subtree it roots (-1: none)
  uint8_t child_mask = 0;
  std::vector<uint32_t> patch;      // original triangles across the children
  std::vector<Layer> layers;        // finest first
  std::vector<uint32_t> reference;  // original vertices of the node's region, thinned
  Sphere bounds;
  bool leaf() const { return child_mask == 0; }
};

// Counted per subtree (the report sums them), from any thread.
struct Tally {
  std::atomic<size_t> short_layers{0};
  std::atomic<size_t> oversized_leaves{0};
};

// The vertex attributes QEM carries, interleaved per vertex in this order: uv (TEXCOORD_0), uv1
// (TEXCOORD_1), RGBA colour (COLOR_0), each only when the mesh has it (as the .lod bake's).
struct Attributes {
  static constexpr size_t kNone = SIZE_MAX;
  size_t uv = kNone, uv1 = kNone, color = kNone;
  size_t count = 0;
  bool has(size_t at) const { return at != kNone; }
};

Attributes attribute_layout(const MeshView& mesh) {
  Attributes a;
  if (!mesh.uvs.empty()) a.uv = a.count, a.count += 2;
  if (!mesh.uvs1.empty()) a.uv1 = a.count, a.count += 2;
  if (!mesh.colors.empty()) a.color = a.count, a.count += 4;
  return a;
}

// What a node's layers are measured against: a part of the original near the node, and the
// whole original for a query the part cannot answer as it would (built on first need).
struct Queries {
  const SurfaceDistance* part = nullptr;
  std::function<const SurfaceDistance*()> whole;
};

struct Context {
  const HlodBuildOptions& options;
  const float* positions = nullptr;
  const uint32_t* indices = nullptr;
  Attributes layout;
  const float* attributes = nullptr;   // of the original, layout.count per vertex, or null
  std::vector<float> interleaved;      // what `attributes` points to when the mesh has more than one
  std::vector<int32_t> vertex_material;  // of the original, per vertex; empty without materials
  std::vector<float> normals;          // of the original, per vertex
  std::vector<uint8_t> patch_depth;    // shallowest depth whose patch holds the vertex
  std::vector<uint32_t> stamp;         // per vertex: which node last visited it
  std::vector<uint32_t> local;         // per vertex: its index in that node's arrays
  std::atomic<uint32_t> next_stamp{1};
  SurfaceDistance original;  // the whole original, when a query needs it (rarely: see Queries)
  uint64_t total_triangles = 0;
  std::atomic<uint64_t> done_triangles{0};

  explicit Context(const HlodBuildOptions& o) : options(o) {}
  uint32_t new_stamp() { return next_stamp.fetch_add(1, std::memory_order_relaxed); }
};

int octant(const Context& c, const BuildNode& n, uint32_t v) {
  const float* p = c.positions + 3 * size_t(v);
  return (p[0] >= n.center[0] ? 1 : 0) | (p[1] >= n.center[1] ? 2 : 0) | (p[2] >= n.center[2] ? 4 : 0);
}

// Distinct vertices of `triangles`, counted only up to one above `enough` (all a split needs:
// the root of a 14M-triangle scan would otherwise count 42M corners at every level of the top).
size_t count_vertices(Context& c, const std::vector<uint32_t>& triangles, size_t enough) {
  const uint32_t s = c.new_stamp();
  size_t count = 0;
  for (uint32_t t : triangles) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = c.indices[3 * size_t(t) + k];
      if (c.stamp[v] != s) c.stamp[v] = s, ++count;
    }
    if (count > enough) break;
  }
  return count;
}

// Triangles within one octant go to that child, the others to the patch. false (nothing
// changed) when every triangle crosses octants: the node stays a leaf.
bool split_node(Context& c, BuildNode& n) {
  // Each triangle's octant (kPatch: it crosses octants) first, so each part is allocated once.
  constexpr uint8_t kPatch = 8;
  std::vector<uint8_t> where(n.triangles.size());
  size_t count[9] = {};
  for (size_t i = 0; i < n.triangles.size(); ++i) {
    const uint32_t* f = c.indices + 3 * size_t(n.triangles[i]);
    const int o = octant(c, n, f[0]);
    where[i] = octant(c, n, f[1]) == o && octant(c, n, f[2]) == o ? uint8_t(o) : kPatch;
    ++count[where[i]];
  }
  if (count[kPatch] == n.triangles.size()) return false;
  std::vector<uint32_t> part[9];
  for (int o = 0; o < 9; ++o) part[o].reserve(count[o]);
  for (size_t i = 0; i < n.triangles.size(); ++i) part[where[i]].push_back(n.triangles[i]);
  std::vector<uint32_t>& patch = part[kPatch];
  for (int o = 0; o < 8; ++o) {
    if (part[o].empty()) continue;
    auto child = std::make_unique<BuildNode>();
    child->depth = uint8_t(n.depth + 1);
    child->half = n.half / 2;
    for (int k = 0; k < 3; ++k) child->center[k] = n.center[k] + ((o >> k) & 1 ? child->half : -child->half);
    child->triangles = std::move(part[o]);
    n.children[o] = std::move(child);
    n.child_mask |= uint8_t(1u << o);
  }
  for (uint32_t t : patch)
    for (int k = 0; k < 3; ++k) {
      uint8_t& d = c.patch_depth[c.indices[3 * size_t(t) + k]];
      d = std::min(d, n.depth);
    }
  n.patch = std::move(patch);
  n.triangles.clear();
  n.triangles.shrink_to_fit();
  return true;
}

// Original vertex v appended to `layer` once per stamp `s`; returns its index there.
uint32_t take_original(Context& c, Layer& layer, uint32_t v, uint32_t s) {
  if (c.stamp[v] == s) return c.local[v];
  c.stamp[v] = s;
  c.local[v] = uint32_t(layer.vertices());
  layer.positions.insert(layer.positions.end(), c.positions + 3 * size_t(v), c.positions + 3 * size_t(v) + 3);
  const size_t n = c.layout.count;
  if (n) layer.attributes.insert(layer.attributes.end(), c.attributes + n * size_t(v), c.attributes + n * size_t(v) + n);
  layer.source.push_back(v);
  return c.local[v];
}

Layer leaf_geometry(Context& c, const BuildNode& n) {
  Layer layer;
  const uint32_t s = c.new_stamp();
  layer.indices.reserve(3 * n.triangles.size());
  for (uint32_t t : n.triangles)
    for (int k = 0; k < 3; ++k) layer.indices.push_back(take_original(c, layer, c.indices[3 * size_t(t) + k], s));
  return layer;
}

// The children's coarsest layers side by side, welded to the patch through the patch's
// vertices (locked in every child, so still at their original positions there).
Layer merged_children(Context& c, const BuildNode& n) {
  Layer layer;
  const uint32_t s = c.new_stamp();
  for (const auto& child : n.children) {
    if (!child) continue;
    const Layer& coarse = child->layers.back();
    const uint32_t base = uint32_t(layer.vertices());
    layer.positions.insert(layer.positions.end(), coarse.positions.begin(), coarse.positions.end());
    layer.attributes.insert(layer.attributes.end(), coarse.attributes.begin(), coarse.attributes.end());
    layer.source.insert(layer.source.end(), coarse.source.begin(), coarse.source.end());
    for (uint32_t i : coarse.indices) layer.indices.push_back(base + i);
    for (uint32_t i = 0; i < coarse.vertices(); ++i) {
      c.stamp[coarse.source[i]] = s;
      c.local[coarse.source[i]] = base + i;
    }
  }
  for (uint32_t t : n.patch)
    for (int k = 0; k < 3; ++k) layer.indices.push_back(take_original(c, layer, c.indices[3 * size_t(t) + k], s));
  return layer;
}

// The layer's triangles grouped by material (materials ascending, the default first; each
// material's in their previous order), before anything reads their order, so that a node's
// layers are the same whether its children were built in this step or stood in for by a baked
// subtree's root. A triangle's material is its first corner's original vertex's (a material
// boundary is a seam, so all three agree).
void group_layer(const Context& c, Layer& l) {
  if (c.vertex_material.empty()) return;
  std::vector<LevelSubmesh> runs;
  group_by_material(l.indices, l.source, c.vertex_material, 0, runs);
}

// Locks the tip of every tetrahedron glued into the surface: a vertex on exactly three faces
// whose three neighbours also form a face. QEM's link condition lets its collapse through,
// and the two faces it doubles are merged into one, opening an edge (non-manifold scans such
// as Stanford's buddha have them).
void lock_tetrahedron_tips(const Layer& l, std::vector<uint8_t>& lock) {
  const size_t nv = l.vertices(), nt = l.triangles();
  std::vector<uint32_t> first(nv + 1, 0);
  for (uint32_t i : l.indices) ++first[i + 1];
  for (size_t v = 0; v < nv; ++v) first[v + 1] += first[v];
  std::vector<uint32_t> fill(first.begin(), first.end() - 1), faces(3 * nt);
  for (uint32_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) faces[fill[l.indices[3 * t + k]]++] = t;
  auto has_corner = [&](uint32_t t, uint32_t w) {
    return l.indices[3 * t] == w || l.indices[3 * t + 1] == w || l.indices[3 * t + 2] == w;
  };
  for (size_t v = 0; v < nv; ++v) {
    if (first[v + 1] - first[v] != 3 || lock[v]) continue;
    std::array<uint32_t, 9> around;
    size_t n = 0;
    for (uint32_t i = first[v]; i < first[v + 1]; ++i)
      for (int k = 0; k < 3; ++k)
        if (const uint32_t w = l.indices[3 * faces[i] + k]; w != v) around[n++] = w;
    std::sort(around.begin(), around.begin() + n);
    if (std::unique(around.begin(), around.begin() + n) - around.begin() != 3) continue;
    // Is (a, b, c) a face? Look among a's faces.
    for (uint32_t i = first[around[0]]; i < first[around[0] + 1]; ++i)
      if (has_corner(faces[i], around[1]) && has_corner(faces[i], around[2])) lock[v] = 1;
  }
}

// Two halvings of layers[0] with every ancestor's patch vertex locked; a layer no smaller than
// the one before is dropped.
void simplify_layers(Context& c, Tally& tally, BuildNode& n) {
  n.layers.reserve(3);  // `finest` stays valid while the coarser layers are appended
  const Layer& finest = n.layers[0];
  const size_t t0 = finest.triangles();
  if (t0 < 2) return;
  std::vector<uint8_t> lock(finest.vertices());
  for (size_t i = 0; i < lock.size(); ++i) lock[i] = c.patch_depth[finest.source[i]] < n.depth;
  lock_tetrahedron_tips(finest, lock);
  QemOptions options;
  options.lock_border = true;  // the mesh's own holes keep their outline in every layer
  // Non-manifold vertices stay too: moving one can open an edge that a patch or a neighbour
  // meets (Stanford's buddha: 80-150 open edges per cut otherwise).
  options.move_nonmanifold = false;
  options.vertex_lock = lock.data();
  // Texture coordinates and colours ride along (interpolated along each collapse, weighted in its
  // cost); seams, uv, colour or material, are copies at one position, moved only along the seam.
  if (c.layout.count)
    options.attributes = finest.attributes.data(), options.attribute_count = c.layout.count,
    options.attribute_weight = c.options.uv_weight;
  // Heavily locked cells otherwise reach their halves by ruinous collapses (on the bunny at
  // min_verts 500, one layer 10 % of the model off its surface, which the monotonic errors
  // then carry to the root).
  options.max_error = c.options.max_error_per_cell * 2 * n.half;
  const size_t targets[2] = {t0 / 2, t0 / 4};
  ChainLevelOut out[2];
  const size_t made = qem_simplify_chain(out, finest.positions.data(), finest.vertices(), finest.indices.data(),
                                         finest.indices.size(), targets, targets[1] > 0 ? 2 : 1, options);
  for (size_t k = 0; k < made; ++k) {
    const size_t tris = out[k].triangle_count();
    if (tris == 0 || tris >= n.layers.back().triangles()) {
      tally.short_layers.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    Layer layer;
    layer.positions = std::move(out[k].positions);
    if (c.layout.count) layer.attributes = std::move(out[k].attributes);
    layer.indices = std::move(out[k].indices);
    layer.source.resize(out[k].source_vertex.size());
    const Layer& from = n.layers[0];
    for (size_t i = 0; i < layer.source.size(); ++i) layer.source[i] = from.source[out[k].source_vertex[i]];
    group_layer(c, layer);
    n.layers.push_back(std::move(layer));
  }
}

// `ids` evenly thinned to at most `cap`, in order.
std::vector<uint32_t> thinned(std::vector<uint32_t> ids, size_t cap) {
  const size_t n = ids.size();
  if (n <= cap) return ids;
  std::vector<uint32_t> out(cap);
  for (size_t k = 0; k < cap; ++k) out[k] = ids[k * n / cap];
  return out;
}

// The node's original region, sampled: a leaf's own vertices; an inner node's children's
// samples and its patch's vertices.
void gather_reference(Context& c, BuildNode& n) {
  std::vector<uint32_t> ids;
  if (n.leaf()) {
    ids = n.layers[0].source;
  } else {
    for (const auto& child : n.children)
      if (child) ids.insert(ids.end(), child->reference.begin(), child->reference.end());
    for (uint32_t t : n.patch)
      for (int k = 0; k < 3; ++k) ids.push_back(c.indices[3 * size_t(t) + k]);
  }
  n.reference = thinned(std::move(ids), c.options.reference_samples);
}

float distance_to_original(const Context& c, const float* p, uint32_t v) {
  const float* o = c.positions + 3 * size_t(v);
  const double dx = p[0] - o[0], dy = p[1] - o[1], dz = p[2] - o[2];
  return float(std::sqrt(dx * dx + dy * dy + dz * dz));
}

// The node's original samples, each with a distance the layer is known to be within: to the
// layer vertex descended from it, when it survived into the layer. (A sorted lookup, not the
// per-vertex scratch: nodes are measured in any order, ancestors beside descendants.)
void reference_samples(const Context& c, const std::vector<uint32_t>& reference, const Layer& layer, std::vector<float>& points,
                       std::vector<float>& known) {
  std::vector<std::pair<uint32_t, uint32_t>> by_source(layer.vertices());
  for (uint32_t i = 0; i < layer.vertices(); ++i) by_source[i] = {layer.source[i], i};
  std::sort(by_source.begin(), by_source.end());
  points.resize(3 * reference.size());
  known.resize(reference.size());
  for (size_t k = 0; k < reference.size(); ++k) {
    const uint32_t v = reference[k];
    for (int j = 0; j < 3; ++j) points[3 * k + j] = c.positions[3 * size_t(v) + j];
    const auto it = std::lower_bound(by_source.begin(), by_source.end(), std::make_pair(v, 0u));
    known[k] = it != by_source.end() && it->first == v
                   ? distance_to_original(c, &layer.positions[3 * size_t(it->second)], v)
                   : INFINITY;
  }
}

// A layer's own samples: every vertex, then the centroids of an even subset of its triangles.
// Each comes with a distance the original surface is known to be within (to the original
// vertex it, or its triangle's nearest corner, descends from), so that its closest-point
// query starts small.
size_t layer_centroids(const Context& c, size_t tris) {
  return std::min(tris, size_t(std::ceil(double(c.options.layer_samples_per_triangle) * double(tris))));
}

void layer_samples(const Context& c, const Layer& layer, std::vector<float>& points, std::vector<float>& known) {
  points = layer.positions;
  known.resize(layer.vertices());
  for (size_t i = 0; i < layer.vertices(); ++i) known[i] = distance_to_original(c, &layer.positions[3 * i], layer.source[i]);
  const size_t tris = layer.triangles();
  const size_t centroids = layer_centroids(c, tris);
  for (size_t k = 0; k < centroids; ++k) {
    const uint32_t* f = &layer.indices[3 * (k * tris / centroids)];
    float p[3];
    for (int j = 0; j < 3; ++j)
      p[j] = (layer.positions[3 * size_t(f[0]) + j] + layer.positions[3 * size_t(f[1]) + j] + layer.positions[3 * size_t(f[2]) + j]) / 3;
    points.insert(points.end(), p, p + 3);
    float bound = INFINITY;
    for (int j = 0; j < 3; ++j) bound = std::min(bound, distance_to_original(c, p, layer.source[f[j]]));
    known.push_back(bound);
  }
}

// The layer's samples to the whole original surface (through the part: the same distances).
Status layer_to_original(const Context& c, const Queries& q, const Layer& layer, float& max) {
  std::vector<float> samples, known;
  layer_samples(c, layer, samples, known);
  SurfaceError e;
  const Status s = q.part->from_points_part(samples.data(), samples.size() / 3, known.data(), q.whole, e, nullptr);
  max = e.max;
  return s;
}

// The node's original samples to the layer (its own BVH, on any surface's Embree device).
Status original_to_layer(const Context& c, const SurfaceDistance& device, const std::vector<uint32_t>& reference,
                         const Layer& layer, float& max) {
  const TriangleMeshView view{layer.positions.data(), layer.vertices(), layer.indices.data(), layer.indices.size()};
  std::vector<float> samples, known;
  reference_samples(c, reference, layer, samples, known);
  SurfaceError e;
  const Status s = device.from_points_to(view, samples.data(), samples.size() / 3, known.data(), e);
  max = e.max;
  return s;
}

// Symmetric distance between a layer and the original: the layer's samples to the whole
// original surface, the node's original samples to the layer.
Status measure_layer(const Context& c, const Queries& q, const std::vector<uint32_t>& reference, const Layer& layer,
                     float& error) {
  float to = 0, from = 0;
  if (Status s = layer_to_original(c, q, layer, to); !s) return s;
  if (Status s = original_to_layer(c, *q.part, reference, layer, from); !s) return s;
  error = std::max(to, from);
  return Status::success();
}

void report_done(Context& c, const BuildNode& n) {
  const uint64_t mine = n.leaf() ? n.layers[0].triangles() : n.patch.size();
  const uint64_t done = c.done_triangles.fetch_add(mine, std::memory_order_relaxed) + mine;
  // Every node reports twice (built, measured): the fraction counts both passes.
  if (c.options.progress) c.options.progress(float(double(done) / double(std::max<uint64_t>(1, 2 * c.total_triangles))));
}

// Pass 2, any node in any order: each layer's own distance to the original (a leaf's layer 0
// is the original itself).
Status measure_layers(Context& c, const Queries& q, BuildNode& n) {
  for (size_t k = n.leaf() ? 1 : 0; k < n.layers.size(); ++k)
    if (Status s = measure_layer(c, q, n.reference, n.layers[k], n.layers[k].error); !s) return s;
  report_done(c, n);
  return Status::success();
}

// Pass 3, children before parents: never below the finer layer, and an inner node never
// below any child's coarsest layer.
void make_errors_monotonic(const std::vector<BuildNode*>& breadth_first) {
  for (size_t i = breadth_first.size(); i-- > 0;) {
    BuildNode& n = *breadth_first[i];
    float floor = 0;
    for (const auto& child : n.children)
      if (child) floor = std::max(floor, child->layers.back().error);
    for (Layer& layer : n.layers) floor = layer.error = std::max(layer.error, floor);
  }
}

// A sphere around every vertex the node draws, grown over its children's spheres.
Sphere node_bounds(const BuildNode& n) {
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (const Layer& l : n.layers)
    for (size_t i = 0; i < l.positions.size(); i += 3)
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], l.positions[i + k]), hi[k] = std::max(hi[k], l.positions[i + k]);
  Sphere s;
  for (int k = 0; k < 3; ++k) s.center[k] = 0.5f * (lo[k] + hi[k]);
  double r2 = 0;
  for (const Layer& l : n.layers)
    for (size_t i = 0; i < l.positions.size(); i += 3) {
      double d2 = 0;
      for (int k = 0; k < 3; ++k) d2 += double(l.positions[i + k] - s.center[k]) * (l.positions[i + k] - s.center[k]);
      r2 = std::max(r2, d2);
    }
  double r = std::sqrt(r2);
  for (const auto& child : n.children) {
    if (!child) continue;
    double d2 = 0;
    for (int k = 0; k < 3; ++k) d2 += double(child->bounds.center[k] - s.center[k]) * (child->bounds.center[k] - s.center[k]);
    r = std::max(r, std::sqrt(d2) + child->bounds.radius);
  }
  s.radius = float(r * (1 + 1e-6));
  return s;
}


// The octree's rule: a cell with more than min_verts vertices splits, unless it is at the
// depth limit or every one of its triangles crosses its octants.
bool split_if_large(Context& c, BuildNode& n, size_t& vertices) {
  vertices = count_vertices(c, n.triangles, c.options.min_verts);
  return vertices > c.options.min_verts && n.depth < kHlodMaxDepth && split_node(c, n);
}

// A node's own layers once its children (if any) have theirs: layer 0, two halvings, its
// reference samples and bounds.
void build_layers(Context& c, Tally& tally, BuildNode& n) {
  n.layers.push_back(n.leaf() ? leaf_geometry(c, n) : merged_children(c, n));
  group_layer(c, n.layers[0]);
  simplify_layers(c, tally, n);
  gather_reference(c, n);
  n.bounds = node_bounds(n);
  report_done(c, n);
}

void run_all(const ParallelFor& parallel_for, size_t count, const std::function<void(size_t)>& body) {
  if (parallel_for && count > 1) parallel_for(count, body);
  else for (size_t i = 0; i < count; ++i) body(i);
}

std::vector<BuildNode*> children_of(BuildNode& n) {
  std::vector<BuildNode*> kids;
  for (auto& child : n.children)
    if (child) kids.push_back(child.get());
  return kids;
}

// Pass 1 below a frontier node: the octree and every layer, bottom-up, children in parallel.
void grow(Context& c, Tally& tally, BuildNode& n) {
  size_t vertices = 0;
  if (split_if_large(c, n, vertices)) {
    const std::vector<BuildNode*> kids = children_of(n);
    run_all(c.options.parallel_for, kids.size(), [&](size_t i) { grow(c, tally, *kids[i]); });
  } else if (vertices > c.options.min_verts) {
    tally.oversized_leaves.fetch_add(1, std::memory_order_relaxed);
  }
  build_layers(c, tally, n);
}

// Breadth-first from `root`, children in octant order; with stop_at_frontier, the top only
// (frontier nodes below the root neither listed nor entered).
enum class Below : uint8_t { everything, stop_at_frontier };
std::vector<BuildNode*> breadth_first(BuildNode& root, Below below) {
  std::vector<BuildNode*> order{&root};
  if (below == Below::stop_at_frontier && root.subtree >= 0) return {};
  for (size_t i = 0; i < order.size(); ++i)
    for (auto& child : order[i]->children)
      if (child && !(below == Below::stop_at_frontier && child->subtree >= 0)) order.push_back(child.get());
  return order;
}

// Pass 2 over `nodes` at once, then pass 3 (children before parents).
Status measure_and_order_errors(Context& c, const Queries& q, const std::vector<BuildNode*>& nodes) {
  std::vector<Status> measured(nodes.size());
  run_all(c.options.parallel_for, nodes.size(), [&](size_t i) { measured[i] = measure_layers(c, q, *nodes[i]); });
  for (const Status& s : measured)
    if (!s) return s;
  make_errors_monotonic(nodes);
  return Status::success();
}


// Per-vertex normals of a layer from its own triangles, except where the vertex is an
// original one shared with a neighbour (locked): there the original normal, so both sides
// shade alike.
enum class Normals : uint8_t { own_except_locked, original };  // a leaf's layer 0 is the original

void layer_normals(const Context& c, const BuildNode& n, const Layer& l, Normals which, std::vector<float>& out) {
  const size_t base = out.size();
  out.resize(base + l.positions.size());
  compute_vertex_normals(l.positions.data(), l.vertices(), l.indices.data(), l.indices.size(), out.data() + base);
  for (size_t i = 0; i < l.vertices(); ++i)
    if (which == Normals::original || c.patch_depth[l.source[i]] < n.depth)
      for (int k = 0; k < 3; ++k) out[base + 3 * i + k] = c.normals[3 * size_t(l.source[i]) + k];
}

// One attribute (at `at`, `per` floats a vertex) of interleaved `attributes`, appended to `out`.
void append_column(const Attributes& a, const std::vector<float>& attributes, size_t at, size_t per, std::vector<float>& out) {
  if (!a.has(at)) return;
  const size_t n = attributes.size() / a.count;
  out.reserve(out.size() + per * n);
  for (size_t v = 0; v < n; ++v) out.insert(out.end(), &attributes[a.count * v + at], &attributes[a.count * v + at] + per);
}

void append_range(const Context& c, HlodPayload& p, const std::vector<float>& positions,
                  const std::vector<float>& attributes, const std::vector<uint32_t>& indices, LodLevel& range) {
  range.first_index = uint32_t(p.indices.size());
  range.index_count = uint32_t(indices.size());
  range.first_vertex = uint32_t(p.positions.size() / 3);
  range.vertex_count = uint32_t(positions.size() / 3);
  range.level = level_of_triangles(indices.size() / 3);
  p.positions.insert(p.positions.end(), positions.begin(), positions.end());
  append_column(c.layout, attributes, c.layout.uv, 2, p.uvs);
  append_column(c.layout, attributes, c.layout.uv1, 2, p.uvs1);
  append_column(c.layout, attributes, c.layout.color, 4, p.colors);
  p.indices.insert(p.indices.end(), indices.begin(), indices.end());
}

// Range `range`'s material runs, from its grouped triangles.
void append_runs(const Context& c, const Layer& l, uint32_t range, HlodPayload& p) {
  if (c.vertex_material.empty()) return;
  std::vector<uint32_t> grouped = l.indices;  // already grouped: the order stays
  group_by_material(grouped, l.source, c.vertex_material, range, p.runs);
}

// How far one attribute (at `at`, `per` floats) of a layer's vertices slid from that of the
// original vertices they descend from, at most (Euclidean: texture units for uvs, linear RGBA
// for colours); 0 when the mesh has none.
float attribute_error(const Context& c, const Layer& l, size_t at, size_t per) {
  if (!c.layout.has(at)) return 0.0f;
  const size_t n = c.layout.count;
  float worst = 0;
  for (size_t i = 0; i < l.vertices(); ++i) {
    const float* from = c.attributes + n * size_t(l.source[i]) + at;
    const float* mine = &l.attributes[n * i + at];
    if (per == 2) {  // uvs: as the tree measured them before it carried colours (same bytes)
      worst = std::max(worst, std::hypot(mine[0] - from[0], mine[1] - from[1]));
      continue;
    }
    double d2 = 0;
    for (size_t k = 0; k < per; ++k) d2 += double(mine[k] - from[k]) * double(mine[k] - from[k]);
    worst = std::max(worst, float(std::sqrt(d2)));
  }
  return worst;
}

HlodPayload make_payload(Context& c, const BuildNode& n) {
  HlodPayload p;
  for (size_t k = 0; k < n.layers.size(); ++k) {
    const Layer& l = n.layers[k];
    LodLevel range;
    append_range(c, p, l.positions, l.attributes, l.indices, range);
    append_runs(c, l, uint32_t(k), p);
    range.error = l.error;
    range.bounds = n.bounds;
    layer_normals(c, n, l, n.leaf() && k == 0 ? Normals::original : Normals::own_except_locked, p.normals);
    p.layers.push_back(range);
  }
  Layer patch;  // the patch with vertices of its own, originals
  const uint32_t s = c.new_stamp();
  for (uint32_t t : n.patch)
    for (int k = 0; k < 3; ++k) patch.indices.push_back(take_original(c, patch, c.indices[3 * size_t(t) + k], s));
  group_layer(c, patch);
  append_range(c, p, patch.positions, patch.attributes, patch.indices, p.boundary);
  append_runs(c, patch, uint32_t(n.layers.size()), p);
  p.boundary.bounds = n.bounds;
  for (uint32_t v : patch.source) p.normals.insert(p.normals.end(), &c.normals[3 * size_t(v)], &c.normals[3 * size_t(v)] + 3);
  return p;
}


// A node's record (parent and first_child left to the caller) and its payload.
HlodNode describe_node(Context& c, const BuildNode& b, HlodPayload& payload) {
  HlodNode h;
  h.depth = b.depth;
  for (int k = 0; k < 3; ++k) h.box_center[k] = b.center[k];
  h.box_half = b.half;
  h.bounds = b.bounds;
  h.child_mask = b.child_mask;
  h.child_count = uint8_t(std::popcount(unsigned(b.child_mask)));
  h.boundary_triangles = uint32_t(b.patch.size());
  h.layer_count = uint8_t(b.layers.size());
  for (size_t k = 0; k < b.layers.size(); ++k)
    h.layers[k] = {uint32_t(b.layers[k].triangles()), uint32_t(b.layers[k].vertices()), b.layers[k].error,
                   attribute_error(c, b.layers[k], c.layout.uv, 2), attribute_error(c, b.layers[k], c.layout.uv1, 2),
                   attribute_error(c, b.layers[k], c.layout.color, 4)};
  payload = make_payload(c, b);
  h.boundary_vertices = payload.boundary.vertex_count;
  h.uvs = c.layout.has(c.layout.uv);
  h.uvs1 = c.layout.has(c.layout.uv1);
  h.colors = c.layout.has(c.layout.color);
  h.material_runs = uint32_t(payload.runs.size());
  h.resident_bytes = hlod_resident_bytes(h);
  return h;
}

// A baked subtree (breadth-first `order` from its root) as records and payloads.
HlodSubtree flatten_subtree(Context& c, const std::vector<BuildNode*>& order) {
  HlodSubtree s;
  s.nodes.resize(order.size());
  s.payloads.resize(order.size());
  uint32_t next = 1;
  for (size_t i = 0; i < order.size(); ++i) {
    HlodNode h = describe_node(c, *order[i], s.payloads[i]);
    h.parent = s.nodes[i].parent;  // set by the parent, below
    h.first_child = h.child_count ? next : 0;
    for (uint32_t k = 0; k < h.child_count; ++k) s.nodes[next + k].parent = int32_t(i);
    next += h.child_count;
    s.nodes[i] = h;
  }
  const BuildNode& root = *order[0];
  s.material_count = uint32_t(c.options.surfaces.materials.size());
  s.root_source = root.layers.back().source;
  s.root_reference = root.reference;
  return s;
}

// What a frontier node is to the levels above once its subtree is baked: its coarsest layer,
// reference samples and bounds, as the subtree's root had them.
void stand_for_subtree(const Context& c, BuildNode& n, const HlodSubtree& s) {
  for (auto& child : n.children) child.reset();
  n.child_mask = 0;
  std::vector<uint32_t>().swap(n.triangles);
  std::vector<uint32_t>().swap(n.patch);
  const HlodNode& root = s.nodes[0];
  const LodLevel& range = s.payloads[0].layers.back();
  Layer coarse;
  const auto* p = s.payloads[0].positions.data() + 3 * size_t(range.first_vertex);
  coarse.positions.assign(p, p + 3 * size_t(range.vertex_count));
  // The payload's columns interleaved again (check_subtree checked they are the mesh's).
  const size_t a = c.layout.count;
  coarse.attributes.resize(a * size_t(range.vertex_count));
  auto take = [&](size_t at, size_t per, const std::vector<float>& column) {
    if (!c.layout.has(at)) return;
    for (size_t v = 0; v < range.vertex_count; ++v)
      std::copy_n(&column[per * (size_t(range.first_vertex) + v)], per, &coarse.attributes[a * v + at]);
  };
  take(c.layout.uv, 2, s.payloads[0].uvs);
  take(c.layout.uv1, 2, s.payloads[0].uvs1);
  take(c.layout.color, 4, s.payloads[0].colors);
  const auto* i = s.payloads[0].indices.data() + range.first_index;
  coarse.indices.assign(i, i + range.index_count);
  coarse.source = s.root_source;
  coarse.error = root.layers[root.layer_count - 1].error;
  n.layers.clear();
  n.layers.push_back(std::move(coarse));
  n.reference = s.root_reference;
  n.bounds = root.bounds;
}

// A subtree result is checked against the mesh before any of it is used as an index.
Status check_subtree(const BuildNode& f, const HlodSubtree& s, size_t vertices, const Attributes& layout,
                     uint32_t materials, const std::string& what) {
  const bool uvs = layout.has(layout.uv), uvs1 = layout.has(layout.uv1), colors = layout.has(layout.color);
  if (s.nodes.empty() || s.payloads.empty() || (s.payloads.size() != 1 && s.payloads.size() != s.nodes.size()))
    return Status::error(what + ": no nodes, or neither the root's payload alone nor one payload per node");
  const HlodNode& root = s.nodes[0];
  if (root.uvs != uvs) return Status::error(what + ": it was baked " + (uvs ? "without" : "with") + " texture coordinates");
  if (root.uvs1 != uvs1) return Status::error(what + ": it was baked " + (uvs1 ? "without" : "with") + " TEXCOORD_1");
  if (root.colors != colors) return Status::error(what + ": it was baked " + (colors ? "without" : "with") + " vertex colours");
  if (root.depth != f.depth || root.box_half != f.half || root.box_center[0] != f.center[0] ||
      root.box_center[1] != f.center[1] || root.box_center[2] != f.center[2])
    return Status::error(what + ": its root is not the frontier node's cell");
  const HlodPayload& p = s.payloads[0];
  if (root.layer_count < 1 || p.layers.size() != root.layer_count) return Status::error(what + ": root layers do not match its record");
  const LodLevel& range = p.layers.back();
  const size_t pv = p.positions.size() / 3;
  if (p.uvs.size() != (uvs ? 2 * pv : 0) || p.uvs1.size() != (uvs1 ? 2 * pv : 0) || p.colors.size() != (colors ? 4 * pv : 0) ||
      s.material_count != materials)
    return Status::error(what + ": its texture coordinates, colours or materials are not the mesh's");
  if (s.root_source.size() != range.vertex_count || size_t(range.first_vertex) + range.vertex_count > p.positions.size() / 3 ||
      size_t(range.first_index) + range.index_count > p.indices.size())
    return Status::error(what + ": root's coarsest layer does not match its vertex sources");
  for (size_t k = 0; k < range.index_count; ++k)
    if (p.indices[range.first_index + k] >= range.vertex_count) return Status::error(what + ": root layer index out of range");
  for (uint32_t v : s.root_source)
    if (v >= vertices) return Status::error(what + ": vertex source " + std::to_string(v) + " is not in the mesh");
  for (uint32_t v : s.root_reference)
    if (v >= vertices) return Status::error(what + ": reference vertex " + std::to_string(v) + " is not in the mesh");
  return Status::success();
}

// Breadth-first order of the whole tree (children of one node contiguous, in octant order), as
// the file stores it: the top's nodes described here, each subtree's spliced in from its result.
struct NodeRef {
  const BuildNode* top = nullptr;  // else a subtree's node
  const HlodSubtree* subtree = nullptr;
  uint32_t local = 0;
};

// The top's payloads are made here; a subtree node's stays with its subtree (origin says where).
void splice(Context& c, BuildNode& root, const std::vector<HlodSubtree>& baked, HlodAssembly& out,
            HlodBuildReport& report) {
  auto ref_of = [&](const BuildNode& n) {
    return n.subtree >= 0 ? NodeRef{nullptr, &baked[size_t(n.subtree)], 0} : NodeRef{&n, nullptr, 0};
  };
  std::vector<NodeRef> order{ref_of(root)};
  std::vector<int32_t> parent{-1};
  out.model.tree.nodes.clear();
  out.model.payloads.clear();
  out.origin.clear();
  for (size_t i = 0; i < order.size(); ++i) {
    const NodeRef r = order[i];
    HlodNode h;
    HlodPayload payload;
    HlodAssembly::Origin origin;
    if (r.top) {
      h = describe_node(c, *r.top, payload);
      for (const auto& child : r.top->children)
        if (child) order.push_back(ref_of(*child));
    } else {
      h = r.subtree->nodes[r.local];
      origin = {int32_t(r.subtree - baked.data()), r.local};
      for (uint32_t k = 0; k < h.child_count; ++k) order.push_back({nullptr, r.subtree, h.first_child + k});
    }
    h.parent = parent[i];
    h.first_child = h.child_count ? uint32_t(order.size() - h.child_count) : 0;
    h.payload_offset = h.payload_size = 0;
    parent.resize(order.size(), int32_t(i));
    report.leaves += h.leaf();
    report.depth = std::max<uint32_t>(report.depth, h.depth);
    report.boundary_triangles += h.boundary_triangles;
    out.model.tree.nodes.push_back(h);
    out.model.payloads.push_back(std::move(payload));
    out.origin.push_back(origin);
  }
  report.nodes = order.size();
}


Status check_input(const MeshView& mesh) {
  const std::string what = mesh.source.empty() ? std::string("mesh") : std::string(mesh.source);
  if (mesh.vertex_count() >= UINT32_MAX) return Status::error(what + ": more than 2^32 - 1 vertices");
  if (mesh.indices.size() % 3 != 0) return Status::error(what + ": index count is not a multiple of 3");
  for (size_t i = 0; i < mesh.positions.size(); ++i)
    if (!std::isfinite(mesh.positions[i]))
      return Status::error(what + ": vertex " + std::to_string(i / 3) + " has a non-finite coordinate");
  if (!mesh.uvs.empty() && mesh.uvs.size() != 2 * mesh.vertex_count())
    return Status::error(what + ": " + std::to_string(mesh.uvs.size() / 2) + " texture coordinates for " +
                         std::to_string(mesh.vertex_count()) + " vertices");
  for (size_t i = 0; i < mesh.uvs.size(); ++i)
    if (!std::isfinite(mesh.uvs[i]))
      return Status::error(what + ": vertex " + std::to_string(i / 2) + " has a non-finite texture coordinate");
  if (!mesh.uvs1.empty() && mesh.uvs1.size() != 2 * mesh.vertex_count())
    return Status::error(what + ": " + std::to_string(mesh.uvs1.size() / 2) + " TEXCOORD_1 values for " +
                         std::to_string(mesh.vertex_count()) + " vertices");
  for (size_t i = 0; i < mesh.uvs1.size(); ++i)
    if (!std::isfinite(mesh.uvs1[i]))
      return Status::error(what + ": vertex " + std::to_string(i / 2) + " has a non-finite TEXCOORD_1");
  if (!mesh.colors.empty() && mesh.colors.size() != 4 * mesh.vertex_count())
    return Status::error(what + ": " + std::to_string(mesh.colors.size() / 4) + " vertex colours for " +
                         std::to_string(mesh.vertex_count()) + " vertices");
  for (size_t i = 0; i < mesh.colors.size(); ++i)
    if (!std::isfinite(mesh.colors[i]))
      return Status::error(what + ": vertex " + std::to_string(i / 4) + " has a non-finite colour");
  for (size_t i = 0; i < mesh.indices.size(); ++i)
    if (mesh.indices[i] >= mesh.vertex_count())
      return Status::error(what + ": face " + std::to_string(i / 3) + " references vertex " +
                           std::to_string(mesh.indices[i]) + " of " + std::to_string(mesh.vertex_count()));
  return Status::success();
}

// The root cell: the cube around the used vertices' box.
void root_cell(const MeshView& mesh, const std::vector<uint32_t>& triangles, BuildNode& root) {
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (uint32_t t : triangles)
    for (int k = 0; k < 3; ++k) {
      const float* p = &mesh.positions[3 * size_t(mesh.indices[3 * size_t(t) + k])];
      for (int j = 0; j < 3; ++j) lo[j] = std::min(lo[j], p[j]), hi[j] = std::max(hi[j], p[j]);
    }
  float extent = 0;
  for (int j = 0; j < 3; ++j) root.center[j] = 0.5f * (lo[j] + hi[j]), extent = std::max(extent, hi[j] - lo[j]);
  root.half = extent > 0 ? 0.5f * extent * (1 + 1e-5f) : 1.0f;
}


// The frontier (see the header's rule): the heaviest node above the limit splits by the
// octree's rule until none is left; a node the rule keeps whole stays on the frontier.
void split_top(Context& c, BuildNode& root, uint32_t subtrees) {
  const uint64_t limit = c.total_triangles / std::max<uint32_t>(1, subtrees);
  std::vector<BuildNode*> frontier{&root};
  std::vector<uint8_t> whole{0};
  for (;;) {
    size_t pick = frontier.size();
    for (size_t i = 0; i < frontier.size(); ++i)
      if (!whole[i] && frontier[i]->triangles.size() > limit &&
          (pick == frontier.size() || frontier[i]->triangles.size() > frontier[pick]->triangles.size()))
        pick = i;
    if (pick == frontier.size()) return;
    BuildNode& n = *frontier[pick];
    size_t vertices = 0;
    if (!split_if_large(c, n, vertices)) {
      whole[pick] = 1;
      continue;
    }
    const std::vector<BuildNode*> kids = children_of(n);
    frontier.erase(frontier.begin() + std::ptrdiff_t(pick));
    whole.erase(whole.begin() + std::ptrdiff_t(pick));
    frontier.insert(frontier.end(), kids.begin(), kids.end());
    whole.insert(whole.end(), kids.size(), 0);
  }
}

// The frontier's nodes in depth-first (octant) order: the order a distributed build cuts into shares.
void frontier_depth_first(BuildNode& n, std::vector<BuildNode*>& out) {
  if (n.leaf()) {
    out.push_back(&n);
    return;
  }
  for (auto& child : n.children)
    if (child) frontier_depth_first(*child, out);
}

// The frontier nodes inside which a cut between the shares falls (in depth-first order; at
// `cuts`, fractions of the cost), those holding more than `fine` triangles and not kept whole.
std::vector<BuildNode*> nodes_at_cuts(const std::vector<BuildNode*>& frontier, const std::vector<double>& cuts,
                                      uint64_t fine, const std::vector<const BuildNode*>& kept) {
  uint64_t total = 0;
  for (const BuildNode* n : frontier) total += n->triangles.size();
  std::vector<BuildNode*> cut;
  uint64_t before = 0;
  for (BuildNode* n : frontier) {
    const uint64_t cost = n->triangles.size();
    // Is a cut strictly inside (before, before + cost)?
    const auto next = std::upper_bound(cuts.begin(), cuts.end(), double(before) / double(std::max<uint64_t>(1, total)));
    if (next != cuts.end() && *next * double(total) < double(before + cost) && cost > fine &&
        std::find(kept.begin(), kept.end(), n) == kept.end())
      cut.push_back(n);
    before += cost;
  }
  return cut;
}

// Equal shares' cuts: k / parts.
std::vector<double> equal_cuts(uint32_t parts) {
  std::vector<double> cuts;
  for (uint32_t k = 1; k < parts; ++k) cuts.push_back(double(k) / double(parts));
  return cuts;
}

// Where the frontier's depth-first order is cut into `parts` shares (a distributed build's
// ranks, each a contiguous run: jobs/hlod_distributed_bake.h), the subtree a cut falls in splits
// by the octree's rule until it holds under a 64th of a share: a few subtrees per part then
// still split evenly, and the top stays small (it grows with the subtree count).
void refine_at_cuts(Context& c, BuildNode& root, uint32_t parts, const std::vector<double>& unequal) {
  if (parts < 2) return;
  const uint64_t fine = c.total_triangles / (64 * uint64_t(parts));
  const std::vector<double> cuts = unequal.size() + 1 == parts ? unequal : equal_cuts(parts);
  std::vector<const BuildNode*> kept;  // leaves by the octree's rule
  for (;;) {
    std::vector<BuildNode*> frontier;
    frontier_depth_first(root, frontier);
    const std::vector<BuildNode*> cut = nodes_at_cuts(frontier, cuts, fine, kept);
    if (cut.empty()) return;
    for (BuildNode* n : cut)
      if (size_t vertices = 0; !split_if_large(c, *n, vertices)) kept.push_back(n);
  }
}

// Frontier nodes numbered in breadth-first order of the top (a top node is one split above).
std::vector<BuildNode*> number_frontier(BuildNode& root) {
  std::vector<BuildNode*> order{&root}, frontier;
  for (size_t i = 0; i < order.size(); ++i) {
    BuildNode& n = *order[i];
    if (n.leaf()) {
      n.subtree = int32_t(frontier.size());
      frontier.push_back(&n);
      continue;
    }
    for (auto& child : n.children)
      if (child) order.push_back(child.get());
  }
  return frontier;
}

HlodSubtreeSpec describe_subtree(const Context& c, const BuildNode& n) {
  HlodSubtreeSpec spec;
  spec.depth = n.depth;
  for (int k = 0; k < 3; ++k) spec.center[k] = n.center[k];
  spec.half = n.half;
  spec.triangles = n.triangles.size();
  // Hashed in pieces (the same value as over all the words at once): a 14M-triangle frontier
  // would otherwise stage 280 MB of words.
  BytesHasher h(0x4c4f4448'53554254ull);
  const uint32_t head[5] = {n.depth, std::bit_cast<uint32_t>(n.center[0]), std::bit_cast<uint32_t>(n.center[1]),
                            std::bit_cast<uint32_t>(n.center[2]), std::bit_cast<uint32_t>(n.half)};
  h.add(head, sizeof head);
  constexpr size_t kChunk = 1024;
  uint32_t words[5 * kChunk];
  for (size_t first = 0; first < n.triangles.size(); first += kChunk) {
    const size_t count = std::min(kChunk, n.triangles.size() - first);
    for (size_t i = 0; i < count; ++i) {
      const uint32_t t = n.triangles[first + i];
      uint32_t* w = words + 5 * i;
      w[0] = t;
      w[4] = 0;
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = c.indices[3 * size_t(t) + k];
        w[1 + k] = v;
        w[4] |= uint32_t(c.patch_depth[v] < n.depth) << k;
      }
    }
    h.add(words, 4 * 5 * count);
  }
  spec.fingerprint = h.finish();
  return spec;
}

// Frontier nodes' places in depth-first order of the top (octant order: a Morton order of cells).
void number_spatially(const BuildNode& n, std::vector<HlodSubtreeSpec>& specs, uint32_t& next) {
  if (n.subtree >= 0) {
    specs[size_t(n.subtree)].spatial = next++;
    return;
  }
  for (const auto& child : n.children)
    if (child) number_spatially(*child, specs, next);
}

// The grids parts of the original are chosen on, over the root cube: 256^3 cells where a part
// is chosen by flags (16 MB of them); 1024^3 for the subtrees' parts, chosen by box, so that a
// deep subtree's margin is not rounded up to a whole coarse cell (the parts' triangles then
// sum to ~1.15 times the mesh's, not ~1.3).
SurfaceGrid part_grid(const BuildNode& root, uint32_t n = 256) {
  SurfaceGrid g;
  for (int k = 0; k < 3; ++k) g.lo[k] = root.center[k] - root.half;
  g.edge = 2 * root.half;
  g.n = n;
  return g;
}

// Flags every cell the box [lo, hi] reaches into.
void want_box(const SurfaceGrid& g, const float* lo, const float* hi, std::vector<uint8_t>& wanted) {
  uint32_t a[3], b[3];
  for (int k = 0; k < 3; ++k) a[k] = g.cell(lo[k], k), b[k] = g.cell(hi[k], k);
  for (uint32_t z = a[2]; z <= b[2]; ++z)
    for (uint32_t y = a[1]; y <= b[1]; ++y)
      for (uint32_t x = a[0]; x <= b[0]; ++x) wanted[(size_t(z) * g.n + y) * g.n + x] = 1;
}

// A subtree's cell grown by a sixteenth of its half-edge: a layer's vertices are vertices of its
// cell's triangles, so its samples lie within a triangle of the cell, and their nearest points
// within the layer's error of them (~1 % of the cell). A query the part cannot answer exactly
// still goes to the whole.
SurfaceBox grown_cell(const HlodSubtreeSpec& spec, float grow) {
  SurfaceBox b;
  for (int k = 0; k < 3; ++k) b.lo[k] = spec.center[k] - grow * spec.half, b.hi[k] = spec.center[k] + grow * spec.half;
  return b;
}

// A part of the original and its vertex scratch, reused by one task after another: a build
// holds one part per task at a time, never a BVH of the whole original.
struct PartSlot {
  SurfaceDistance part;
  std::vector<uint32_t> remap;
};

class PartPool {
 public:
  std::unique_ptr<PartSlot> take() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (free_.empty()) return std::make_unique<PartSlot>();
    std::unique_ptr<PartSlot> slot = std::move(free_.back());
    free_.pop_back();
    return slot;
  }
  void give(std::unique_ptr<PartSlot> slot) {
    std::lock_guard<std::mutex> lock(mutex_);
    free_.push_back(std::move(slot));
  }
  // A part built before (ready, so its Embree device can build a layer's BVH), if any: valid
  // while no task takes parts from the pool.
  const SurfaceDistance* any() {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& slot : free_)
      if (slot->part.ready()) return &slot->part;
    return nullptr;
  }

 private:
  std::mutex mutex_;
  std::vector<std::unique_ptr<PartSlot>> free_;
};

// The frontier node whose cell holds p (-1: none, p in an empty octant of the top).
int subtree_at(const BuildNode& root, const float* p) {
  const BuildNode* n = &root;
  while (n->subtree < 0) {
    const int o = (p[0] >= n->center[0] ? 1 : 0) | (p[1] >= n->center[1] ? 2 : 0) | (p[2] >= n->center[2] ? 4 : 0);
    if (!n->children[size_t(o)]) return -1;
    n = n->children[size_t(o)].get();
  }
  return n->subtree;
}

}  // namespace

struct HlodBuilder::Impl {
  const MeshView mesh;
  std::string what;
  HlodBuildOptions options;  // a copy: Context keeps a reference, callers pass temporaries
  Context c;
  std::unique_ptr<BuildNode> root;
  std::vector<BuildNode*> frontier;
  std::vector<HlodSubtreeSpec> specs;
  std::vector<uint8_t> baked;  // per subtree: handed to bake_subtrees already
  size_t dropped = 0;
  bool planned = false, assembled = false;
  std::once_flag whole_once;
  std::atomic<bool> whole_built{false};
  Status surface;  // the whole original's BVH, once built
  double whole_cpu = 0;
  std::atomic<uint64_t> part_ns{0}, part_triangles{0};
  // Per subtree baked here, where its part's triangles are listed (plan, box): built again to
  // measure the top's samples in its cell (the top's finest layers cover the whole surface).
  std::vector<std::unique_ptr<SurfacePartPlan>> plans;
  std::vector<std::pair<int32_t, uint32_t>> part_of;
  std::vector<size_t> region;  // set_region: the subtrees whose cells' top samples it answers
  PartPool pool;
  Tally top_tally;

  Impl(const MeshView& m, const HlodBuildOptions& o)
      : mesh(m), what(m.source.empty() ? std::string("mesh") : std::string(m.source)), options(o), c(options) {}

  TriangleMeshView original() const {
    return {mesh.positions.data(), mesh.vertex_count(), mesh.indices.data(), mesh.indices.size()};
  }
  // The whole original's BVH, built once from whichever thread needs it first; null on failure.
  const SurfaceDistance* whole_surface() {
    std::call_once(whole_once, [this] {
      const double cpu0 = thread_cpu_seconds();
      surface = c.original.set_surface(original(), what);
      whole_cpu = thread_cpu_seconds() - cpu0;
      whole_built.store(true);
    });
    return surface ? &c.original : nullptr;
  }
  std::function<const SurfaceDistance*()> whole() {
    return [this] { return whole_surface(); };
  }
  void count_part(double cpu0, size_t triangles) {
    part_ns.fetch_add(uint64_t((thread_cpu_seconds() - cpu0) * 1e9), std::memory_order_relaxed);
    part_triangles.fetch_add(triangles, std::memory_order_relaxed);
  }
  // The parts of `subtrees` (those not planned yet) listed in one pass over the original.
  Status plan_parts(const std::vector<size_t>& subtrees) {
    const double cpu0 = thread_cpu_seconds();
    std::vector<size_t> todo;
    std::vector<SurfaceBox> boxes;
    std::vector<uint8_t> listed(specs.size(), 0);
    for (size_t i : subtrees)
      if (i < specs.size() && part_of[i].first < 0 && !listed[i]) {
        listed[i] = 1;
        todo.push_back(i);
        boxes.push_back(grown_cell(specs[i], 1.0625f));
      }
    if (todo.empty()) return Status::success();
    auto plan = std::make_unique<SurfacePartPlan>();
    const Status s = plan_surface_parts(original(), part_grid(*root, 1024), std::move(boxes), *plan, what + " (subtrees' parts)");
    count_part(cpu0, 0);
    if (!s) return s;
    for (size_t k = 0; k < todo.size(); ++k) part_of[todo[k]] = {int32_t(plans.size()), uint32_t(k)};
    plans.push_back(std::move(plan));
    return Status::success();
  }
  std::string name(size_t i) const {
    return what + ": subtree " + std::to_string(i) + " (depth " + std::to_string(specs[i].depth) + ", " +
           std::to_string(specs[i].triangles) + " triangles)";
  }
  Status finish(size_t i, Tally& tally, const SubtreeDone& done);
  Status build_part(size_t subtree, PartSlot& slot) {
    const auto [plan, box] = part_of[subtree];
    const double cpu0 = thread_cpu_seconds();
    const Status s = slot.part.set_surface_planned(original(), *plans[size_t(plan)], box, slot.remap,
                                                   name(subtree) + " (the original near it)");
    count_part(cpu0, slot.part.triangles());
    return s;
  }
  Status measure_in_parts(const std::vector<HlodLayerProbe>& probes, const std::vector<uint8_t>& listed,
                          std::vector<float>& to_max, std::vector<std::vector<uint8_t>>& answered);
  Status measure_near(const std::vector<HlodLayerProbe>& probes, const std::function<bool(size_t, size_t, const float*)>& take,
                      bool whole_answers, std::vector<float>& to_max, std::vector<std::vector<uint8_t>>* answered,
                      const std::vector<size_t>& reference, std::vector<float>& from_max);
  Status measure_from_side(const std::vector<HlodLayerProbe>& probes, const std::vector<size_t>& reference,
                           const SurfaceDistance& device, std::vector<float>& from_max);
  void build_top(BuildNode& n);
};

HlodBuilder::HlodBuilder(const MeshView& mesh, const HlodBuildOptions& options)
    : impl_(std::make_unique<Impl>(mesh, options)) {}
HlodBuilder::~HlodBuilder() = default;

const std::vector<HlodSubtreeSpec>& HlodBuilder::subtrees() const { return impl_->specs; }
double HlodBuilder::surface_cpu_seconds() const { return impl_->whole_cpu + double(impl_->part_ns.load()) * 1e-9; }
size_t HlodBuilder::part_triangles() const { return impl_->part_triangles.load(); }
bool HlodBuilder::whole_surface_built() const { return impl_->whole_built.load(); }
void HlodBuilder::set_region(const std::vector<size_t>& subtrees) { impl_->region = subtrees; }


Status HlodBuilder::plan() {
  Impl& m = *impl_;
  const MeshView& mesh = m.mesh;
  if (m.planned) return Status::error(m.what + ": HLOD build planned twice");
  if (Status s = check_input(mesh); !s) return s;
  if (m.options.surfaces.materials.size() > kMaxMaterials)
    return Status::error(m.what + ": " + std::to_string(m.options.surfaces.materials.size()) + " materials, at most " +
                         std::to_string(kMaxMaterials));
  m.root = std::make_unique<BuildNode>();
  m.root->triangles.reserve(mesh.triangle_count());
  for (uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    const uint32_t* f = &mesh.indices[3 * size_t(t)];
    if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2]) ++m.dropped;
    else m.root->triangles.push_back(t);
  }
  if (m.root->triangles.empty()) return Status::error(m.what + ": no triangles to build an HLOD from");
  root_cell(mesh, m.root->triangles, *m.root);
  Context& c = m.c;
  c.positions = mesh.positions.data();
  c.indices = mesh.indices.data();
  c.total_triangles = m.root->triangles.size();
  c.patch_depth.assign(mesh.vertex_count(), kNoPatch);
  c.stamp.assign(mesh.vertex_count(), 0);
  c.local.assign(mesh.vertex_count(), 0);
  c.layout = attribute_layout(mesh);
  if (c.layout.count == 2 && c.layout.has(c.layout.uv)) {
    c.attributes = mesh.uvs.data();  // uvs alone: no copy
  } else if (c.layout.count) {
    c.interleaved.resize(c.layout.count * mesh.vertex_count());
    auto put = [&](size_t at, std::span<const float> column, size_t per) {
      if (!c.layout.has(at)) return;
      for (size_t v = 0; v < mesh.vertex_count(); ++v)
        std::copy_n(&column[per * v], per, &c.interleaved[c.layout.count * v + at]);
    };
    put(c.layout.uv, mesh.uvs, 2);
    put(c.layout.uv1, mesh.uvs1, 2);
    put(c.layout.color, mesh.colors, 4);
    c.attributes = c.interleaved.data();
  }
  if (!m.options.surfaces.materials.empty()) {
    c.vertex_material = vertex_materials(mesh);
    for (int32_t& id : c.vertex_material)
      if (id < -1 || id >= int32_t(m.options.surfaces.materials.size())) id = -1;
  }
  c.normals.resize(mesh.positions.size());
  compute_vertex_normals(mesh.positions.data(), mesh.vertex_count(), mesh.indices.data(), mesh.indices.size(),
                         c.normals.data());
  split_top(c, *m.root, c.options.subtrees);
  refine_at_cuts(c, *m.root, c.options.balance_parts, c.options.balance_cuts);
  m.frontier = number_frontier(*m.root);
  for (const BuildNode* n : m.frontier) m.specs.push_back(describe_subtree(c, *n));
  uint32_t next = 0;
  number_spatially(*m.root, m.specs, next);
  m.baked.assign(m.frontier.size(), 0);
  m.part_of.assign(m.frontier.size(), {-1, 0});
  m.planned = true;
  return Status::success();
}

// Passes 2 and 3 of a grown subtree, against the part of the original near its cell, its
// result handed on, its build nodes freed.
Status HlodBuilder::Impl::finish(size_t i, Tally& tally, const SubtreeDone& done) {
  BuildNode& n = *frontier[i];
  const std::vector<BuildNode*> order = breadth_first(n, Below::everything);
  std::unique_ptr<PartSlot> slot = pool.take();
  Status measured = build_part(i, *slot);
  if (measured) measured = measure_and_order_errors(c, Queries{&slot->part, whole()}, order);
  pool.give(std::move(slot));
  if (!measured) return Status::error(name(i) + ": " + measured.message);
  HlodSubtree result = flatten_subtree(c, order);
  result.short_layers = tally.short_layers.load();
  result.oversized_leaves = tally.oversized_leaves.load();
  for (auto& child : n.children) child.reset();
  n.layers.clear();
  n.reference.clear();
  if (Status s = done(i, std::move(result)); !s) return Status::error(name(i) + ": " + s.message);
  return Status::success();
}

// The parts of the original near the subtrees planned (passes 2 need them) with subtrees growing
// beside, then per subtree passes 1 (if not grown yet), 2 and 3, each result handed on as it is
// finished. Only the parts being measured are held: never a BVH of the whole original, unless a
// query no part can answer exactly needs it.
Status HlodBuilder::bake_subtrees(const std::vector<size_t>& which, const SubtreeDone& done) {
  Impl& m = *impl_;
  if (!m.planned) return Status::error(m.what + ": HLOD subtrees baked before the build was planned");
  for (size_t i : which) {
    if (i >= m.frontier.size() || m.baked[i])
      return Status::error(m.what + ": subtree " + std::to_string(i) + " does not exist or was baked already");
    m.baked[i] = 1;
  }
  if (which.empty()) return Status::success();
  const ParallelFor& parallel_for = m.c.options.parallel_for;
  std::vector<Tally> tallies(which.size());
  std::vector<uint8_t> grown(which.size(), 0);
  std::vector<size_t> planned_here = which;  // with the region's, in the same pass
  planned_here.insert(planned_here.end(), m.region.begin(), m.region.end());
  Status planned;
  std::atomic<bool> plan_done{false};
  run_all(parallel_for, 2, [&](size_t part) {  // subtrees grow beside the plan (none serially)
    if (part == 0) {
      planned = m.plan_parts(planned_here);
      plan_done.store(true);
      return;
    }
    for (size_t k = 0; k < which.size() && !plan_done.load(); ++k) {
      grow(m.c, tallies[k], *m.frontier[which[k]]);
      grown[k] = 1;
    }
  });
  if (!planned) return planned;
  // The rest grow and finish one by one, so that results are handed on from the start.
  std::vector<Status> finished(which.size());
  std::atomic<bool> failed{false};
  run_all(parallel_for, which.size(), [&](size_t k) {
    if (failed.load(std::memory_order_relaxed)) return;
    if (!grown[k]) grow(m.c, tallies[k], *m.frontier[which[k]]);
    finished[k] = m.finish(which[k], tallies[k], done);
    if (!finished[k]) failed.store(true, std::memory_order_relaxed);
  });
  for (const Status& s : finished)
    if (!s) return s;
  return Status::success();
}

// Pass 1 of the top, children before parents; each frontier node stands for its baked subtree by now.
void HlodBuilder::Impl::build_top(BuildNode& n) {
  if (n.subtree >= 0) return;
  const std::vector<BuildNode*> kids = children_of(n);
  run_all(c.options.parallel_for, kids.size(), [&](size_t i) { build_top(*kids[i]); });
  build_layers(c, top_tally, n);
}

// The top's layers to measure, in breadth-first order of the top, finest first.
std::vector<std::pair<BuildNode*, size_t>> top_layers(BuildNode& root) {
  std::vector<std::pair<BuildNode*, size_t>> out;
  for (BuildNode* n : breadth_first(root, Below::stop_at_frontier))
    for (size_t k = n->leaf() ? 1 : 0; k < n->layers.size(); ++k) out.push_back({n, k});
  return out;
}

Status HlodBuilder::build_top(const std::vector<HlodSubtree>& baked, std::vector<HlodLayerProbe>& probes) {
  Impl& m = *impl_;
  if (!m.planned) return Status::error(m.what + ": HLOD assembled before the build was planned");
  if (m.assembled) return Status::error(m.what + ": HLOD assembled twice");
  if (baked.size() != m.frontier.size())
    return Status::error(m.what + ": " + std::to_string(baked.size()) + " subtree results for " +
                         std::to_string(m.frontier.size()) + " subtrees");
  for (size_t i = 0; i < baked.size(); ++i) {
    if (Status s = check_subtree(*m.frontier[i], baked[i], m.mesh.vertex_count(), m.c.layout,
                                 uint32_t(m.options.surfaces.materials.size()), m.name(i));
        !s)
      return s;
    stand_for_subtree(m.c, *m.frontier[i], baked[i]);
  }
  m.assembled = true;
  m.build_top(*m.root);
  probes.clear();
  for (const auto& [n, k] : top_layers(*m.root)) {
    const Layer& l = n->layers[k];
    probes.push_back({l.positions, l.indices, l.source, n->reference});
  }
  return Status::success();
}

namespace {

// What comes from elsewhere is checked before it is used as an index.
Status check_probes(const std::string& what, uint64_t vertices, const std::vector<HlodLayerProbe>& probes,
                    const std::vector<size_t>& which) {
  for (size_t i : which) {
    if (i >= probes.size()) return Status::error(what + ": top layer " + std::to_string(i) + " does not exist");
    const HlodLayerProbe& p = probes[i];
    if (p.positions.size() != 3 * p.source.size() || p.indices.size() % 3 != 0)
      return Status::error(what + ": top layer " + std::to_string(i) + " has mismatched arrays");
    for (uint32_t v : p.source)
      if (v >= vertices) return Status::error(what + ": top layer " + std::to_string(i) + " names a vertex outside the mesh");
    for (uint32_t v : p.reference)
      if (v >= vertices) return Status::error(what + ": top layer " + std::to_string(i) + " names a vertex outside the mesh");
    for (uint32_t t : p.indices)
      if (t >= p.source.size()) return Status::error(what + ": top layer " + std::to_string(i) + " has an index out of range");
  }
  return Status::success();
}

// How many samples layer_samples takes of a probe's layer (without copying it).
size_t probe_sample_count(const Context& c, const HlodLayerProbe& p) {
  return p.positions.size() / 3 + layer_centroids(c, p.indices.size() / 3);
}

Layer probe_layer(const HlodLayerProbe& p) {
  Layer layer;
  layer.positions = p.positions;
  layer.indices = p.indices;
  layer.source = p.source;
  return layer;
}

std::vector<size_t> every(size_t n) {
  std::vector<size_t> all(n);
  for (size_t i = 0; i < n; ++i) all[i] = i;
  return all;
}

}  // namespace

// The top's layers measured against a part of the original built near their samples: the
// samples `take` picks (probe, sample, point), each with the cells within its known bound of it
// (and a cell's width more). One pass over the whole mesh: for the few samples no subtree's
// part answered, or for a builder that baked no subtree. A sample
// the part cannot answer exactly goes to the whole original when `whole_answers`, else is left
// unanswered (answered flags, one per sample of every probe). For the probes in `reference`, the
// other side (the node's original samples to the layer; from_max by position in `reference`).
Status HlodBuilder::Impl::measure_near(const std::vector<HlodLayerProbe>& probes,
                                       const std::function<bool(size_t, size_t, const float*)>& take, bool whole_answers,
                                       std::vector<float>& to_max, std::vector<std::vector<uint8_t>>* answered,
                                       const std::vector<size_t>& reference, std::vector<float>& from_max) {
  const size_t n = probes.size();
  std::vector<std::vector<float>> points(n), known(n);
  std::vector<std::vector<uint32_t>> taken(n);
  const SurfaceGrid grid = part_grid(*root);
  std::vector<uint8_t> wanted(grid.cells(), 0);
  if (answered) answered->assign(n, {});
  for (size_t k = 0; k < n; ++k) {
    std::vector<float> pts, kn;
    layer_samples(c, probe_layer(probes[k]), pts, kn);
    if (answered) (*answered)[k].assign(kn.size(), 0);
    for (size_t i = 0; i < kn.size(); ++i) {
      if (!take(k, i, &pts[3 * i])) continue;
      taken[k].push_back(uint32_t(i));
      points[k].insert(points[k].end(), &pts[3 * i], &pts[3 * i] + 3);
      known[k].push_back(kn[i]);
      const float reach = std::isfinite(kn[i]) ? kn[i] * 1.01f + grid.edge / float(grid.n) : grid.edge;
      float lo[3], hi[3];
      for (int j = 0; j < 3; ++j) lo[j] = pts[3 * i + j] - reach, hi[j] = pts[3 * i + j] + reach;
      want_box(grid, lo, hi, wanted);
    }
  }
  from_max.assign(reference.size(), 0.0f);
  size_t left = 0;
  for (const auto& t : taken) left += t.size();
  const SurfaceDistance* device = pool.any();  // the other side needs only an Embree device
  if (left == 0 && reference.empty()) return Status::success();
  if (left == 0 && device) return measure_from_side(probes, reference, *device, from_max);
  SurfaceDistance near;
  const double cpu0 = thread_cpu_seconds();
  if (Status s = near.set_surface_part(original(), grid, wanted, what + " (near the top's samples)"); !s) return s;
  count_part(cpu0, near.triangles());
  const std::function<const SurfaceDistance*()> fallback = whole_answers ? whole() : nullptr;
  std::vector<Status> measured(n);
  run_all(c.options.parallel_for, n, [&](size_t k) {
    if (taken[k].empty()) return;
    std::vector<uint8_t> got;
    SurfaceError e;
    measured[k] = near.from_points_part(points[k].data(), taken[k].size(), known[k].data(), fallback, e,
                                        answered ? &got : nullptr);
    to_max[k] = std::max(to_max[k], e.max);
    for (size_t i = 0; i < got.size(); ++i) (*answered)[k][taken[k][i]] = got[i];
  });
  for (const Status& s : measured)
    if (!s) return s;
  return measure_from_side(probes, reference, device ? *device : near, from_max);
}

// The original's side of the probes in `reference` (the node's original samples to the layer,
// its BVH built on `device`'s Embree device): from_max by position in `reference`.
Status HlodBuilder::Impl::measure_from_side(const std::vector<HlodLayerProbe>& probes, const std::vector<size_t>& reference,
                                            const SurfaceDistance& device, std::vector<float>& from_max) {
  from_max.assign(reference.size(), 0.0f);
  std::vector<Status> measured(reference.size());
  run_all(c.options.parallel_for, reference.size(), [&](size_t k) {
    const HlodLayerProbe& p = probes[reference[k]];
    measured[k] = original_to_layer(c, device, p.reference, probe_layer(p), from_max[k]);
  });
  for (const Status& s : measured)
    if (!s) return s;
  return Status::success();
}

// The samples of the listed probes in the cells of subtrees baked here, each subtree's against
// its part built again (one part per task at a time): to_max raised, answered flagged (one flag
// per sample of every probe).
Status HlodBuilder::Impl::measure_in_parts(const std::vector<HlodLayerProbe>& probes, const std::vector<uint8_t>& listed,
                                           std::vector<float>& to_max, std::vector<std::vector<uint8_t>>& answered) {
  const size_t n = probes.size();
  std::vector<std::vector<float>> points(n), known(n);
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> in(specs.size());  // per subtree: (probe, sample)
  answered.assign(n, {});
  for (size_t k = 0; k < n; ++k) {
    answered[k].assign(probe_sample_count(c, probes[k]), 0);
    if (!listed[k]) continue;
    layer_samples(c, probe_layer(probes[k]), points[k], known[k]);
    for (size_t i = 0; i < known[k].size(); ++i)
      if (const int t = subtree_at(*root, &points[k][3 * i]); t >= 0 && part_of[size_t(t)].first >= 0)
        in[size_t(t)].push_back({uint32_t(k), uint32_t(i)});
  }
  std::vector<size_t> todo;
  for (size_t t = 0; t < in.size(); ++t)
    if (!in[t].empty()) todo.push_back(t);
  std::vector<std::vector<float>> maxes(todo.size());
  std::vector<Status> measured(todo.size());
  run_all(c.options.parallel_for, todo.size(), [&](size_t x) {
    const auto& samples = in[todo[x]];
    std::unique_ptr<PartSlot> slot = pool.take();
    measured[x] = build_part(todo[x], *slot);
    maxes[x].assign(n, 0.0f);
    for (size_t a = 0, b = 0; measured[x] && a < samples.size(); a = b) {  // one run per probe
      const uint32_t k = samples[a].first;
      std::vector<float> pts, kn;
      for (b = a; b < samples.size() && samples[b].first == k; ++b) {
        const uint32_t i = samples[b].second;
        pts.insert(pts.end(), &points[k][3 * size_t(i)], &points[k][3 * size_t(i)] + 3);
        kn.push_back(known[k][i]);
      }
      std::vector<uint8_t> got;
      SurfaceError e;
      measured[x] = slot->part.from_points_part(pts.data(), kn.size(), kn.data(), {}, e, &got);
      maxes[x][k] = e.max;
      for (size_t i = 0; i < got.size(); ++i) answered[k][samples[a + i].second] = got[i];
    }
    pool.give(std::move(slot));
  });
  for (size_t x = 0; x < todo.size(); ++x) {
    if (!measured[x]) return measured[x];
    for (size_t k = 0; k < n; ++k) to_max[k] = std::max(to_max[k], maxes[x][k]);
  }
  return Status::success();
}

Status HlodBuilder::measure_probes(const std::vector<HlodLayerProbe>& probes, const std::vector<size_t>& which,
                                   std::vector<float>& errors) {
  Impl& m = *impl_;
  if (!m.planned) return Status::error(m.what + ": HLOD layers measured before the build was planned");
  if (Status s = check_probes(m.what, m.mesh.vertex_count(), probes, which); !s) return s;
  std::vector<uint8_t> listed(probes.size(), 0);
  for (size_t k : which) listed[k] = 1;
  std::vector<float> to_max(probes.size(), 0.0f), from_max;
  std::vector<std::vector<uint8_t>> answered;
  if (Status s = m.measure_in_parts(probes, listed, to_max, answered); !s) return s;
  const auto left = [&](size_t k, size_t i, const float*) { return listed[k] && !answered[k][i]; };
  if (Status s = m.measure_near(probes, left, true, to_max, nullptr, which, from_max); !s) return s;
  errors.resize(which.size());
  for (size_t k = 0; k < which.size(); ++k) errors[k] = std::max(to_max[which[k]], from_max[k]);
  return Status::success();
}

Status HlodBuilder::measure_probes_part(const std::vector<HlodLayerProbe>& probes, const std::vector<size_t>& reference,
                                        std::vector<float>& to_max, std::vector<std::vector<uint8_t>>& answered,
                                        std::vector<float>& from_max) {
  Impl& m = *impl_;
  if (!m.planned) return Status::error(m.what + ": HLOD layers measured before the build was planned");
  if (Status s = check_probes(m.what, m.mesh.vertex_count(), probes, every(probes.size())); !s) return s;
  for (size_t i : reference)
    if (i >= probes.size()) return Status::error(m.what + ": top layer " + std::to_string(i) + " does not exist");
  if (Status s = m.plan_parts(m.region); !s) return s;  // a rank that baked none of its region
  to_max.assign(probes.size(), 0.0f);
  if (Status s = m.measure_in_parts(probes, std::vector<uint8_t>(probes.size(), 1), to_max, answered); !s) return s;
  from_max.clear();
  if (reference.empty()) return Status::success();
  if (const SurfaceDistance* device = m.pool.any()) return m.measure_from_side(probes, reference, *device, from_max);
  const auto nothing = [](size_t, size_t, const float*) { return false; };  // near nothing: a device
  std::vector<float> unused(probes.size(), 0.0f);
  return m.measure_near(probes, nothing, false, unused, nullptr, reference, from_max);
}

Status HlodBuilder::measure_probes_rest(const std::vector<HlodLayerProbe>& probes,
                                        const std::vector<std::vector<uint8_t>>& answered, std::vector<float>& to_max) {
  Impl& m = *impl_;
  if (!m.planned) return Status::error(m.what + ": HLOD layers measured before the build was planned");
  if (answered.size() != probes.size() || to_max.size() != probes.size())
    return Status::error(m.what + ": " + std::to_string(answered.size()) + " answered lists for " +
                         std::to_string(probes.size()) + " top layers");
  if (Status s = check_probes(m.what, m.mesh.vertex_count(), probes, every(probes.size())); !s) return s;
  for (size_t k = 0; k < probes.size(); ++k)
    if (answered[k].size() != probe_sample_count(m.c, probes[k]))
      return Status::error(m.what + ": top layer " + std::to_string(k) + ": answered flags do not match its samples");
  const auto take = [&](size_t k, size_t i, const float*) { return answered[k][i] == 0; };
  std::vector<float> from_max;
  return m.measure_near(probes, take, true, to_max, nullptr, {}, from_max);
}

Status HlodBuilder::finish_top(const std::vector<HlodSubtree>& baked, const std::vector<float>& errors,
                               HlodAssembly& out, HlodBuildReport* report_out) {
  Impl& m = *impl_;
  if (!m.assembled) return Status::error(m.what + ": HLOD top finished before it was built");
  const std::vector<std::pair<BuildNode*, size_t>> layers = top_layers(*m.root);
  if (errors.size() != layers.size() || baked.size() != m.frontier.size())
    return Status::error(m.what + ": " + std::to_string(errors.size()) + " errors for " + std::to_string(layers.size()) +
                         " top layers");
  for (size_t i = 0; i < layers.size(); ++i) layers[i].first->layers[layers[i].second].error = errors[i];
  const std::vector<BuildNode*> top = breadth_first(*m.root, Below::stop_at_frontier);
  for (BuildNode* n : top) report_done(m.c, *n);
  make_errors_monotonic(top);
  HlodBuildReport report;
  report.dropped_triangles = m.dropped;
  for (const HlodSubtree& s : baked) report.short_layers += s.short_layers, report.oversized_leaves += s.oversized_leaves;
  HlodAssembly assembly;
  assembly.model.tree.min_verts = m.c.options.min_verts;
  for (int k = 0; k < 3; ++k) assembly.model.tree.box_center[k] = m.root->center[k];
  assembly.model.tree.box_half = m.root->half;
  assembly.model.tree.source_triangles = m.mesh.triangle_count();
  assembly.model.tree.uvs = m.c.layout.has(m.c.layout.uv);
  assembly.model.tree.uvs1 = m.c.layout.has(m.c.layout.uv1);
  assembly.model.tree.colors = m.c.layout.has(m.c.layout.color);
  assembly.model.tree.material_count = uint32_t(m.options.surfaces.materials.size());
  assembly.model.tree.materials = m.options.surfaces.materials;
  assembly.model.tree.texture_base = m.options.surfaces.texture_base;
  assembly.model.tree.images = m.options.surfaces.images;
  splice(m.c, *m.root, baked, assembly, report);
  report.short_layers += m.top_tally.short_layers.load();
  report.oversized_leaves += m.top_tally.oversized_leaves.load();
  out = std::move(assembly);
  if (report_out) *report_out = report;
  return Status::success();
}

Status HlodBuilder::assemble_top(const std::vector<HlodSubtree>& baked, HlodAssembly& out, HlodBuildReport* report_out) {
  std::vector<HlodLayerProbe> probes;
  if (Status s = build_top(baked, probes); !s) return s;
  std::vector<size_t> all(probes.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  std::vector<float> errors;
  if (Status s = measure_probes(probes, all, errors); !s) return s;
  return finish_top(baked, errors, out, report_out);
}

Status HlodBuilder::assemble(std::vector<HlodSubtree>& baked, HlodModel& out, HlodBuildReport* report_out) {
  Impl& m = *impl_;
  for (size_t i = 0; i < baked.size(); ++i)
    if (baked[i].payloads.size() != baked[i].nodes.size())
      return Status::error(m.name(i) + ": not one payload per node");
  HlodAssembly assembly;
  if (Status s = assemble_top(baked, assembly, report_out); !s) return s;
  for (size_t i = 0; i < assembly.origin.size(); ++i)
    if (const HlodAssembly::Origin o = assembly.origin[i]; o.subtree >= 0)
      assembly.model.payloads[i] = std::move(baked[size_t(o.subtree)].payloads[o.local]);
  out = std::move(assembly.model);
  return Status::success();
}

// (a), (b) for every subtree, (c): the composition a distributed build spreads out.
Status build_hlod(HlodModel& out, const MeshData& mesh, const HlodBuildOptions& options, HlodBuildReport* report) {
  HlodBuilder builder(mesh, options);
  if (Status s = builder.plan(); !s) return s;
  std::vector<HlodSubtree> baked(builder.subtrees().size());
  std::vector<size_t> all(baked.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  const Status st = builder.bake_subtrees(all, [&](size_t i, HlodSubtree&& s) {
    baked[i] = std::move(s);
    return Status::success();
  });
  if (!st) return st;
  return builder.assemble(baked, out, report);
}

}  // namespace lod
