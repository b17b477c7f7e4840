#include "preprocess/scene_hlod_build.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>

#include "preprocess/surface_error.h"
#include "runtime/world_bounds.h"

namespace lod {

namespace {

struct Cell {
  float center[3];
  float half;
};

struct Proxy {
  std::vector<float> positions;
  std::vector<uint32_t> indices;
  float error = 0;
};

uint32_t octant_of(const Sphere& s, const Cell& c) {
  return (s.center[0] >= c.center[0] ? 1u : 0u) | (s.center[1] >= c.center[1] ? 2u : 0u) |
         (s.center[2] >= c.center[2] ? 4u : 0u);
}

Cell child_cell(const Cell& c, uint32_t octant) {
  Cell k;
  k.half = c.half / 2;
  for (int a = 0; a < 3; ++a) k.center[a] = c.center[a] + ((octant >> a & 1) ? k.half : -k.half);
  return k;
}

Cell root_cell(const SceneHlodObjectsIn& in) {
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (const Sphere& s : in.sphere)
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], s.center[a]), hi[a] = std::max(hi[a], s.center[a]);
  Cell c;
  c.half = 0;
  for (int a = 0; a < 3; ++a) {
    c.center[a] = (lo[a] + hi[a]) / 2;
    c.half = std::max(c.half, (hi[a] - lo[a]) / 2);
  }
  return c;
}

// Stable partition of ids[b, e) by octant; returns where each octant starts (9 bounds).
std::array<uint32_t, 9> partition(std::vector<uint32_t>& ids, uint32_t b, uint32_t e, const SceneHlodObjectsIn& in,
                                  const Cell& c) {
  std::array<uint32_t, 9> start{};
  for (uint32_t j = b; j < e; ++j) ++start[octant_of(in.sphere[ids[j]], c) + 1];
  start[0] = b;
  for (int o = 0; o < 8; ++o) start[o + 1] += start[o];
  std::array<uint32_t, 9> at = start;
  std::vector<uint32_t> sorted(e - b);
  for (uint32_t j = b; j < e; ++j) sorted[at[octant_of(in.sphere[ids[j]], c)]++ - b] = ids[j];
  std::copy(sorted.begin(), sorted.end(), ids.begin() + b);
  return start;
}

Sphere enclosing(const SceneHlodObjectsIn& in, std::span<const uint32_t> ids) {
  double c[3] = {0, 0, 0};
  for (uint32_t i : ids)
    for (int a = 0; a < 3; ++a) c[a] += in.sphere[i].center[a];
  Sphere s;
  for (int a = 0; a < 3; ++a) s.center[a] = float(c[a] / double(ids.size()));
  for (uint32_t i : ids) {
    const Sphere& o = in.sphere[i];
    const float d = std::sqrt((o.center[0] - s.center[0]) * (o.center[0] - s.center[0]) +
                              (o.center[1] - s.center[1]) * (o.center[1] - s.center[1]) +
                              (o.center[2] - s.center[2]) * (o.center[2] - s.center[2]));
    s.radius = std::max(s.radius, d + o.radius);
  }
  s.radius *= 1.0001f;  // float rounding: every object's sphere stays inside
  return s;
}

// Breadth-first nodes over the objects (ids permuted into octree order as cells split).
void build_octree(const SceneHlodObjectsIn& in, const SceneHlodSettings& settings, std::vector<uint32_t>& ids,
                  std::vector<SceneHlodNode>& nodes) {
  const uint32_t n = uint32_t(in.model.size());
  ids.resize(n);
  for (uint32_t i = 0; i < n; ++i) ids[i] = i;
  if (n < std::max<uint32_t>(2, settings.min_objects)) return;
  std::vector<Cell> cells{root_cell(in)};
  nodes.push_back(SceneHlodNode{});
  nodes[0].object_count = n;
  for (size_t at = 0; at < nodes.size(); ++at) {
    const Cell cell = cells[at];
    const uint32_t b = nodes[at].first_object, e = b + nodes[at].object_count;
    nodes[at].bounds = enclosing(in, std::span(ids).subspan(b, e - b));
    if (nodes[at].depth >= kSceneHlodMaxDepth || !(cell.half > 0)) continue;  // all at one point
    const std::array<uint32_t, 9> start = partition(ids, b, e, in, cell);
    nodes[at].first_child = uint32_t(nodes.size());
    for (uint32_t o = 0; o < 8; ++o) {
      if (start[o + 1] - start[o] < std::max<uint32_t>(2, settings.min_objects)) continue;
      SceneHlodNode child;
      child.first_object = start[o];
      child.object_count = start[o + 1] - start[o];
      child.depth = uint8_t(nodes[at].depth + 1);
      nodes.push_back(child);
      cells.push_back(child_cell(cell, o));
      ++nodes[at].child_count;
    }
  }
}

// The coarsest level of a chain that draws something (a culled level draws nothing).
const LodLevel* coarsest_drawn(const LodChain& chain) {
  for (size_t k = chain.levels.size(); k-- > 0;)
    if (chain.levels[k].index_count >= 3) return &chain.levels[k];
  return nullptr;
}

// Appends object i's coarsest level in world space; returns its error in world units.
float append_object(const SceneHlodObjectsIn& in, uint32_t i, Proxy& mesh) {
  const LodChain& chain = in.chains[in.model[i]];
  const LodLevel* l = coarsest_drawn(chain);
  if (!l) return 0;
  const Transform& t = in.transform[i];
  float q[4];
  normalized_rotation(t, q);
  const uint32_t base = uint32_t(mesh.positions.size() / 3);
  for (uint32_t v = 0; v < l->vertex_count; ++v) {
    const float* p = chain.positions.data() + 3 * (size_t(l->first_vertex) + v);
    const float s[3] = {p[0] * t.scale, p[1] * t.scale, p[2] * t.scale};
    float r[3];
    rotate_by_quaternion(q, s, r);
    for (int a = 0; a < 3; ++a) mesh.positions.push_back(t.position[a] + r[a]);
  }
  for (uint32_t k = 0; k < l->index_count; ++k) mesh.indices.push_back(base + chain.indices[l->first_index + k]);
  return l->error * t.scale;
}

void append_proxy(const Proxy& p, Proxy& mesh) {
  const uint32_t base = uint32_t(mesh.positions.size() / 3);
  mesh.positions.insert(mesh.positions.end(), p.positions.begin(), p.positions.end());
  for (uint32_t v : p.indices) mesh.indices.push_back(base + v);
}

// The node's inputs merged: child proxies, then the objects in no child, in octree order.
Proxy gather_inputs(const SceneHlodObjectsIn& in, const std::vector<uint32_t>& ids,
                    const std::vector<SceneHlodNode>& nodes, const std::vector<Proxy>& proxies, uint32_t node,
                    float& input_error) {
  const SceneHlodNode& n = nodes[node];
  Proxy mesh;
  input_error = 0;
  uint32_t j = n.first_object;
  const uint32_t end = n.first_object + n.object_count;
  for (uint32_t c = 0; c <= n.child_count; ++c) {
    const uint32_t until = c < n.child_count ? nodes[n.first_child + c].first_object : end;
    for (; j < until; ++j) input_error = std::max(input_error, append_object(in, ids[j], mesh));
    if (c == n.child_count) break;
    const SceneHlodNode& child = nodes[n.first_child + c];
    append_proxy(proxies[n.first_child + c], mesh);
    input_error = std::max(input_error, proxies[n.first_child + c].error);
    j = child.first_object + child.object_count;
  }
  return mesh;
}

TriangleMeshView view_of(const Proxy& p) {
  return {p.positions.data(), p.positions.size() / 3, p.indices.data(), p.indices.size()};
}

// Symmetric distance between a proxy and what it was built from, at vertices: every proxy
// vertex to the input's surface, and up to `samples` input vertices (evenly thinned) to the
// proxy's. QEM moves vertices, so that is where the distance is; the tests check the bound
// against dense surface samples of the full-detail objects.
Status proxy_distance(const Proxy& input, const Proxy& proxy, uint32_t samples, float& out) {
  SurfaceDistance surface;
  if (Status st = surface.set_surface(view_of(input), "proxy input"); !st) return st;
  SurfaceError to_input, to_proxy;
  if (Status st = surface.from_points(proxy.positions.data(), proxy.positions.size() / 3, nullptr, to_input); !st)
    return st;
  const size_t n = input.positions.size() / 3, keep = std::min<size_t>(n, std::max<uint32_t>(1, samples));
  std::vector<float> points(3 * keep);
  for (size_t k = 0; k < keep; ++k)
    std::copy_n(&input.positions[3 * (k * n / keep)], 3, &points[3 * k]);
  if (Status st = surface.from_points_to(view_of(proxy), points.data(), keep, nullptr, to_proxy); !st) return st;
  out = std::max(to_input.max, to_proxy.max);
  return Status::success();
}

Status build_proxy(const SceneHlodObjectsIn& in, const SceneHlodSettings& settings, const std::vector<uint32_t>& ids,
                   const std::vector<SceneHlodNode>& nodes, std::vector<Proxy>& proxies, uint32_t node) {
  float input_error = 0;
  Proxy merged = gather_inputs(in, ids, nodes, proxies, node, input_error);
  const size_t tris = merged.indices.size() / 3;
  const size_t target = size_t(double(tris) * settings.reduction);
  Proxy& out = proxies[node];
  out.error = input_error;
  if (target < 1 || tris < 8) {
    out.positions = std::move(merged.positions);
    out.indices = std::move(merged.indices);
    return Status::success();
  }
  ChainLevelOut level;
  QemOptions options;
  options.max_error = settings.cell_error * nodes[node].bounds.radius;
  qem_simplify_chain(&level, merged.positions.data(), merged.positions.size() / 3, merged.indices.data(),
                     merged.indices.size(), &target, 1, options);
  if (level.triangle_count() == 0) level.indices = merged.indices, level.positions = merged.positions;
  out.positions = std::move(level.positions);
  out.indices = std::move(level.indices);
  float measured = 0;
  if (Status st = proxy_distance(merged, out, settings.error_samples, measured); !st)
    return Status::error("scene hlod node " + std::to_string(node) + ": " + st.message);
  out.error = input_error + measured;
  return Status::success();
}

void vertex_normals(const std::vector<float>& p, const std::vector<uint32_t>& idx, std::vector<float>& n) {
  n.assign(p.size(), 0.f);
  for (size_t t = 0; t + 2 < idx.size(); t += 3) {
    const float* a = &p[3 * size_t(idx[t])];
    const float* b = &p[3 * size_t(idx[t + 1])];
    const float* c = &p[3 * size_t(idx[t + 2])];
    const float u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const float f[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    for (int k = 0; k < 3; ++k)
      for (int a2 = 0; a2 < 3; ++a2) n[3 * size_t(idx[t + k]) + a2] += f[a2];  // area-weighted
  }
  for (size_t v = 0; v + 2 < n.size(); v += 3) {
    const float len = std::sqrt(n[v] * n[v] + n[v + 1] * n[v + 1] + n[v + 2] * n[v + 2]);
    if (len > 0)
      for (int a = 0; a < 3; ++a) n[v + a] /= len;
  }
}

void assemble(const SceneHlodObjectsIn& in, const std::vector<uint32_t>& ids, std::vector<Proxy>& proxies,
              SceneHlodTree& out) {
  for (size_t i = 0; i < out.nodes.size(); ++i) {
    SceneHlodNode& n = out.nodes[i];
    Proxy& p = proxies[i];
    n.error = p.error;
    n.first_vertex = uint32_t(out.positions.size() / 3);
    n.vertex_count = uint32_t(p.positions.size() / 3);
    n.first_index = uint32_t(out.indices.size());
    n.index_count = uint32_t(p.indices.size());
    std::vector<float> normals;
    vertex_normals(p.positions, p.indices, normals);
    out.positions.insert(out.positions.end(), p.positions.begin(), p.positions.end());
    out.normals.insert(out.normals.end(), normals.begin(), normals.end());
    out.indices.insert(out.indices.end(), p.indices.begin(), p.indices.end());
    p = Proxy{};
  }
  out.objects.resize(ids.size());
  for (size_t j = 0; j < ids.size(); ++j) {
    const uint32_t i = ids[j];
    out.objects[j] = {in.scene_index[i], 0, in.model[i], in.sphere[i]};
    out.source_triangles += in.chains[in.model[i]].levels.empty() ? 0 : in.chains[in.model[i]].levels[0].triangles();
  }
}

Status check_input(const SceneHlodObjectsIn& in) {
  const size_t n = in.model.size();
  if (in.transform.size() != n || in.sphere.size() != n || in.scene_index.size() != n)
    return Status::error("scene hlod: object columns of different lengths");
  for (size_t i = 0; i < n; ++i)
    if (in.model[i] >= in.chains.size()) return Status::error("scene hlod: object " + std::to_string(i) + ": unknown model");
  return Status::success();
}

}  // namespace

Status build_scene_hlod(const SceneHlodObjectsIn& in, const SceneHlodSettings& settings, const ParallelFor& parallel_for,
                        const std::function<void(size_t, size_t)>& progress, SceneHlodTree& out) {
  if (Status st = check_input(in); !st) return st;
  SceneHlodTree tree;
  std::vector<uint32_t> ids;
  build_octree(in, settings, ids, tree.nodes);
  std::vector<Proxy> proxies(tree.nodes.size());
  std::vector<Status> status(tree.nodes.size());
  std::atomic<size_t> done{0};
  // Deepest first: a node's children are finished before it starts.
  for (int depth = int(kSceneHlodMaxDepth); depth >= 0; --depth) {
    std::vector<uint32_t> level;
    for (uint32_t i = 0; i < tree.nodes.size(); ++i)
      if (tree.nodes[i].depth == depth) level.push_back(i);
    if (level.empty()) continue;
    parallel_for(level.size(), [&](size_t k) {
      status[level[k]] = build_proxy(in, settings, ids, tree.nodes, proxies, level[k]);
      const size_t d = done.fetch_add(1) + 1;
      if (progress) progress(d, tree.nodes.size());
    });
    for (uint32_t i : level)
      if (!status[i]) return status[i];
  }
  assemble(in, ids, proxies, tree);
  out = std::move(tree);
  return Status::success();
}

}  // namespace lod
