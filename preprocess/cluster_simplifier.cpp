// Grid vertex clustering with quadric representatives (see cluster_simplifier.h for the papers).
//
// Passes: normalise positions and compute face planes and vertex normals once; search the grid
// resolution (each probe: cell id per vertex, then count the faces whose corners fall in three
// different cells); for the chosen grid, number the occupied cells, split the cells whose
// vertices face opposite ways, sum each cell's face quadrics, solve for its vertex, and emit
// the surviving faces once each. The face count that matters is after the split and after
// duplicates are removed, which the cheap probe cannot see, so the search is re-aimed by the
// observed ratio.
#include "preprocess/cluster_simplifier.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "runtime/bytes_hasher.h"

namespace lod {
namespace {

// Regularisation of each cell's 3x3 system towards the cell's vertex centroid.
constexpr double kRegularisation = 1e-3;
// Targets below faces / kRefineLimit are clustered to kRefine times the target and finished by
// QEM edge collapse, which is cheap at that size and places the last faces where they matter.
// On inputs below kSmallInput faces the finish is a large share of the time, so the grid aims
// at kRefineSmall times the target instead (66k buddha at 1.5 %: 3.8 -> 2.95 ms, RMS 0.72 ->
// 0.70x sloppy's; on the 871k dragon 1.5x cost extra probes at 0.18 %, so 2x stays there).
constexpr double kRefine = 2;
constexpr double kRefineSmall = 1.5;
constexpr size_t kSmallInput = 250000;
constexpr size_t kRefineLimit = 30;
constexpr double kMaxGrid = 1 << 20;  // cells along the longest axis

struct Prepared {
  std::vector<float> unit;          // positions in [0,1] of the longest axis
  std::vector<uint32_t> triangles;  // valid faces only
  std::vector<float> planes;        // per valid face: unit normal, offset, area (0s when degenerate)
  std::vector<float> normals;       // per vertex, area-weighted
  float origin[3] = {0, 0, 0};
  float extent = 1;                 // longest side of the bounding box
  float span[3] = {1, 1, 1};        // each side / extent
  double area = 0;                  // surface area in those units
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
  p.triangles.resize(index_count - index_count % 3);
  p.planes.resize(5 * (index_count / 3));
  p.normals.assign(3 * vertex_count, 0.f);
  size_t kept = 0;
  double area = 0;
  const float* u = p.unit.data();
  for (size_t t = 0; t + 2 < index_count; t += 3) {
    const uint32_t a = indices[t], b = indices[t + 1], c = indices[t + 2];
    if (a >= vertex_count || b >= vertex_count || c >= vertex_count) continue;
    if (a == b || b == c || a == c || !finite[a] || !finite[b] || !finite[c]) continue;
    const float e1[3] = {u[3 * b] - u[3 * a], u[3 * b + 1] - u[3 * a + 1], u[3 * b + 2] - u[3 * a + 2]};
    const float e2[3] = {u[3 * c] - u[3 * a], u[3 * c + 1] - u[3 * a + 1], u[3 * c + 2] - u[3 * a + 2]};
    float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    float* plane = &p.planes[5 * (kept / 3)];
    if (len > 0) {
      const float r = 1 / len;
      for (float& x : n) x *= r;
      plane[0] = n[0], plane[1] = n[1], plane[2] = n[2];
      plane[3] = -(n[0] * u[3 * a] + n[1] * u[3 * a + 1] + n[2] * u[3 * a + 2]);
      plane[4] = 0.5f * len;
      area += plane[4];
      // Area-weighted vertex normals (unnormalised: only their directions are compared).
      for (const uint32_t v : {a, b, c}) {
        float* vn = &p.normals[3 * size_t(v)];
        vn[0] += plane[4] * n[0], vn[1] += plane[4] * n[1], vn[2] += plane[4] * n[2];
      }
    } else {
      plane[0] = plane[1] = plane[2] = plane[3] = plane[4] = 0;  // zero-area faces carry no plane
    }
    p.triangles[kept++] = a, p.triangles[kept++] = b, p.triangles[kept++] = c;
  }
  p.triangles.resize(kept);
  p.planes.resize(5 * (kept / 3));
  p.area = area;
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

// Whether every cell id of the grid fits 32 bits (halves the probes' memory traffic).
bool narrow_ids(const Grid& g) { return double(g.dims[0]) * double(g.dims[1]) * double(g.dims[2]) < 4294967295.0; }

template <typename Id>
void cell_ids(Id* ids, const Prepared& p, const Grid& g) {
  const float s = float(g.cells);
  const int64_t d0 = int64_t(g.dims[0]), d1 = int64_t(g.dims[1]), d2 = int64_t(g.dims[2]);
  const float* u = p.unit.data();
  for (size_t v = 0; v < p.vertex_count; ++v) {
    const int64_t x = std::min(int64_t(u[3 * v] * s), d0 - 1);
    const int64_t y = std::min(int64_t(u[3 * v + 1] * s), d1 - 1);
    const int64_t z = std::min(int64_t(u[3 * v + 2] * s), d2 - 1);
    ids[v] = Id(uint64_t(x) + uint64_t(d0) * (uint64_t(y) + uint64_t(d1) * uint64_t(z)));
  }
}

// Faces whose corners lie in three different cells (duplicates included).
template <typename Id>
size_t count_spanning(const Id* ids, const Prepared& p) {
  size_t n = 0;
  const uint32_t* t = p.triangles.data();
  for (size_t i = 0; i < p.triangles.size(); i += 3) {
    const Id a = ids[t[i]], b = ids[t[i + 1]], c = ids[t[i + 2]];
    n += (a != b) & (b != c) & (a != c);
  }
  return n;
}

// Open-addressing table from 64-bit cell id to dense cluster number; grows as it fills, so
// it can start at the size the search expects rather than one slot pair per vertex.
struct CellTable {
  struct Entry {
    uint64_t key;
    uint32_t value, unused;
  };
  std::vector<Entry> entries, old;
  size_t mask = 0, count = 0;
  void reset(size_t expected) {
    size_t cap = 64;
    while (cap < 2 * expected) cap *= 2;
    entries.assign(cap, Entry{~0ull, 0, 0});
    mask = cap - 1;
    count = 0;
  }
  uint32_t insert(uint64_t key, uint32_t next) {
    if (2 * (count + 1) > entries.size()) grow();
    size_t slot = detail::fmix64(key) & mask;
    while (entries[slot].key != ~0ull && entries[slot].key != key) slot = (slot + 1) & mask;
    if (entries[slot].key == ~0ull) entries[slot] = Entry{key, next, 0}, count++;
    return entries[slot].value;
  }
  void grow() {
    old.swap(entries);
    entries.assign(2 * old.size(), Entry{~0ull, 0, 0});
    mask = entries.size() - 1;
    for (const Entry& e : old) {
      if (e.key == ~0ull) continue;
      size_t slot = detail::fmix64(e.key) & mask;
      while (entries[slot].key != ~0ull) slot = (slot + 1) & mask;
      entries[slot] = e;
    }
  }
};

// Hash lookups go in batches: the slots of a batch are fetched together, then used in order
// (same result as one at a time, without waiting on each miss).
constexpr size_t kBatch = 16;

// Faces left after clustering, canonically rotated (smallest cluster first, orientation
// kept), each set of three cells once. Returns their count; writes them to `out` when given.
size_t unique_faces(std::vector<uint32_t>& faces, std::vector<uint64_t>& table, const std::vector<uint32_t>& cluster,
                    size_t clusters, const Prepared& p, std::vector<uint32_t>* out) {
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
  const size_t mask = cap - 1;
  // Same three cells in either orientation is one face (a two-sided sliver otherwise). The
  // key packs the three cluster numbers when they fit 21 bits each, else it is the first
  // face's index (the faces are compared then).
  const bool packed = clusters < (size_t(1) << 21);
  table.assign(cap, ~0ull);
  auto key_of = [&](size_t f) {
    const uint32_t* x = &faces[3 * f];
    const uint64_t xl = std::min(x[1], x[2]), xh = std::max(x[1], x[2]);
    return packed ? uint64_t(x[0]) << 42 | xl << 21 | xh : detail::fmix64(uint64_t(x[0]) * 0x9e3779b97f4a7c15ull ^ (xl << 32 | xh));
  };
  auto same = [&](size_t f, uint64_t stored, uint64_t key) {
    if (packed) return stored == key;
    const uint32_t* x = &faces[3 * f];
    const uint32_t* y = &faces[3 * stored];
    return y[0] == x[0] && std::min(y[1], y[2]) == std::min(x[1], x[2]) && std::max(y[1], y[2]) == std::max(x[1], x[2]);
  };
  size_t kept = 0;
  uint64_t keys[kBatch];
  for (size_t f0 = 0; f0 < n; f0 += kBatch) {
    const size_t m = std::min(kBatch, n - f0);
    for (size_t j = 0; j < m; ++j) {
      keys[j] = key_of(f0 + j);
      __builtin_prefetch(&table[(packed ? detail::fmix64(keys[j]) : keys[j]) & mask]);
    }
    for (size_t j = 0; j < m; ++j) {
      const size_t f = f0 + j;
      size_t slot = (packed ? detail::fmix64(keys[j]) : keys[j]) & mask;
      bool duplicate = false;
      while (table[slot] != ~0ull) {
        if (same(f, table[slot], keys[j])) {
          duplicate = true;
          break;
        }
        slot = (slot + 1) & mask;
      }
      if (duplicate) continue;
      table[slot] = packed ? keys[j] : uint64_t(f);
      if (out) out->insert(out->end(), &faces[3 * f], &faces[3 * f] + 3);
      kept++;
    }
  }
  return kept;
}

struct Scratch {
  std::vector<uint64_t> ids;
  std::vector<uint32_t> ids32;
  std::vector<uint32_t> cluster, faces, out_faces;
  std::vector<uint64_t> table;
  std::vector<uint32_t> best_cluster, best_faces;
  std::vector<uint32_t> reference, twin;
  CellTable cells;
};

// Spanning-face count of one grid.
size_t probe(Scratch& s, const Prepared& p, const Grid& g) {
  if (narrow_ids(g)) {
    s.ids32.resize(p.vertex_count);
    cell_ids(s.ids32.data(), p, g);
    return count_spanning(s.ids32.data(), p);
  }
  s.ids.resize(p.vertex_count);
  cell_ids(s.ids.data(), p, g);
  return count_spanning(s.ids.data(), p);
}

// Dense cluster number per vertex (s.cluster); returns the number of clusters.
// `expected`: about how many cells (the table grows past it).
// `probed`: s.ids32 already holds this grid's ids (it was the last probe).
size_t number_cells(Scratch& s, const Prepared& p, const Grid& g, size_t expected, bool probed) {
  const bool narrow = probed && narrow_ids(g);
  if (!narrow) {
    s.ids.resize(p.vertex_count);
    cell_ids(s.ids.data(), p, g);
  }
  s.cells.reset(std::min(expected, p.vertex_count));
  s.cluster.resize(p.vertex_count);
  uint32_t next = 0;
  uint64_t last_id = ~0ull;
  uint32_t last = 0;
  for (size_t v = 0; v < p.vertex_count; ++v) {
    // Neighbouring vertices often share a cell: skip the table then.
    const uint64_t id = narrow ? uint64_t(s.ids32[v]) : s.ids[v];
    if (id != last_id) {
      last = s.cells.insert(id, next);
      last_id = id;
      if (last == next) next++;
    }
    s.cluster[v] = last;
  }
  // A cell holding both sides of a thin part (a tube or sheet thinner than the cell) would
  // fold them into one vertex, and the faces between them would vanish with the part: its
  // vertices facing away from the cell's first vertex get a cluster of their own.
  const size_t cells = next;
  s.reference.assign(cells, ~0u);
  s.twin.assign(cells, ~0u);
  const float* nrm = p.normals.data();
  for (size_t v = 0; v < p.vertex_count; ++v) {
    const uint32_t c = s.cluster[v];
    if (s.reference[c] == ~0u) {
      s.reference[c] = uint32_t(v);
      continue;
    }
    const float* r = nrm + 3 * size_t(s.reference[c]);
    const float* n = nrm + 3 * v;
    if (r[0] * n[0] + r[1] * n[1] + r[2] * n[2] >= 0) continue;
    if (s.twin[c] == ~0u) s.twin[c] = next++;
    s.cluster[v] = s.twin[c];
  }
  return next;
}

// Grid whose unique face count is close to `target`. Probes count only the faces spanning
// three cells (a pass over vertices and one over faces) and interpolate the grid size in log
// space; the closest probe is then clustered for real, its unique faces being what the output
// holds. When those miss the tolerance, the aim is corrected by the observed unique/spanning
// ratio and the search goes on. The best grid's clusters and faces are left in
// s.best_cluster and s.best_faces.
Grid search_grid(Scratch& s, const Prepared& p, size_t target, double tolerance, int max_probes) {
  const size_t faces = p.triangles.size() / 3;
  Grid best = make_grid(p, 1);
  double best_miss = std::numeric_limits<double>::max(), best_unique = -1;
  // Counts are searched as t(n) = -ln(1 - n / faces), which grows about as cells^2 on every
  // grid: a surface of area A meets about kCellsPerArea * A * cells^2 cells, each spanning
  // face is one more, and on fine grids the count saturates at the face count.
  const double all = double(std::max<size_t>(faces, 1));
  auto linear = [all](double n) { return -std::log(1 - std::min(std::max(n, 1.0), 0.999 * all) / all); };
  constexpr double kCellsPerArea = 2.5;
  // Every probe is kept: a later round (aiming elsewhere) brackets and interpolates with them.
  struct Probe {
    double cells, n;
  };
  std::vector<Probe> history;
  // Next grid for `aim`: between the closest probes below and above it (log t against log
  // cells), else a step from the closest probe with the local slope (2 when unknown).
  auto predict = [&](double aim) {
    const double aim_t = linear(aim);
    const Probe* below = nullptr;
    const Probe* above = nullptr;
    for (const Probe& h : history) {
      if (h.n < aim && (!below || h.n > below->n || (h.n == below->n && h.cells > below->cells))) below = &h;
      if (h.n >= aim && (!above || h.n < above->n || (h.n == above->n && h.cells < above->cells))) above = &h;
    }
    if (below && above && below->n > 0 && above->cells > below->cells) {
      const double l = std::log(below->cells), h = std::log(above->cells);
      const double tl = std::log(linear(below->n)), th = std::log(linear(above->n));
      const double f = th > tl ? (std::log(aim_t) - tl) / (th - tl) : 0.5;
      // Strictly inside, so the bracket shrinks even when the interpolation overshoots.
      return std::exp(l + std::clamp(f, 0.1, 0.9) * (h - l));
    }
    const Probe* near = below ? below : above;
    double slope = 2;
    for (const Probe& h : history)
      if (&h != near && h.cells != near->cells && h.n > 0 && near->n > 0 && linear(h.n) != linear(near->n)) {
        slope = std::clamp((std::log(linear(h.n)) - std::log(linear(near->n))) /
                               (std::log(h.cells) - std::log(near->cells)),
                           0.5, 4.0);
        break;
      }
    return near->cells * std::exp(std::clamp((std::log(aim_t) - std::log(linear(near->n))) / slope, -1.5, 1.5));
  };
  double aim = double(target);
  double cells = std::sqrt(linear(aim) * all / (kCellsPerArea * std::max(p.area, 1e-12)));
  int probes = 0;
  double numbered = -1;  // grid last clustered for real
  double probed = -1;    // grid whose ids the last probe left
  for (int round = 0; round < 4 && probes < max_probes; ++round) {
    for (int i = 0; i < 12 && probes < max_probes; ++i, ++probes) {
      cells = std::clamp(cells, 1.0, kMaxGrid);
      const double n = double(probe(s, p, make_grid(p, cells)));
      probed = cells;
      history.push_back({cells, n});
      // Later rounds know the unique/spanning ratio: aim closer, a probe costs less than a round.
      if (std::fabs(n - aim) <= (round == 0 ? 0.5 : 0.25) * tolerance * aim) break;
      const double next = predict(aim);
      if (std::fabs(next - cells) < 1e-3 * cells) break;
      cells = next;
    }
    // The closest probe to the aim (equally close: the one with more faces) is clustered.
    const Probe* g = &history.front();
    for (const Probe& h : history) {
      const double m = std::fabs(h.n - aim), gm = std::fabs(g->n - aim);
      if (m < gm || (m == gm && h.n > g->n)) g = &h;
    }
    if (g->cells == numbered) break;  // nothing new to try
    numbered = g->cells;
    const Grid grid = make_grid(p, g->cells);
    // A closed surface has about half as many vertices as faces.
    const size_t clusters = number_cells(s, p, grid, size_t(g->n / 2) + 64, g->cells == probed);
    s.out_faces.clear();
    const double unique = double(unique_faces(s.faces, s.table, s.cluster, clusters, p, &s.out_faces));
    probes++;
    const double miss = std::fabs(unique - double(target));
    // Equally far: keep more faces (a tiny mesh may offer only "all" or "none").
    if (miss < best_miss || (miss == best_miss && unique > best_unique)) {
      best_miss = miss, best_unique = unique, best = grid;
      s.best_cluster.swap(s.cluster);
      s.best_faces.swap(s.out_faces);
    }
    if (miss <= tolerance * double(target) || unique <= 0) break;
    // Unique faces (after the facing split and duplicates) track the spanning count closely:
    // aim the spanning count at what gives the target.
    aim = std::max(1.0, g->n * double(target) / unique);
    cells = predict(aim);
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

  if (target == 0) {
    // Nothing asked for: no faces (one cell would still split by facing).
    result.cell_size = p.extent;
    return 0;
  }
  // Small targets: cluster to a few times the target, then let QEM edge collapse (cheap at that
  // size) choose which detail goes; clustering alone spends faces evenly over the grid.
  const bool refine = double(target) * kRefine * kRefineLimit <= double(faces);
  const double factor = faces < kSmallInput ? kRefineSmall : kRefine;
  const size_t grid_target = refine ? size_t(double(target) * factor) : target;
  // The finish lands on the target exactly, so the grid it starts from need not.
  constexpr double kRefineTolerance = 0.25;
  const Grid g = search_grid(s, p, grid_target, grid_target != target ? kRefineTolerance : options.tolerance,
                             options.max_probes);
  s.cluster.swap(s.best_cluster);
  size_t clusters = 0;
  for (uint32_t c : s.cluster) clusters = std::max<size_t>(clusters, c + 1);

  // Lindstrom: every face's plane quadric goes to the cells of its corners. Floats, relative to
  // each cell's first vertex so that nothing cancels: half the memory traffic of doubles.
  struct CellQuadric {
    float a00, a11, a22, a01, a02, a12, b0, b1, b2, c, w;
    float ox, oy, oz;  // origin: the cell's first vertex
    float sx, sy, sz;  // vertex sum, relative to the origin
    uint32_t n;
  };
  std::vector<CellQuadric> q(clusters, CellQuadric{});
  std::vector<uint32_t> first_vertex(clusters);  // also each output vertex's source
  const float* unit = p.unit.data();
  for (size_t v = 0; v < p.vertex_count; ++v) {
    CellQuadric& c = q[s.cluster[v]];
    if (c.n == 0) c.ox = unit[3 * v], c.oy = unit[3 * v + 1], c.oz = unit[3 * v + 2], first_vertex[s.cluster[v]] = uint32_t(v);
    c.sx += unit[3 * v] - c.ox, c.sy += unit[3 * v + 1] - c.oy, c.sz += unit[3 * v + 2] - c.oz;
    c.n++;
  }
  for (size_t i = 0; i < p.triangles.size(); i += 3) {
    const float* plane = &p.planes[5 * (i / 3)];
    const float w = plane[4];
    if (!(w > 0)) continue;
    const float n[3] = {plane[0], plane[1], plane[2]};
    const float wn[3] = {w * n[0], w * n[1], w * n[2]};
    const uint32_t c0 = s.cluster[p.triangles[i]], c1 = s.cluster[p.triangles[i + 1]], c2 = s.cluster[p.triangles[i + 2]];
    auto add = [&](uint32_t k) {
      CellQuadric& r = q[k];
      const float d = plane[3] + n[0] * r.ox + n[1] * r.oy + n[2] * r.oz;  // offset from the cell's origin
      r.a00 += wn[0] * n[0], r.a11 += wn[1] * n[1], r.a22 += wn[2] * n[2];
      r.a01 += wn[0] * n[1], r.a02 += wn[0] * n[2], r.a12 += wn[1] * n[2];
      r.b0 += wn[0] * d, r.b1 += wn[1] * d, r.b2 += wn[2] * d;
      r.c += w * d * d, r.w += w;
    };
    add(c0);  // once per distinct cell
    if (c1 != c0) add(c1);
    if (c2 != c0 && c2 != c1) add(c2);
  }

  // Each cell's vertex: the regularised quadric minimum, kept inside the cell.
  std::vector<float> rep(3 * clusters);
  const double cell = 1.0 / g.cells;
  double worst = 0;
  for (size_t k = 0; k < clusters; ++k) {
    const CellQuadric& c = q[k];
    const float o[3] = {c.ox, c.oy, c.oz};
    const double m[3] = {double(c.sx) / c.n, double(c.sy) / c.n, double(c.sz) / c.n};  // local centroid
    const double lambda = kRegularisation * (double(c.a00) + c.a11 + c.a22) + 1e-30;
    const double a00 = c.a00 + lambda, a11 = c.a11 + lambda, a22 = c.a22 + lambda;
    const double a01 = c.a01, a02 = c.a02, a12 = c.a12;
    const double r0 = -c.b0 + lambda * m[0], r1 = -c.b1 + lambda * m[1], r2 = -c.b2 + lambda * m[2];
    const double c00 = a11 * a22 - a12 * a12, c01 = a02 * a12 - a01 * a22, c02 = a01 * a12 - a02 * a11;
    const double det = a00 * c00 + a01 * c01 + a02 * c02;
    double x[3] = {m[0], m[1], m[2]};
    if (det > 1e-300) {
      const double c11 = a00 * a22 - a02 * a02, c12 = a01 * a02 - a00 * a12, c22 = a00 * a11 - a01 * a01;
      const double sol[3] = {(c00 * r0 + c01 * r1 + c02 * r2) / det, (c01 * r0 + c11 * r1 + c12 * r2) / det,
                             (c02 * r0 + c12 * r1 + c22 * r2) / det};
      // Cell bounds from the centroid's cell; a solution outside is pulled back in.
      for (int d = 0; d < 3; ++d) {
        const double lo = std::floor((o[d] + m[d]) * g.cells) * cell - o[d];
        x[d] = std::isfinite(sol[d]) ? std::clamp(sol[d], lo, lo + cell) : m[d];
      }
    }
    const double e = x[0] * (c.a00 * x[0] + a01 * x[1] + a02 * x[2]) + x[1] * (a01 * x[0] + c.a11 * x[1] + a12 * x[2]) +
                     x[2] * (a02 * x[0] + a12 * x[1] + c.a22 * x[2]) + 2 * (c.b0 * x[0] + c.b1 * x[1] + c.b2 * x[2]) + c.c;
    if (c.w > 0) worst = std::max(worst, std::max(e, 0.0) / c.w);
    for (int d = 0; d < 3; ++d) rep[3 * k + d] = float(o[d] + x[d]);
  }
  // Only cells some face still uses become vertices.
  s.out_faces.swap(s.best_faces);
  std::vector<uint32_t> used(clusters, ~0u);
  out_positions.reserve(3 * clusters);
  out_indices.reserve(s.out_faces.size());
  if (out_source) out_source->reserve(clusters);
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
    // Split cells leave fins and doubled edges behind; locking their vertices would stall
    // the finish above its target.
    qo.move_nonmanifold = true;
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
