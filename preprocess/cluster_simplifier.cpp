// Grid vertex clustering with quadric representatives (see cluster_simplifier.h for the papers).
//
// Passes: normalise positions once; search the grid resolution (each probe: cell id per vertex,
// then count the faces whose corners fall in three different cells); for the chosen grid,
// number the occupied cells, sum each cell's face quadrics, solve for its vertex, and emit the
// surviving faces once each. The face count that matters is after duplicates are removed,
// which the cheap probe cannot see, so the search is re-aimed by the observed ratio.
#include "preprocess/cluster_simplifier.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

namespace lod {
namespace {

// Regularisation of each cell's 3x3 system towards the cell's vertex centroid.
constexpr double kRegularisation = 1e-2;
// Targets below faces / kRefineLimit are clustered to kRefine times the target and finished by
// QEM edge collapse, which is cheap at that size and places the last faces where they matter.
constexpr size_t kRefine = 2;
constexpr size_t kRefineLimit = 30;
constexpr double kMaxGrid = 1 << 20;  // cells along the longest axis

struct Prepared {
  std::vector<float> unit;          // positions in [0,1] of the longest axis
  std::vector<uint32_t> triangles;  // valid faces only
  float origin[3] = {0, 0, 0};
  float extent = 1;                 // longest side of the bounding box
  float span[3] = {1, 1, 1};        // each side / extent
  size_t vertex_count = 0;
};

void prepare(Prepared& p, const float* positions, size_t vertex_count, const uint32_t* indices, size_t index_count) {
  p.vertex_count = vertex_count;
  std::vector<uint8_t> finite(vertex_count);
  float lo[3] = {std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
                 std::numeric_limits<float>::max()};
  float hi[3] = {-lo[0], -lo[1], -lo[2]};
  for (size_t v = 0; v < vertex_count; ++v) {
    const float* q = positions + 3 * v;
    finite[v] = std::isfinite(q[0]) && std::isfinite(q[1]) && std::isfinite(q[2]);
    if (!finite[v]) continue;
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], q[k]), hi[k] = std::max(hi[k], q[k]);
  }
  float extent = 0;
  for (int k = 0; k < 3; ++k) extent = std::max(extent, hi[k] - lo[k]);
  p.extent = extent > 0 ? extent : 1;
  for (int k = 0; k < 3; ++k) {
    p.origin[k] = lo[k] <= hi[k] ? lo[k] : 0;
    p.span[k] = lo[k] <= hi[k] ? (hi[k] - lo[k]) / p.extent : 0;
  }
  const float inv = 1 / p.extent;
  p.unit.resize(3 * vertex_count);
  for (size_t v = 0; v < vertex_count; ++v)
    for (int k = 0; k < 3; ++k) p.unit[3 * v + k] = finite[v] ? (positions[3 * v + k] - p.origin[k]) * inv : 0;
  p.triangles.clear();
  p.triangles.reserve(index_count);
  for (size_t t = 0; t + 2 < index_count; t += 3) {
    const uint32_t a = indices[t], b = indices[t + 1], c = indices[t + 2];
    if (a >= vertex_count || b >= vertex_count || c >= vertex_count) continue;
    if (a == b || b == c || a == c || !finite[a] || !finite[b] || !finite[c]) continue;
    p.triangles.insert(p.triangles.end(), {a, b, c});
  }
}

struct Grid {
  double cells = 1;  // along the longest axis
  uint64_t dims[3] = {1, 1, 1};
};

Grid make_grid(const Prepared& p, double cells) {
  Grid g;
  g.cells = cells;
  for (int k = 0; k < 3; ++k) g.dims[k] = uint64_t(double(p.span[k]) * cells) + 1;
  return g;
}

void cell_ids(std::vector<uint64_t>& ids, const Prepared& p, const Grid& g) {
  ids.resize(p.vertex_count);
  const float s = float(g.cells);
  const int64_t d0 = int64_t(g.dims[0]), d1 = int64_t(g.dims[1]), d2 = int64_t(g.dims[2]);
  const float* u = p.unit.data();
  for (size_t v = 0; v < p.vertex_count; ++v) {
    const int64_t x = std::min(int64_t(u[3 * v] * s), d0 - 1);
    const int64_t y = std::min(int64_t(u[3 * v + 1] * s), d1 - 1);
    const int64_t z = std::min(int64_t(u[3 * v + 2] * s), d2 - 1);
    ids[v] = uint64_t(x) + uint64_t(d0) * (uint64_t(y) + uint64_t(d1) * uint64_t(z));
  }
}

// Faces whose corners lie in three different cells (duplicates included).
size_t count_spanning(const std::vector<uint64_t>& ids, const Prepared& p) {
  size_t n = 0;
  const uint32_t* t = p.triangles.data();
  for (size_t i = 0; i < p.triangles.size(); i += 3) {
    const uint64_t a = ids[t[i]], b = ids[t[i + 1]], c = ids[t[i + 2]];
    n += (a != b) & (b != c) & (a != c);
  }
  return n;
}

inline uint64_t mix(uint64_t h) {
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdull;
  h ^= h >> 33;
  h *= 0xc4ceb9fe1a85ec53ull;
  h ^= h >> 33;
  return h;
}

// Open-addressing table from 64-bit cell id to dense cluster number.
struct CellTable {
  std::vector<uint64_t> keys;
  std::vector<uint32_t> values;
  size_t mask = 0;
  void reset(size_t expected) {
    size_t cap = 64;
    while (cap < 2 * expected) cap *= 2;
    keys.assign(cap, ~0ull);
    values.resize(cap);
    mask = cap - 1;
  }
  uint32_t insert(uint64_t key, uint32_t next) {
    size_t slot = mix(key) & mask;
    while (keys[slot] != ~0ull && keys[slot] != key) slot = (slot + 1) & mask;
    if (keys[slot] == ~0ull) keys[slot] = key, values[slot] = next;
    return values[slot];
  }
};

// Faces left after clustering, canonically rotated (smallest cluster first, orientation
// kept), each set of three cells once. Returns their count; writes them to `out` when given.
size_t unique_faces(std::vector<uint32_t>& faces, std::vector<uint32_t>& table, const std::vector<uint32_t>& cluster,
                    const Prepared& p, std::vector<uint32_t>* out) {
  faces.resize(p.triangles.size());
  const uint32_t* t = p.triangles.data();
  size_t n = 0;
  for (size_t i = 0; i < p.triangles.size(); i += 3) {
    uint32_t a = cluster[t[i]], b = cluster[t[i + 1]], c = cluster[t[i + 2]];
    if (a == b || b == c || a == c) continue;
    if (b < a && b < c) std::swap(a, b), std::swap(b, c);  // rotate b to the front
    else if (c < a && c < b) std::swap(a, c), std::swap(b, c);
    faces[3 * n] = a, faces[3 * n + 1] = b, faces[3 * n + 2] = c;
    n++;
  }
  size_t cap = 64;
  while (cap < 2 * n) cap *= 2;
  table.assign(cap, ~0u);
  size_t kept = 0;
  for (size_t f = 0; f < n; ++f) {
    // Same three cells in either orientation is one face (a two-sided sliver otherwise).
    const uint32_t* x = &faces[3 * f];
    const uint32_t xl = std::min(x[1], x[2]), xh = std::max(x[1], x[2]);
    size_t slot = mix(uint64_t(x[0]) * 0x9e3779b97f4a7c15ull ^ (uint64_t(xl) << 32 | xh)) & (cap - 1);
    bool duplicate = false;
    while (table[slot] != ~0u) {
      const uint32_t* y = &faces[3 * size_t(table[slot])];
      if (y[0] == x[0] && std::min(y[1], y[2]) == xl && std::max(y[1], y[2]) == xh) {
        duplicate = true;
        break;
      }
      slot = (slot + 1) & (cap - 1);
    }
    if (duplicate) continue;
    table[slot] = uint32_t(f);
    if (out) out->push_back(x[0]), out->push_back(x[1]), out->push_back(x[2]);
    kept++;
  }
  return kept;
}

struct Scratch {
  std::vector<uint64_t> ids;
  std::vector<uint32_t> cluster, faces, table, out_faces;
  CellTable cells;
};

size_t number_cells(Scratch& s, const Prepared& p) {
  s.cells.reset(std::min<size_t>(p.vertex_count, 1u << 24));
  s.cluster.resize(p.vertex_count);
  uint32_t next = 0;
  for (size_t v = 0; v < p.vertex_count; ++v) {
    const uint32_t c = s.cells.insert(s.ids[v], next);
    if (c == next) next++;
    s.cluster[v] = c;
  }
  return next;
}

size_t count_unique(Scratch& s, const Prepared& p, const Grid& g) {
  cell_ids(s.ids, p, g);
  number_cells(s, p);
  return unique_faces(s.faces, s.table, s.cluster, p, nullptr);
}

// Grid whose unique face count is close to `target`: log-space interpolation on the cheap
// spanning count, re-aimed by the spanning/unique ratio of the last candidate.
// `current` tells whether s.ids and s.cluster already hold the returned grid's cells.
Grid search_grid(Scratch& s, const Prepared& p, size_t target, const ClusterOptions& options, bool& current) {
  const size_t faces = p.triangles.size() / 3;
  Grid best = make_grid(p, 1);
  double best_miss = std::numeric_limits<double>::max(), best_unique = -1;
  double aim = double(target);
  int probes = 0;
  double cells = std::sqrt(aim / std::max<double>(1, double(faces))) * std::sqrt(double(p.vertex_count)) + 1;
  for (int round = 0; round < 4 && probes < options.max_probes; ++round) {
    // Bracket and interpolate on the spanning count (grows about as cells^2).
    double lo = 1, hi = kMaxGrid;
    double lo_n = 0, hi_n = double(faces);
    cells = std::clamp(cells, 1.0, kMaxGrid);
    Grid g = make_grid(p, cells);
    double g_miss = std::numeric_limits<double>::max(), g_n = -1;
    for (int i = 0; i < 12 && probes < options.max_probes; ++i, ++probes) {
      const Grid probe = make_grid(p, cells);
      cell_ids(s.ids, p, probe);
      const double n = double(count_spanning(s.ids, p));
      // The closest probe so far (equally close: the one with more faces) is the candidate.
      const double m = std::fabs(n - aim);
      if (m < g_miss || (m == g_miss && n > g_n)) g = probe, g_miss = m, g_n = n;
      if (m <= 0.5 * options.tolerance * aim) break;
      if (n < aim) lo = cells, lo_n = n;
      else hi = cells, hi_n = n;
      double next;
      if (lo_n > 0 && hi < kMaxGrid) {
        const double t = (std::log(aim) - std::log(lo_n)) / (std::log(hi_n) - std::log(lo_n));
        next = std::exp(std::log(lo) + std::clamp(t, 0.1, 0.9) * (std::log(hi) - std::log(lo)));
      } else {
        next = cells * std::clamp(std::sqrt(aim / std::max(n, 1.0)), 0.25, 4.0);
        next = std::clamp(next, lo, hi);
      }
      if (hi - lo < 1e-3 * lo) break;
      cells = next;
    }
    const double unique = double(count_unique(s, p, g));
    probes++;
    const double miss = std::fabs(unique - double(target));
    // Equally far: keep more faces (a tiny mesh may offer only "all" or "none").
    current = miss < best_miss || (miss == best_miss && unique > best_unique);
    if (current) best_miss = miss, best_unique = unique, best = g;
    if (miss <= options.tolerance * double(target) || unique <= 0) break;
    aim *= double(target) / unique;
    cells = g.cells * std::sqrt(double(target) / std::max(unique, 1.0));
  }
  return best;
}

}  // namespace

namespace {

size_t cluster_run(std::vector<uint32_t>& out_indices, std::vector<float>& out_positions,
                   std::vector<float>* out_attributes, std::vector<uint32_t>* out_source, Scratch& s,
                   const Prepared& p, size_t target, const float* positions, const ClusterOptions& options,
                   ClusterResult& result) {
  const size_t faces = p.triangles.size() / 3;
  const size_t ac = options.attributes ? options.attribute_count : 0;
  result = ClusterResult{};
  out_indices.clear();
  out_positions.clear();
  if (out_attributes) out_attributes->clear();
  if (out_source) out_source->clear();
  if (target >= faces || faces == 0) {
    // Nothing to remove: the valid faces as they are, on their own vertices.
    std::vector<uint32_t> map(p.vertex_count, ~0u);
    for (uint32_t v : p.triangles) {
      if (map[v] == ~0u) {
        map[v] = uint32_t(out_positions.size() / 3);
        out_positions.insert(out_positions.end(), positions + 3 * size_t(v), positions + 3 * size_t(v) + 3);
        if (out_attributes && ac)
          out_attributes->insert(out_attributes->end(), options.attributes + ac * v, options.attributes + ac * (v + 1));
        if (out_source) out_source->push_back(v);
      }
      out_indices.push_back(map[v]);
    }
    result.triangles = out_indices.size() / 3;
    result.vertices = out_positions.size() / 3;
    return result.triangles;
  }

  // Small targets: cluster to a few times the target, then let QEM edge collapse (cheap at that
  // size) choose which detail goes; clustering alone spends faces evenly over the grid.
  const size_t grid_target = target * kRefine * kRefineLimit <= faces ? target * kRefine : target;
  bool current = false;
  const Grid g = target == 0 ? make_grid(p, 1) : search_grid(s, p, grid_target, options, current);
  size_t clusters = 0;
  if (current) {
    for (uint32_t c : s.cluster) clusters = std::max<size_t>(clusters, c + 1);
  } else {
    cell_ids(s.ids, p, g);
    clusters = number_cells(s, p);
  }

  // Lindstrom: every face's plane quadric goes to the cells of its corners.
  struct CellQuadric {
    double a00, a11, a22, a01, a02, a12, b0, b1, b2, c, w;
    double sx, sy, sz;
    uint32_t n;
  };
  std::vector<CellQuadric> q(clusters, CellQuadric{});
  for (size_t v = 0; v < p.vertex_count; ++v) {
    CellQuadric& c = q[s.cluster[v]];
    c.sx += p.unit[3 * v], c.sy += p.unit[3 * v + 1], c.sz += p.unit[3 * v + 2];
    c.n++;
  }
  for (size_t i = 0; i < p.triangles.size(); i += 3) {
    const float* p0 = &p.unit[3 * size_t(p.triangles[i])];
    const float* p1 = &p.unit[3 * size_t(p.triangles[i + 1])];
    const float* p2 = &p.unit[3 * size_t(p.triangles[i + 2])];
    const double e1[3] = {double(p1[0]) - p0[0], double(p1[1]) - p0[1], double(p1[2]) - p0[2]};
    const double e2[3] = {double(p2[0]) - p0[0], double(p2[1]) - p0[1], double(p2[2]) - p0[2]};
    double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0)) continue;
    for (double& x : n) x /= len;
    const double d = -(n[0] * p0[0] + n[1] * p0[1] + n[2] * p0[2]);
    const double w = 0.5 * len;
    const uint32_t c0 = s.cluster[p.triangles[i]], c1 = s.cluster[p.triangles[i + 1]], c2 = s.cluster[p.triangles[i + 2]];
    auto add = [&](CellQuadric& r) {
      r.a00 += w * n[0] * n[0], r.a11 += w * n[1] * n[1], r.a22 += w * n[2] * n[2];
      r.a01 += w * n[0] * n[1], r.a02 += w * n[0] * n[2], r.a12 += w * n[1] * n[2];
      r.b0 += w * n[0] * d, r.b1 += w * n[1] * d, r.b2 += w * n[2] * d;
      r.c += w * d * d, r.w += w;
    };
    add(q[c0]);  // once per distinct cell
    if (c1 != c0) add(q[c1]);
    if (c2 != c0 && c2 != c1) add(q[c2]);
  }

  // Each cell's vertex: the regularised quadric minimum, kept inside the cell.
  std::vector<float> rep(3 * clusters);
  const double cell = 1.0 / g.cells;
  double worst = 0;
  for (size_t k = 0; k < clusters; ++k) {
    const CellQuadric& c = q[k];
    const double m[3] = {c.sx / c.n, c.sy / c.n, c.sz / c.n};
    const double lambda = kRegularisation * (c.a00 + c.a11 + c.a22) + 1e-30;
    const double a00 = c.a00 + lambda, a11 = c.a11 + lambda, a22 = c.a22 + lambda;
    const double r0 = -c.b0 + lambda * m[0], r1 = -c.b1 + lambda * m[1], r2 = -c.b2 + lambda * m[2];
    const double c00 = a11 * a22 - c.a12 * c.a12, c01 = c.a02 * c.a12 - c.a01 * a22, c02 = c.a01 * c.a12 - c.a02 * a11;
    const double det = a00 * c00 + c.a01 * c01 + c.a02 * c02;
    double x[3] = {m[0], m[1], m[2]};
    if (det > 1e-300) {
      const double c11 = a00 * a22 - c.a02 * c.a02, c12 = c.a01 * c.a02 - a00 * c.a12, c22 = a00 * a11 - c.a01 * c.a01;
      const double sol[3] = {(c00 * r0 + c01 * r1 + c02 * r2) / det, (c01 * r0 + c11 * r1 + c12 * r2) / det,
                             (c02 * r0 + c12 * r1 + c22 * r2) / det};
      // Cell bounds from the centroid's cell; a solution outside is pulled back in.
      for (int d = 0; d < 3; ++d) {
        const double lo = std::floor(m[d] * g.cells) * cell;
        x[d] = std::isfinite(sol[d]) ? std::clamp(sol[d], lo, lo + cell) : m[d];
      }
    }
    const double e = x[0] * (c.a00 * x[0] + c.a01 * x[1] + c.a02 * x[2]) + x[1] * (c.a01 * x[0] + c.a11 * x[1] + c.a12 * x[2]) +
                     x[2] * (c.a02 * x[0] + c.a12 * x[1] + c.a22 * x[2]) + 2 * (c.b0 * x[0] + c.b1 * x[1] + c.b2 * x[2]) + c.c;
    if (c.w > 0) worst = std::max(worst, std::max(e, 0.0) / c.w);
    for (int d = 0; d < 3; ++d) rep[3 * k + d] = float(x[d]);
  }
  // Only cells some face still uses become vertices.
  s.out_faces.clear();
  unique_faces(s.faces, s.table, s.cluster, p, &s.out_faces);
  std::vector<uint32_t> used(clusters, ~0u);
  std::vector<uint32_t> first_vertex(clusters, ~0u);
  for (size_t v = 0; v < p.vertex_count; ++v)
    if (first_vertex[s.cluster[v]] == ~0u) first_vertex[s.cluster[v]] = uint32_t(v);
  for (uint32_t c : s.out_faces) {
    if (used[c] == ~0u) {
      used[c] = uint32_t(out_positions.size() / 3);
      for (int d = 0; d < 3; ++d) out_positions.push_back(rep[3 * c + d] * p.extent + p.origin[d]);
      if (out_source) out_source->push_back(first_vertex[c]);
    }
    out_indices.push_back(used[c]);
  }
  if (out_attributes && ac) {
    // Mean attribute of each used cell's vertices.
    std::vector<double> sum(ac * clusters, 0.0);
    for (size_t v = 0; v < p.vertex_count; ++v)
      for (size_t k = 0; k < ac; ++k) sum[ac * s.cluster[v] + k] += options.attributes[ac * v + k];
    out_attributes->assign(ac * (out_positions.size() / 3), 0.f);
    for (size_t c = 0; c < clusters; ++c) {
      if (used[c] == ~0u) continue;
      for (size_t k = 0; k < ac; ++k) (*out_attributes)[ac * used[c] + k] = float(sum[ac * c + k] / q[c].n);
    }
  }
  if (grid_target != target) {
    ChainLevelOut level;
    QemOptions qo;
    qo.move_nonmanifold = false;  // clustering leaves many; moving them costs accuracy here
    qo.attributes = out_attributes && ac ? out_attributes->data() : nullptr;
    qo.attribute_count = ac;
    qem_simplify_chain(&level, out_positions.data(), out_positions.size() / 3, out_indices.data(), out_indices.size(),
                       &target, 1, qo);
    std::vector<uint32_t> src;
    if (out_source)
      for (uint32_t v : level.source_vertex) src.push_back((*out_source)[v]);
    out_indices.swap(level.indices);
    out_positions.swap(level.positions);
    if (out_attributes) out_attributes->swap(level.attributes);
    if (out_source) out_source->swap(src);
    worst = std::max(worst, double(level.error / p.extent) * double(level.error / p.extent));
  }
  result.triangles = out_indices.size() / 3;
  result.vertices = out_positions.size() / 3;
  result.cell_size = float(cell * p.extent);
  result.error = float(std::sqrt(worst) * p.extent);
  return result.triangles;
}

}  // namespace

size_t cluster_simplify(uint32_t* destination_indices, float* destination_positions, const float* positions,
                        size_t vertex_count, const uint32_t* indices, size_t index_count, size_t target_triangles,
                        const ClusterOptions& options, ClusterResult* result) {
  Prepared p;
  prepare(p, positions, vertex_count, indices, index_count);
  Scratch s;
  std::vector<uint32_t> out_indices;
  std::vector<float> out_positions;
  ClusterResult r;
  cluster_run(out_indices, out_positions, nullptr, nullptr, s, p, target_triangles, positions, options, r);
  std::copy(out_indices.begin(), out_indices.end(), destination_indices);
  std::copy(out_positions.begin(), out_positions.end(), destination_positions);
  if (result) *result = r;
  return r.triangles;
}

size_t cluster_simplify_chain(ChainLevelOut* levels, const float* positions, size_t vertex_count,
                              const uint32_t* indices, size_t index_count, const size_t* target_triangles,
                              size_t level_count, const ClusterOptions& options) {
  Prepared p;
  prepare(p, positions, vertex_count, indices, index_count);
  Scratch s;
  float error = 0;
  for (size_t l = 0; l < level_count; ++l) {
    ChainLevelOut& level = levels[l];
    ClusterResult r;
    cluster_run(level.indices, level.positions, &level.attributes, &level.source_vertex, s, p, target_triangles[l],
                positions, options, r);
    error = std::max(error, r.error);
    level.target_triangles = target_triangles[l];
    level.error = error;
    level.reached = double(r.triangles) <= (1 + options.tolerance) * double(target_triangles[l]) + 1;
  }
  return level_count;
}

}  // namespace lod
