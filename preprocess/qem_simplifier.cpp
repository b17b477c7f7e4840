// QEM edge collapse in sorted passes (see qem_simplifier.h for the papers).
//
// Once per call: vertex kinds (manifold / border / seam / locked) and border loops; a seam
// vertex is one of two copies at a position whose open edges are each other's twins, and it
// collapses only with its copy, along both sides of the seam at once. On manifold input kinds
// and loops stay valid because every allowed collapse keeps them (next to a non-manifold vertex
// a loop may point at a vertex gone since, which only leaves that border edge uncollapsed).
// Each pass: build vertex -> face lists (CSR, each entry the face's other two corners) from
// the current index buffer; give every collapsible edge its position and quadric cost;
// radix-sort the costs; collapse in order, skipping an edge when either end was already
// touched this pass (its cost is stale) or when the collapse would break the link condition
// or flip/fold a face; then rewrite the index buffer through the remap table. Scratch arrays
// are sized once per call and reused by every pass; the only other allocations are vertex
// compactions, each after the face count halves.
#include "preprocess/qem_simplifier.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "preprocess/edge_parameter.h"
#include "preprocess/position_copies.h"

namespace lod {
namespace {

constexpr uint8_t kManifold = 0;
constexpr uint8_t kBorder = 1;
constexpr uint8_t kLocked = 2;
// One of a pair of copies on an attribute seam: it collapses only onto its neighbour along
// its side of the seam, and its copy onto the same neighbour's copy on the other side.
constexpr uint8_t kSeam = 3;

// A collapse must not turn a face by more than this (cosine between old and new normal):
// 0 would only refuse flips; a margin also refuses folds that create near-vertical slivers.
constexpr float kMinNormalCos = 0.2f;
// Optimal placement is regularised towards the edge midpoint by this fraction of trace(A), so
// flat and crease regions (rank-deficient A) still get a well-defined, nearby optimum.
constexpr double kRegularisation = 1e-3;
// Edges at vertices with more faces than this are left alone: checking a collapse walks the
// faces of both ends, and a hub of a huge fan would make every pass quadratic.
constexpr uint32_t kMaxValence = 256;
// Passes per level before giving up (each removes at least one face); real meshes need ~10.
constexpr int kMaxPassesPerLevel = 100;
// Below this many faces a split costs more than it saves.
constexpr size_t kMinSplitTriangles = 20000;
// Weight of each vertex's point quadric, relative to the mean vertex area.
constexpr double kPointWeight = 1e-3;
// An optimum farther than this many edge lengths from the midpoint is distrusted.
constexpr double kMaxPlacementDistance = 1.5;

void quadric_add_plane(Quadric& q, double nx, double ny, double nz, double d, double w) {
  q.a00 += w * nx * nx;
  q.a11 += w * ny * ny;
  q.a22 += w * nz * nz;
  q.a01 += w * nx * ny;
  q.a02 += w * nx * nz;
  q.a12 += w * ny * nz;
  q.b0 += w * nx * d;
  q.b1 += w * ny * d;
  q.b2 += w * nz * d;
  q.c += w * d * d;
  q.w += w;
}

inline __attribute__((always_inline)) void quadric_add(Quadric& q, const Quadric& r) {
  q.a00 += r.a00;
  q.a11 += r.a11;
  q.a22 += r.a22;
  q.a01 += r.a01;
  q.a02 += r.a02;
  q.a12 += r.a12;
  q.b0 += r.b0;
  q.b1 += r.b1;
  q.b2 += r.b2;
  q.c += r.c;
  q.w += r.w;
}

inline __attribute__((always_inline)) Quadric quadric_sum(const Quadric& a, const Quadric& b) {
  Quadric q = a;
  quadric_add(q, b);
  return q;
}

double quadric_eval(const Quadric& q, double x, double y, double z) {
  const double ax = q.a00 * x + q.a01 * y + q.a02 * z;
  const double ay = q.a01 * x + q.a11 * y + q.a12 * z;
  const double az = q.a02 * x + q.a12 * y + q.a22 * z;
  const double r = x * ax + y * ay + z * az + 2 * (q.b0 * x + q.b1 * y + q.b2 * z) + q.c;
  return r > 0 ? r : 0;
}

// Normalised error: area-weighted mean squared plane distance.
float quadric_cost(const Quadric& q, const float* p) {
  const double e = quadric_eval(q, p[0], p[1], p[2]);
  return q.w > 0 ? float(e / q.w) : float(e);
}

void attribute_add(AttributeQuadric& q, const AttributeQuadric& r) {
  q.a00 += r.a00, q.a11 += r.a11, q.a22 += r.a22, q.a01 += r.a01, q.a02 += r.a02, q.a12 += r.a12;
  q.b0 += r.b0, q.b1 += r.b1, q.b2 += r.b2, q.c += r.c, q.w += r.w;
}

// A vertex's gradient sums (kGradientWords per channel), to read or add to.
double* gradients_of(QemMesh& mesh, uint32_t v) {
  return mesh.attribute_gradients.data() + kGradientWords * mesh.attribute_channels * v;
}
const double* gradients_of(const QemMesh& mesh, uint32_t v) {
  return mesh.attribute_gradients.data() + kGradientWords * mesh.attribute_channels * v;
}

void gradients_add(double* g, const double* r, size_t channels) {
  for (size_t i = 0; i < kGradientWords * channels; ++i) g[i] += r[i];
}

// Vertex b's attribute quadric plus a's (both parts), as one collapse merges them.
void attribute_merge(QemMesh& mesh, uint32_t b, uint32_t a) {
  attribute_add(mesh.attribute_quadrics[b], mesh.attribute_quadrics[a]);
  gradients_add(gradients_of(mesh, b), gradients_of(mesh, a), mesh.attribute_channels);
}

// sum w (g.p + d - s_k)^2 at p with the merged vertex's attributes s (`channels` of them;
// g: their gradient sums).
double attribute_eval(const AttributeQuadric& q, const double* g, const float* p, const float* s, size_t channels) {
  const double x = p[0], y = p[1], z = p[2];
  double r = x * (q.a00 * x + q.a01 * y + q.a02 * z) + y * (q.a01 * x + q.a11 * y + q.a12 * z) +
             z * (q.a02 * x + q.a12 * y + q.a22 * z) + 2 * (q.b0 * x + q.b1 * y + q.b2 * z) + q.c;
  for (size_t k = 0; k < channels; ++k, g += kGradientWords)
    r += -2 * double(s[k]) * (g[0] * x + g[1] * y + g[2] * z + g[3]) + double(s[k]) * s[k] * q.w;
  return r;
}

// The attribute error at p of vertices a and b merged, with attributes s: their quadrics
// summed on the stack (no vertex changes).
double merged_attribute_eval(const QemMesh& mesh, uint32_t a, uint32_t b, const float* p, const float* s) {
  const size_t channels = mesh.attribute_channels;
  AttributeQuadric q = mesh.attribute_quadrics[a];
  attribute_add(q, mesh.attribute_quadrics[b]);
  double g[kGradientWords * kAttributeQuadricChannels];
  std::memcpy(g, gradients_of(mesh, a), kGradientWords * channels * sizeof(double));
  gradients_add(g, gradients_of(mesh, b), channels);
  return attribute_eval(q, g, p, s, channels);
}

// Face (p0, p1, p2) with attributes s0, s1, s2 (`channels` each): for every channel the linear
// function g.p + d over the face's plane through the corner values, added with weight w to the
// three corners' attribute quadrics.
void add_face_attributes(AttributeQuadric* corners[3], double* corner_gradients[3], const float* p0, const float* p1,
                         const float* p2, const float* s0, const float* s1, const float* s2, size_t channels, double w) {
  const double e1[3] = {double(p1[0]) - p0[0], double(p1[1]) - p0[1], double(p1[2]) - p0[2]};
  const double e2[3] = {double(p2[0]) - p0[0], double(p2[1]) - p0[1], double(p2[2]) - p0[2]};
  const double m11 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2], m22 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
  const double m12 = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2];
  const double det = m11 * m22 - m12 * m12;
  if (!(det > 1e-30 * m11 * m22) || !(w > 0)) return;
  AttributeQuadric f;
  double fg[kGradientWords * kAttributeQuadricChannels];
  f.w = w;
  for (size_t k = 0; k < channels; ++k) {
    // g = alpha e1 + beta e2 with g.e1 = s1 - s0, g.e2 = s2 - s0 (in the face's plane).
    const double r1 = double(s1[k]) - s0[k], r2 = double(s2[k]) - s0[k];
    const double alpha = (r1 * m22 - r2 * m12) / det, beta = (r2 * m11 - r1 * m12) / det;
    const double g[3] = {alpha * e1[0] + beta * e2[0], alpha * e1[1] + beta * e2[1], alpha * e1[2] + beta * e2[2]};
    const double d = s0[k] - (g[0] * p0[0] + g[1] * p0[1] + g[2] * p0[2]);
    f.a00 += w * g[0] * g[0], f.a11 += w * g[1] * g[1], f.a22 += w * g[2] * g[2];
    f.a01 += w * g[0] * g[1], f.a02 += w * g[0] * g[2], f.a12 += w * g[1] * g[2];
    f.b0 += w * d * g[0], f.b1 += w * d * g[1], f.b2 += w * d * g[2];
    f.c += w * d * d;
    for (int j = 0; j < 3; ++j) fg[kGradientWords * k + size_t(j)] = w * g[j];
    fg[kGradientWords * k + 3] = w * d;
  }
  for (int c = 0; c < 3; ++c) {
    attribute_add(*corners[c], f);
    gradients_add(corner_gradients[c], fg, channels);
  }
}

// Best point on the segment a-b (1D quadratic, clamped), midpoint when flat along it.
void place_on_segment(const Quadric& q, const float* a, const float* b, float* out) {
  const double d[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
  const double ad[3] = {q.a00 * d[0] + q.a01 * d[1] + q.a02 * d[2], q.a01 * d[0] + q.a11 * d[1] + q.a12 * d[2],
                        q.a02 * d[0] + q.a12 * d[1] + q.a22 * d[2]};
  const double dad = d[0] * ad[0] + d[1] * ad[1] + d[2] * ad[2];
  double t = 0.5;
  if (dad > 1e-30) {
    const double num = a[0] * ad[0] + a[1] * ad[1] + a[2] * ad[2] + q.b0 * d[0] + q.b1 * d[1] + q.b2 * d[2];
    t = std::clamp(-num / dad, 0.0, 1.0);
  }
  for (int k = 0; k < 3; ++k) out[k] = float(a[k] + t * d[k]);
}

// Minimiser of q (+ a small pull to the midpoint) by Cramer's rule; falls back to the segment.
void place_optimal(const Quadric& q, const float* a, const float* b, float* out) {
  const double m[3] = {0.5 * (double(a[0]) + b[0]), 0.5 * (double(a[1]) + b[1]), 0.5 * (double(a[2]) + b[2])};
  const double lambda = kRegularisation * (q.a00 + q.a11 + q.a22) + 1e-30;
  const double a00 = q.a00 + lambda, a11 = q.a11 + lambda, a22 = q.a22 + lambda;
  const double a01 = q.a01, a02 = q.a02, a12 = q.a12;
  const double r0 = -q.b0 + lambda * m[0], r1 = -q.b1 + lambda * m[1], r2 = -q.b2 + lambda * m[2];
  const double c00 = a11 * a22 - a12 * a12, c01 = a02 * a12 - a01 * a22, c02 = a01 * a12 - a02 * a11;
  const double det = a00 * c00 + a01 * c01 + a02 * c02;
  if (det > 1e-300) {
    const double c11 = a00 * a22 - a02 * a02, c12 = a01 * a02 - a00 * a12, c22 = a00 * a11 - a01 * a01;
    const double inv = 1.0 / det;
    const double x = (c00 * r0 + c01 * r1 + c02 * r2) * inv;
    const double y = (c01 * r0 + c11 * r1 + c12 * r2) * inv;
    const double z = (c02 * r0 + c12 * r1 + c22 * r2) * inv;
    const double dx = double(b[0]) - a[0], dy = double(b[1]) - a[1], dz = double(b[2]) - a[2];
    const double len2 = dx * dx + dy * dy + dz * dz;
    const double ox = x - m[0], oy = y - m[1], oz = z - m[2];
    if (std::isfinite(x + y + z) &&
        ox * ox + oy * oy + oz * oz <= kMaxPlacementDistance * kMaxPlacementDistance * len2) {
      out[0] = float(x);
      out[1] = float(y);
      out[2] = float(z);
      return;
    }
  }
  place_on_segment(q, a, b, out);
}

struct Candidate {
  uint32_t from, to;
  float cost;
  float p[3];
};

// Scratch for one simplification call, sized once for the mesh it starts from.
struct Work {
  std::vector<uint32_t> offset, fill;  // CSR vertex -> faces
  std::vector<uint32_t> ring;          // per CSR entry: the face's next and previous corner
  std::vector<uint8_t> kind;
  std::vector<uint32_t> next, prev;    // border loops, for border (and seam) vertices
  std::vector<uint32_t> sibling;       // a seam vertex's copy on the other side
  std::vector<uint8_t> seam_out;       // the open edge v -> next[v] has a twin (a seam edge)
  std::vector<uint32_t> stamp;
  std::vector<uint8_t> out_count, in_count;
  std::vector<uint32_t> remap;
  std::vector<uint8_t> pass_lock;
  std::vector<uint32_t> mark;
  uint32_t mark_value = 0;
  std::vector<Candidate> cands;
  std::vector<uint32_t> keys, order, order_tmp;
  std::vector<uint32_t> vmap;
  bool dedupe_faces = false;  // the mesh has non-manifold edges: collapses may double faces

  void reserve(size_t v, size_t t) {
    offset.reserve(v + 1);
    fill.reserve(v);
    ring.reserve(6 * t);
    remap.reserve(v);
    pass_lock.reserve(v);
    mark.reserve(v);
    cands.reserve(3 * t);
    keys.reserve(3 * t);
    order.reserve(3 * t);
    order_tmp.reserve(3 * t);
    vmap.reserve(v);
  }
};

// The copy of t that f's copy collapses onto when f collapses onto t along their seam: the
// copy's neighbour the other way along its own side. ~0u when there is none to take (t is the
// closed end of a slit, which both copies would reach at once).
uint32_t seam_partner(const Work& w, uint32_t f, uint32_t t) {
  const uint32_t g = w.sibling[f];
  const uint32_t tp = w.next[f] == t ? w.prev[g] : w.prev[f] == t ? w.next[g] : ~0u;
  if (tp == ~0u || tp == t || tp == f || tp == g) return ~0u;
  return tp;
}

// Cost of collapsing seam vertex f onto t with its copy g onto t's copy tp, all at t's place:
// the plane error of all four, plus each side's attribute error with that side's attributes
// of t (each copy keeps the uvs of its own side). Infinite when the pair cannot collapse.
float seam_cost(const Work& w, const QemMesh& mesh, uint32_t f, uint32_t t) {
  const uint32_t g = w.sibling[f], tp = seam_partner(w, f, t);
  if (tp == ~0u || w.offset[g + 1] - w.offset[g] > kMaxValence || w.offset[tp + 1] - w.offset[tp] > kMaxValence)
    return std::numeric_limits<float>::infinity();
  Quadric q = quadric_sum(mesh.quadrics[f], mesh.quadrics[t]);
  quadric_add(q, mesh.quadrics[g]);
  quadric_add(q, mesh.quadrics[tp]);
  const float* p = &mesh.positions[3 * size_t(t)];
  double e = quadric_eval(q, p[0], p[1], p[2]);
  if (!mesh.attribute_quadrics.empty()) {
    const size_t ac = mesh.attribute_count;
    e += std::max(0.0, merged_attribute_eval(mesh, f, t, p, &mesh.attributes[ac * t]));
    e += std::max(0.0, merged_attribute_eval(mesh, g, tp, p, &mesh.attributes[ac * tp]));
  }
  return q.w > 0 ? float(e / q.w) : float(e);
}

// CSR lists for the current index buffer: each face of v as its (next, previous) corners.
void build_lists(Work& w, const QemMesh& mesh) {
  const size_t nv = mesh.positions.size() / 3;
  const size_t nt = mesh.indices.size() / 3;
  const uint32_t* idx = mesh.indices.data();
  w.offset.assign(nv + 1, 0);
  for (size_t i = 0; i < 3 * nt; ++i) w.offset[idx[i] + 1]++;
  for (size_t v = 0; v < nv; ++v) w.offset[v + 1] += w.offset[v];
  w.fill.assign(w.offset.begin(), w.offset.end() - 1);
  w.ring.resize(6 * nt);
  for (size_t t = 0; t < nt; ++t) {
    const uint32_t a = idx[3 * t], b = idx[3 * t + 1], c = idx[3 * t + 2];
    uint32_t* ra = &w.ring[2 * size_t(w.fill[a]++)];
    ra[0] = b, ra[1] = c;
    uint32_t* rb = &w.ring[2 * size_t(w.fill[b]++)];
    rb[0] = c, rb[1] = a;
    uint32_t* rc = &w.ring[2 * size_t(w.fill[c]++)];
    rc[0] = a, rc[1] = b;
  }
}

bool same_position(const QemMesh& mesh, uint32_t a, uint32_t b) {
  return std::memcmp(&mesh.positions[3 * size_t(a)], &mesh.positions[3 * size_t(b)], 12) == 0;
}

// Copies at one position among the live vertices: `group` links each copy to the next one at
// its position, in a cycle.
void link_copies(Work& w, const QemMesh& mesh, std::vector<uint32_t>& group) {
  const size_t nv = mesh.positions.size() / 3;
  group.assign(nv, ~0u);
  size_t copies = 0;
  for (size_t v = 0; v < nv; ++v) copies += (mesh.lock[v] & QemMesh::kCopy) && w.offset[v] != w.offset[v + 1];
  size_t cap = 16;
  while (cap < 2 * copies) cap *= 2;
  std::vector<uint32_t> table(cap, ~0u);
  for (uint32_t v = 0; v < nv; ++v) {
    if (!(mesh.lock[v] & QemMesh::kCopy) || w.offset[v] == w.offset[v + 1]) continue;
    uint32_t h[3];
    std::memcpy(h, &mesh.positions[3 * size_t(v)], 12);
    size_t slot = (h[0] * 73856093u ^ h[1] * 19349663u ^ h[2] * 83492791u) & (cap - 1);
    while (table[slot] != ~0u && !same_position(mesh, table[slot], v)) slot = (slot + 1) & (cap - 1);
    const uint32_t o = table[slot];
    if (o == ~0u) {
      table[slot] = v;
      group[v] = v;
    } else {
      group[v] = group[o];
      group[o] = v;
    }
  }
}

// Seam pairs among the copies (kSeam from classify): the two copies at a position are a pair
// when each one's open edges are the other's, reversed (the side of one ends where the other's
// begins). Anything else at a copy (a third copy, a missing twin in this part, a seam meeting
// a border or ending inside the surface) locks it. Also marks which open edges are seam edges,
// and locks the single vertex at the closed end of a slit (a seam ending inside the surface,
// whose two open edges lead to the two copies of one position).
void pair_seams(Work& w, const QemMesh& mesh) {
  const size_t nv = mesh.positions.size() / 3;
  w.sibling.assign(nv, ~0u);
  w.seam_out.assign(nv, 0);
  std::vector<uint32_t> group;
  link_copies(w, mesh, group);
  auto open_ok = [&](uint32_t v) {
    return w.next[v] != ~0u && w.prev[v] != ~0u && w.next[v] != w.prev[v] && !same_position(mesh, v, w.next[v]) &&
           !same_position(mesh, v, w.prev[v]);
  };
  for (uint32_t v = 0; v < nv; ++v) {
    if (group[v] == ~0u) {
      // The closed end of a slit: both open edges lead to one position.
      if (w.kind[v] == kBorder && open_ok(v) && same_position(mesh, w.next[v], w.prev[v]))
        w.kind[v] = kLocked, w.seam_out[v] = 1;
      continue;
    }
    for (uint32_t u = group[v]; u != v; u = group[u])
      if (w.next[v] != ~0u && w.prev[u] != ~0u && w.prev[u] != w.next[v] && same_position(mesh, w.prev[u], w.next[v]))
        w.seam_out[v] = 1;
    if (w.kind[v] != kSeam) continue;
    const uint32_t u = group[v];
    const bool pair = u != v && group[u] == v && w.kind[u] == kSeam && open_ok(v) && open_ok(u) &&
                      same_position(mesh, w.next[v], w.prev[u]) && same_position(mesh, w.prev[v], w.next[u]);
    if (pair) {
      w.sibling[v] = u;
    } else {
      w.kind[v] = kLocked;
    }
  }
  // A pair whose other half was locked above is no pair.
  for (uint32_t v = 0; v < nv; ++v)
    if (w.kind[v] == kSeam && (w.sibling[v] == ~0u || w.kind[w.sibling[v]] != kSeam)) w.kind[v] = kLocked, w.sibling[v] = ~0u;
}

// Vertex kinds and border loops, once per call: collapses that pass the link condition keep
// every vertex's kind, and border collapses update the loops as they go.
void classify(Work& w, const QemMesh& mesh, bool lock_border, bool move_nonmanifold) {
  const size_t nv = mesh.positions.size() / 3;
  w.kind.assign(nv, kLocked);
  w.next.assign(nv, ~0u);
  w.prev.assign(nv, ~0u);
  w.stamp.assign(nv, 0);
  w.out_count.assign(nv, 0);
  w.in_count.assign(nv, 0);
  w.dedupe_faces = false;
  for (size_t v = 0; v < nv; ++v) {
    const uint32_t begin = w.offset[v], end = w.offset[v + 1];
    if (begin == end) continue;
    const uint32_t s = uint32_t(v) + 1;
    for (uint32_t i = begin; i < end; ++i) {
      const uint32_t n = w.ring[2 * i], p = w.ring[2 * i + 1];
      if (w.stamp[n] != s) w.stamp[n] = s, w.out_count[n] = 0, w.in_count[n] = 0;
      if (w.stamp[p] != s) w.stamp[p] = s, w.out_count[p] = 0, w.in_count[p] = 0;
      if (w.out_count[n] < 255) w.out_count[n]++;
      if (w.in_count[p] < 255) w.in_count[p]++;
    }
    unsigned border_out = 0, border_in = 0;
    bool complex = false;
    for (uint32_t i = begin; i < end; ++i) {
      const uint32_t n = w.ring[2 * i], p = w.ring[2 * i + 1];
      if (w.out_count[n] == 1 && w.in_count[n] == 0) border_out++, w.next[v] = n;
      if (w.in_count[p] == 1 && w.out_count[p] == 0) border_in++, w.prev[v] = p;
      complex |= w.out_count[n] > 1 || w.in_count[n] > 1 || w.out_count[p] > 1 || w.in_count[p] > 1;
    }
    // One open edge out and one in: a border loop passes through v, and v slides along it
    // (whatever else meets there). A non-manifold vertex (edges with more than two faces or
    // faces of both orientations) moves like a manifold one otherwise, as in meshoptimizer,
    // even at the open end of a fin or a flipped patch: Stanford's own decimated scans have
    // thousands of those, and locking them leaves the chain stuck far above its targets with
    // every remaining collapse costly. The link condition and the face checks still apply.
    // A plain bow-tie (two border loops through one vertex) stays locked.
    uint8_t kind = kLocked;
    if (border_out == 0 && border_in == 0 && !complex) kind = kManifold;
    if (complex && move_nonmanifold) kind = kManifold;
    if (complex && kind == kManifold && !mesh.lock[v]) w.dedupe_faces = true;
    if (border_out == 1 && border_in == 1 && (!complex || move_nonmanifold)) kind = lock_border ? kLocked : kBorder;
    // A copy is a seam vertex only if pair_seams finds its twin; one open edge each way is the
    // shape it needs (its side's fan ends at the seam on both hands).
    if (mesh.lock[v] & QemMesh::kCopy) kind = border_out == 1 && border_in == 1 && !complex ? kSeam : kLocked;
    if (mesh.lock[v] & QemMesh::kLockMask) kind = kLocked;
    w.kind[v] = kind;
  }
  pair_seams(w, mesh);
}

void radix_sort(Work& w, size_t n) {
  w.keys.resize(n);
  w.order.resize(n);
  w.order_tmp.resize(n);
  for (size_t i = 0; i < n; ++i) {
    uint32_t bits;
    std::memcpy(&bits, &w.cands[i].cost, 4);  // costs are >= 0, so bits sort like values
    w.keys[i] = bits;
    w.order[i] = uint32_t(i);
  }
  // The top 22 bits (sign is always 0) order costs to 2^-13 relative: plenty for greedy
  // collapse order, and one scatter pass fewer.
  uint32_t hist[2][2048] = {};
  for (size_t i = 0; i < n; ++i) {
    const uint32_t k = w.keys[i] >> 9;
    w.keys[i] = k;
    hist[0][k & 2047]++;
    hist[1][(k >> 11) & 2047]++;
  }
  for (int pass = 0; pass < 2; ++pass) {
    uint32_t sum = 0;
    for (uint32_t& h : hist[pass]) {
      const uint32_t c = h;
      h = sum;
      sum += c;
    }
    const int shift = 11 * pass;
    for (size_t i = 0; i < n; ++i) {
      const uint32_t o = w.order[i];
      w.order_tmp[hist[pass][(w.keys[o] >> shift) & 2047]++] = o;
    }
    std::swap(w.order, w.order_tmp);
  }
}

bool normal_kept(const float* p0, const float* p1, const float* p2, const float* q0) {
  // The face (p0, p1, p2) with p0 moved to q0.
  const float e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
  const float e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
  const float f1[3] = {p1[0] - q0[0], p1[1] - q0[1], p1[2] - q0[2]};
  const float f2[3] = {p2[0] - q0[0], p2[1] - q0[1], p2[2] - q0[2]};
  const float n0[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  const float n1[3] = {f1[1] * f2[2] - f1[2] * f2[1], f1[2] * f2[0] - f1[0] * f2[2], f1[0] * f2[1] - f1[1] * f2[0]};
  const float d = n0[0] * n1[0] + n0[1] * n1[1] + n0[2] * n1[2];
  if (d <= 0) return false;
  const float l0 = n0[0] * n0[0] + n0[1] * n0[1] + n0[2] * n0[2];
  const float l1 = n1[0] * n1[0] + n1[1] * n1[1] + n1[2] * n1[2];
  return d * d >= kMinNormalCos * kMinNormalCos * l0 * l1;
}

// Whether collapsing a into b at p keeps the mesh as it was: the link condition (the common
// neighbours of a and b are exactly the apexes of the faces on edge a-b), enough faces left
// around the merged vertex, and no face around a or b flipped or folded. One walk over each
// vertex's faces. Sets `removed` to the number of faces on the edge.
bool collapse_allowed(Work& w, const QemMesh& mesh, uint32_t a, uint32_t b, const float* p, bool b_moves,
                      size_t& removed) {
  const float* pos = mesh.positions.data();
  const float* pa = pos + 3 * size_t(a);
  const float* pb = pos + 3 * size_t(b);
  w.mark_value += 2;
  const uint32_t na = w.mark_value, counted = w.mark_value + 1;
  size_t faces_a = 0, faces_b = 0, shared = 0, common = 0;
  for (uint32_t i = w.offset[a]; i < w.offset[a + 1]; ++i) {
    const uint32_t y = w.remap[w.ring[2 * i]], z = w.remap[w.ring[2 * i + 1]];
    if (y == z || y == a || z == a) continue;  // collapsed earlier in this pass
    faces_a++;
    w.mark[y] = na;
    w.mark[z] = na;
    if (y != b && z != b && !normal_kept(pa, pos + 3 * size_t(y), pos + 3 * size_t(z), p)) return false;
  }
  for (uint32_t i = w.offset[b]; i < w.offset[b + 1]; ++i) {
    const uint32_t y = w.remap[w.ring[2 * i]], z = w.remap[w.ring[2 * i + 1]];
    if (y == z || y == b || z == b) continue;
    faces_b++;
    if (y == a || z == a) {
      shared++;
    } else if (b_moves && !normal_kept(pb, pos + 3 * size_t(y), pos + 3 * size_t(z), p)) {
      return false;
    }
    if (y != a && w.mark[y] == na) w.mark[y] = counted, common++;
    if (z != a && w.mark[z] == na) w.mark[z] = counted, common++;
  }
  removed = shared;
  if (shared == 0 || common != shared) return false;
  const size_t left = faces_a + faces_b - 2 * shared;
  return w.kind[b] == kManifold ? left >= 3 : left >= 1;
}

constexpr size_t kDuplicateFace = ~size_t(0);

// Face t's slot in an open-addressed table of face ids (a power-of-two size, ~0u = empty) keyed
// by its vertex set, or kDuplicateFace when a face already in the table has the same three
// vertices in any order.
size_t face_set_slot(const std::vector<uint32_t>& table, const uint32_t* idx, size_t t) {
  const size_t mask = table.size() - 1;
  uint32_t k[3] = {idx[3 * t], idx[3 * t + 1], idx[3 * t + 2]};
  std::sort(k, k + 3);
  size_t slot = size_t(((uint64_t(k[0]) * 0x9e3779b97f4a7c15ull) ^ (uint64_t(k[1]) * 0xc2b2ae3d27d4eb4full) ^
                        (uint64_t(k[2]) * 0x165667b19e3779f9ull)) >> 7) & mask;
  while (table[slot] != ~0u) {
    const size_t f = table[slot];
    uint32_t o[3] = {idx[3 * f], idx[3 * f + 1], idx[3 * f + 2]};
    std::sort(o, o + 3);
    if (o[0] == k[0] && o[1] == k[1] && o[2] == k[2]) return kDuplicateFace;
    slot = (slot + 1) & mask;
  }
  return slot;
}

// Removes faces on the same three vertices as an earlier face; returns the faces left.
size_t drop_duplicate_faces(Work& w, std::vector<uint32_t>& indices) {
  const size_t nf = indices.size() / 3;
  size_t cap = 16;
  while (cap < 2 * nf) cap *= 2;
  std::vector<uint32_t>& table = w.order_tmp;  // reuse: face id per slot
  table.assign(cap, ~0u);
  uint32_t* idx = indices.data();
  size_t kept = 0;
  for (size_t t = 0; t < nf; ++t) {
    const size_t slot = face_set_slot(table, idx, t);
    if (slot == kDuplicateFace) continue;
    // Kept faces move down in place; the table refers to their new slots.
    for (int c = 0; c < 3; ++c) idx[3 * kept + c] = idx[3 * t + c];
    table[slot] = uint32_t(kept);
    kept++;
  }
  indices.resize(3 * kept);
  return kept;
}

// Whether the faces around f and t reach neither g nor tp: the two sides' collapses of a
// seam pair are then independent, and checking each alone checks both.
bool sides_apart(const Work& w, uint32_t f, uint32_t t, uint32_t g, uint32_t tp) {
  for (uint32_t v : {f, t})
    for (uint32_t i = 2 * w.offset[v]; i < 2 * w.offset[v + 1]; ++i) {
      const uint32_t x = w.remap[w.ring[i]];
      if (x == g || x == tp) return false;
    }
  return true;
}

// Collapses a onto b at p: b takes a's quadrics, its border loop place and its faces (through
// the remap table), and the attribute at p interpolated along the edge a-b.
void apply_collapse(Work& w, QemMesh& mesh, uint32_t a, uint32_t b, const float* p) {
  float* pos = mesh.positions.data();
  const size_t ac = mesh.attribute_count;
  if (ac) {
    const float t = edge_parameter(pos + 3 * size_t(a), pos + 3 * size_t(b), p);
    float* at = mesh.attributes.data();
    for (size_t k = 0; k < ac; ++k) at[b * ac + k] = at[a * ac + k] * (1 - t) + at[b * ac + k] * t;
  }
  if (w.kind[a] == kBorder || w.kind[a] == kSeam) {
    // a leaves its border loop (a seam vertex: its side's open loop)
    const uint32_t pa = w.prev[a], na = w.next[a];
    if (na == b) {
      if (pa != ~0u) w.next[pa] = b;
      w.prev[b] = pa;
    } else {
      if (na != ~0u) w.prev[na] = b;
      w.next[b] = na;
    }
  }
  std::memcpy(pos + 3 * size_t(b), p, 3 * sizeof(float));
  quadric_add(mesh.quadrics[b], mesh.quadrics[a]);
  if (!mesh.attribute_quadrics.empty()) attribute_merge(mesh, b, a);
  w.remap[a] = b;
  w.pass_lock[a] = w.pass_lock[b] = 1;
}

// Pass over the current mesh: returns the number of faces removed.
size_t collapse_pass(Work& w, QemMesh& mesh, size_t target, double cost_limit, bool& hit_limit,
                     bool lists_current) {
  const size_t nv = mesh.positions.size() / 3;
  const size_t nt = mesh.indices.size() / 3;
  if (!lists_current) build_lists(w, mesh);
  float* pos = mesh.positions.data();

  const bool weighted = !mesh.attribute_quadrics.empty();
  const size_t ac = mesh.attribute_count, channels = std::min(ac, kAttributeQuadricChannels);
  // Every collapsible edge once, with its direction, position and cost.
  // Walked per vertex (each face's edge a -> next), so a's quadric is read once.
  // Written in place (a candidate built on the stack and pushed stalls on its own stores).
  if (w.cands.size() < 3 * nt) w.cands.resize(3 * nt);
  size_t n = 0;
  for (uint32_t a = 0; a < nv; ++a) {
    const uint8_t ka = w.kind[a];
    const Quadric& qa = mesh.quadrics[a];
    if (w.offset[a + 1] - w.offset[a] > kMaxValence) continue;
    for (uint32_t i = w.offset[a]; i < w.offset[a + 1]; ++i) {
      const uint32_t b = w.ring[2 * i];
      const uint8_t kb = w.kind[b];
      if (ka == kLocked && kb == kLocked) continue;
      if (w.offset[b + 1] - w.offset[b] > kMaxValence) continue;
      const bool border = (ka == kBorder && w.next[a] == b) || (kb == kBorder && w.prev[b] == a);
      const bool seam = (ka == kSeam || kb == kSeam) && (w.next[a] == b || w.prev[b] == a);
      if (!border && !seam && a > b) continue;  // an interior edge is seen from both faces
      Candidate& c = w.cands[n];
      if (seam && ka != kManifold && kb != kManifold) {
        // Along the seam: the pair at one end onto the pair at the other; the cheaper way when
        // both ends may move. Each seam edge is seen from both sides: kept from the side whose
        // moving copy has the lower id.
        float cab = std::numeric_limits<float>::infinity(), cba = cab;
        if (ka == kSeam && a < w.sibling[a]) cab = seam_cost(w, mesh, a, b);
        if (kb == kSeam && b < w.sibling[b]) cba = seam_cost(w, mesh, b, a);
        if (!(std::min(cab, cba) < std::numeric_limits<float>::infinity())) continue;
        c.from = cab <= cba ? a : b;
        c.to = cab <= cba ? b : a;
        c.cost = std::min(cab, cba);
        std::memcpy(c.p, pos + 3 * size_t(c.to), sizeof c.p);
        n++;
        continue;
      }
      const Quadric q = quadric_sum(qa, mesh.quadrics[b]);
      if (ka == kManifold && kb == kManifold) {
        c.from = a, c.to = b;
        place_optimal(q, pos + 3 * size_t(a), pos + 3 * size_t(b), c.p);
      } else if (ka == kManifold || kb == kManifold) {
        c.from = ka == kManifold ? a : b;
        c.to = ka == kManifold ? b : a;
        std::memcpy(c.p, pos + 3 * size_t(c.to), sizeof c.p);
      } else if (!border) {
        continue;  // border vertices only slide along their border; locked ones never move
      } else if (ka == kBorder && kb == kBorder) {
        // Along a border the vertex stays on one end: a point inside the chord would pull
        // both ends off the outline.
        const float ea = quadric_cost(q, pos + 3 * size_t(a)), eb = quadric_cost(q, pos + 3 * size_t(b));
        c.from = ea < eb ? b : a;
        c.to = ea < eb ? a : b;
        std::memcpy(c.p, pos + 3 * size_t(c.to), sizeof c.p);
      } else {
        c.from = ka == kBorder ? a : b;
        c.to = ka == kBorder ? b : a;
        std::memcpy(c.p, pos + 3 * size_t(c.to), sizeof c.p);
      }
      c.cost = quadric_cost(q, c.p);
      if (weighted) {
        // The attribute the merged vertex gets (interpolated along the edge, as the collapse
        // does), against the faces' attribute functions of both ends.
        const uint32_t f = c.from, to = c.to;
        const float t = edge_parameter(pos + 3 * size_t(f), pos + 3 * size_t(to), c.p);
        float s[kAttributeQuadricChannels];
        const float* at = mesh.attributes.data();
        for (size_t k = 0; k < channels; ++k) s[k] = at[f * ac + k] * (1 - t) + at[to * ac + k] * t;
        const double e =
            quadric_eval(q, c.p[0], c.p[1], c.p[2]) + std::max(0.0, merged_attribute_eval(mesh, a, b, c.p, s));
        c.cost = q.w > 0 ? float(e / q.w) : float(e);
      }
      n++;
    }
  }
  if (n == 0) return 0;
  radix_sort(w, n);

  // Collapse in cost order. Each success locks ~6 other edges for this pass, so the error
  // allowed per pass follows the goal-th cheapest edge (meshoptimizer's pass limit).
  const size_t face_goal = nt - target;
  const size_t edge_goal = face_goal / 2;
  // Close to the target (5 %) the remaining few collapses go in one pass, not in a long tail
  // of passes that each find a handful (small meshes took 4 passes for their last 3 %).
  const bool last_stretch = face_goal * 20 < nt;
  const float error_goal = edge_goal < n && !last_stretch ? 1.5f * w.cands[w.order[edge_goal]].cost
                                                          : std::numeric_limits<float>::max();
  const size_t collapse_floor = edge_goal / 6;

  w.remap.resize(nv);
  for (size_t v = 0; v < nv; ++v) w.remap[v] = uint32_t(v);
  w.pass_lock.assign(nv, 0);
  if (w.mark.size() < nv) w.mark.assign(nv, 0), w.mark_value = 0;
  if (w.mark_value > 0xfffffff0u) std::fill(w.mark.begin(), w.mark.end(), 0), w.mark_value = 0;

  // Candidates are gathered into sorted order a chunk at a time: independent loads overlap,
  // where the collapse loop below would wait on each one.
  constexpr size_t kChunk = 512;
  constexpr size_t kAhead = 8;
  Candidate chunk[kChunk];
  size_t removed_total = 0, collapses = 0;
  for (size_t i = 0; i < n; ++i) {
    if (i % kChunk == 0) {
      const size_t m = std::min(kChunk, n - i);
      for (size_t j = 0; j < m; ++j) chunk[j] = w.cands[w.order[i + j]];
    }
    // Two-stage prefetch: the lists' offsets far ahead, then the lists themselves.
    if (i % kChunk + 2 * kAhead < kChunk && i + 2 * kAhead < n) {
      const Candidate& f = chunk[i % kChunk + 2 * kAhead];
      __builtin_prefetch(&w.offset[f.from]);
      __builtin_prefetch(&w.offset[f.to]);
      __builtin_prefetch(&w.pass_lock[f.from]);
      __builtin_prefetch(&w.pass_lock[f.to]);
    }
    if (i % kChunk + kAhead < kChunk && i + kAhead < n) {
      const Candidate& f = chunk[i % kChunk + kAhead];
      if (!w.pass_lock[f.from] && !w.pass_lock[f.to]) {
        const uint32_t* ra = &w.ring[2 * size_t(w.offset[f.from])];
        const uint32_t* rb = &w.ring[2 * size_t(w.offset[f.to])];
        __builtin_prefetch(ra);
        __builtin_prefetch(ra + 16);
        __builtin_prefetch(rb);
        __builtin_prefetch(rb + 16);
        __builtin_prefetch(pos + 3 * size_t(f.from));
        __builtin_prefetch(pos + 3 * size_t(f.to));
        // A successful collapse adds the quadrics (88 bytes each, two lines).
        const char* qa = reinterpret_cast<const char*>(&mesh.quadrics[f.from]);
        const char* qb = reinterpret_cast<const char*>(&mesh.quadrics[f.to]);
        __builtin_prefetch(qa);
        __builtin_prefetch(qa + 64);
        __builtin_prefetch(qb);
        __builtin_prefetch(qb + 64);
      }
    }
    const Candidate& c = chunk[i % kChunk];
    if (c.cost > cost_limit) {
      hit_limit = true;
      break;
    }
    if (removed_total >= face_goal) break;
    if (c.cost > error_goal && collapses > collapse_floor) break;
    const uint32_t a = c.from, b = c.to;
    if (w.pass_lock[a] || w.pass_lock[b]) continue;
    size_t removed = 0;
    if (w.kind[a] == kSeam) {
      // Both copies along their own sides of the seam, or neither.
      const uint32_t a2 = w.sibling[a], b2 = seam_partner(w, a, b);
      if (b2 == ~0u || w.pass_lock[a2] || w.pass_lock[b2] || !sides_apart(w, a, b, a2, b2)) continue;
      size_t removed2 = 0;
      if (!collapse_allowed(w, mesh, a, b, c.p, false, removed) || !collapse_allowed(w, mesh, a2, b2, c.p, false, removed2))
        continue;
      apply_collapse(w, mesh, a, b, c.p);
      apply_collapse(w, mesh, a2, b2, c.p);
      removed += removed2;
    } else {
      const bool b_moves = std::memcmp(c.p, pos + 3 * size_t(b), sizeof c.p) != 0;
      if (!collapse_allowed(w, mesh, a, b, c.p, b_moves, removed)) continue;
      apply_collapse(w, mesh, a, b, c.p);
    }
    removed_total += removed;
    collapses++;
    mesh.error = std::max(mesh.error, double(c.cost));
  }

  // Rewrite the faces through the remap table; drop the ones that collapsed.
  size_t kept = 0;
  uint32_t* out = mesh.indices.data();
  for (size_t t = 0; t < nt; ++t) {
    const uint32_t x = w.remap[out[3 * t]], y = w.remap[out[3 * t + 1]], z = w.remap[out[3 * t + 2]];
    if (x == y || y == z || x == z) continue;
    out[3 * kept] = x, out[3 * kept + 1] = y, out[3 * kept + 2] = z;
    kept++;
  }
  mesh.indices.resize(3 * kept);
  if (w.dedupe_faces) kept = drop_duplicate_faces(w, mesh.indices);
  return nt - kept;
}

// Drops unreferenced vertices so later passes touch only live ones.
void compact_vertices(Work& w, QemMesh& mesh) {
  const size_t nv = mesh.positions.size() / 3;
  const size_t ac = mesh.attribute_count;
  w.vmap.assign(nv, ~0u);
  uint32_t next = 0;
  for (uint32_t& i : mesh.indices) {
    if (w.vmap[i] == ~0u) w.vmap[i] = next++;
    i = w.vmap[i];
  }
  std::vector<uint32_t>& order = w.fill;  // reuse: old id per new id
  order.resize(next);
  for (size_t v = 0; v < nv; ++v)
    if (w.vmap[v] != ~0u) order[w.vmap[v]] = uint32_t(v);
  // New ids follow first use, not old id order, so copy through fresh arrays.
  QemMesh tmp;
  tmp.positions.resize(3 * size_t(next));
  tmp.attributes.resize(ac * size_t(next));
  tmp.quadrics.resize(next);
  tmp.attribute_quadrics.resize(mesh.attribute_quadrics.empty() ? 0 : next);
  const size_t gw = mesh.attribute_quadrics.empty() ? 0 : kGradientWords * mesh.attribute_channels;
  tmp.attribute_gradients.resize(gw * next);
  tmp.source_vertex.resize(next);
  tmp.lock.resize(next);
  for (uint32_t n = 0; n < next; ++n) {
    const uint32_t o = order[n];
    std::memcpy(&tmp.positions[3 * size_t(n)], &mesh.positions[3 * size_t(o)], 12);
    if (ac) std::memcpy(&tmp.attributes[ac * n], &mesh.attributes[ac * o], ac * sizeof(float));
    tmp.quadrics[n] = mesh.quadrics[o];
    if (!mesh.attribute_quadrics.empty()) tmp.attribute_quadrics[n] = mesh.attribute_quadrics[o];
    if (gw) std::memcpy(&tmp.attribute_gradients[gw * n], &mesh.attribute_gradients[gw * o], gw * sizeof(double));
    tmp.source_vertex[n] = mesh.source_vertex[o];
    tmp.lock[n] = mesh.lock[o];
  }
  std::vector<uint8_t> kind(next);
  std::vector<uint32_t> nx(next), pv(next), sib(next);
  for (uint32_t n = 0; n < next; ++n) {
    const uint32_t o = order[n];
    kind[n] = w.kind[o];
    nx[n] = w.next[o] == ~0u ? ~0u : w.vmap[w.next[o]];
    pv[n] = w.prev[o] == ~0u ? ~0u : w.vmap[w.prev[o]];
    sib[n] = w.sibling[o] == ~0u ? ~0u : w.vmap[w.sibling[o]];
    if (kind[n] == kSeam && sib[n] == ~0u) kind[n] = kLocked;  // its copy is gone (cannot happen on a pair)
  }
  w.kind.swap(kind);
  w.next.swap(nx);
  w.prev.swap(pv);
  w.sibling.swap(sib);
  mesh.positions.swap(tmp.positions);
  mesh.attributes.swap(tmp.attributes);
  mesh.quadrics.swap(tmp.quadrics);
  mesh.attribute_quadrics.swap(tmp.attribute_quadrics);
  mesh.attribute_gradients.swap(tmp.attribute_gradients);
  mesh.source_vertex.swap(tmp.source_vertex);
  mesh.lock.swap(tmp.lock);
}

// Copies the live mesh out in object space, each face once: collapses around non-manifold
// input can leave two faces on the same three vertices, and a level should not draw both.
void snapshot(ChainLevelOut& level, Work& w, const QemMesh& mesh) {
  const size_t nv = mesh.positions.size() / 3;
  const size_t ac = mesh.attribute_count;
  const size_t nf = mesh.indices.size() / 3;
  size_t cap = 16;
  while (cap < 2 * nf) cap *= 2;
  std::vector<uint32_t>& table = w.keys;  // reuse: face id per slot
  table.assign(cap, ~0u);
  w.vmap.assign(nv, ~0u);
  level.indices.clear();
  level.positions.clear();
  level.attributes.clear();
  level.source_vertex.clear();
  uint32_t next = 0;
  const uint32_t* idx = mesh.indices.data();
  for (size_t t = 0; t < nf; ++t) {
    const size_t slot = face_set_slot(table, idx, t);
    if (slot == kDuplicateFace) continue;
    table[slot] = uint32_t(t);
    for (int c = 0; c < 3; ++c) {
      const uint32_t v = idx[3 * t + c];
      if (w.vmap[v] == ~0u) {
        w.vmap[v] = next++;
        for (int j = 0; j < 3; ++j) level.positions.push_back(mesh.positions[3 * size_t(v) + j] * mesh.scale);
        for (size_t j = 0; j < ac; ++j) level.attributes.push_back(mesh.attributes[v * ac + j]);
        level.source_vertex.push_back(mesh.source_vertex[v]);
      }
      level.indices.push_back(w.vmap[v]);
    }
  }
  level.error = float(std::sqrt(mesh.error) * mesh.scale);
}

}  // namespace

namespace {

// What every part of one input shares: the frame, the valid faces, vertex locks and the
// weight of the point quadrics.
struct Frame {
  float scale = 1;
  double point_weight = 0;
  std::vector<uint8_t> finite;
  std::vector<uint8_t> lock;    // per input vertex
  std::vector<uint32_t> faces;  // valid input faces, input ids
  std::vector<uint32_t> first_copy;  // per input vertex: the first vertex at its position
};

void make_frame(Frame& f, const float* positions, size_t vertex_count, const uint32_t* indices, size_t index_count,
                const QemOptions& options) {
  // A power-of-two scale and no offset, so normalising is exact and vertices that never move
  // come out bit-identical.
  f.finite.resize(vertex_count);
  float max_abs = 0;
  for (size_t v = 0; v < vertex_count; ++v) {
    const float* p = positions + 3 * v;
    f.finite[v] = std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
    if (!f.finite[v]) continue;
    for (int k = 0; k < 3; ++k) max_abs = std::max(max_abs, std::fabs(p[k]));
  }
  f.scale = max_abs > 0 ? std::exp2(std::ceil(std::log2(max_abs))) : 1.f;
  const float inv = 1 / f.scale;

  // Faces that cannot be simplified meaningfully are dropped: bad indices, repeats, NaNs.
  f.faces.clear();
  f.faces.reserve(index_count);
  for (size_t t = 0; t + 2 < index_count; t += 3) {
    const uint32_t a = indices[t], b = indices[t + 1], c = indices[t + 2];
    if (a >= vertex_count || b >= vertex_count || c >= vertex_count) continue;
    if (a == b || b == c || a == c || !f.finite[a] || !f.finite[b] || !f.finite[c]) continue;
    f.faces.insert(f.faces.end(), {a, b, c});
  }

  f.lock.assign(vertex_count, 0);
  if (options.vertex_lock)
    for (size_t v = 0; v < vertex_count; ++v) f.lock[v] = options.vertex_lock[v] ? QemMesh::kLockUser : 0;
  // Vertices sharing a position (attribute seams, unwelded input) are copies: a pair moves
  // only together along its seam (classify decides where it may), and three or more at one
  // place (a branch of the seam) stay put, since moving one copy alone would tear the surface.
  {
    f.first_copy.resize(vertex_count);
    std::vector<uint32_t> copies(vertex_count);  // per vertex: how many share its position
    find_position_copies(f.first_copy, copies, positions, vertex_count, f.finite.data());
    for (size_t v = 0; v < vertex_count; ++v) {
      if (copies[v] >= 2) f.lock[v] |= QemMesh::kCopy;
      if (copies[v] >= 3) f.lock[v] |= QemMesh::kLockUser;
    }
  }

  // A weak point quadric at every vertex, the same for all: plane quadrics alone see no error
  // when a needle or fin of tiny faces (scan spikes) folds back along its own planes, and a
  // mean-area-normalised cost would remove such features first and cost a large Hausdorff
  // distance. Against ordinary faces it is negligible. Weight: kPointWeight x the mean area
  // per vertex (each face counted at its three corners).
  double area = 0;
  std::vector<uint8_t> has_area(vertex_count, 0);
  for (size_t t = 0; t < f.faces.size(); t += 3) {
    const uint32_t* c = &f.faces[t];
    double e1[3], e2[3];
    for (int k = 0; k < 3; ++k) {
      const float p0 = positions[3 * size_t(c[0]) + k] * inv;
      e1[k] = double(positions[3 * size_t(c[1]) + k] * inv) - p0;
      e2[k] = double(positions[3 * size_t(c[2]) + k] * inv) - p0;
    }
    const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0)) continue;
    area += 3 * 0.5 * len;
    has_area[c[0]] = has_area[c[1]] = has_area[c[2]] = 1;
  }
  size_t with_area = 0;
  for (uint8_t h : has_area) with_area += h;
  f.point_weight = kPointWeight * area / double(std::max<size_t>(with_area, 1));
}

// The working mesh of `vertices` (input ids, in the order they get) and `faces` (ids into
// `vertices`). `seam` (optional, per part vertex) marks vertices shared with another part:
// they are locked, and get their point quadric only where `point_terms_on_seam` (so that
// merging the parts adds it once). Boundary planes come with the first simplification.
void build_part(QemMesh& out, const float* positions, size_t vertex_count, const Frame& f,
                const std::vector<uint32_t>& vertices, std::vector<uint32_t>&& faces, const std::vector<uint8_t>* seam,
                bool point_terms_on_seam, const QemOptions& options) {
  out = QemMesh{};
  out.input_vertex_count = vertex_count;
  out.attribute_count = options.attributes ? options.attribute_count : 0;
  out.scale = f.scale;
  const size_t ac = out.attribute_count;
  const size_t nv = vertices.size();
  const float inv = 1 / f.scale;
  out.positions.resize(3 * nv);
  out.attributes.resize(ac * nv);
  out.source_vertex = vertices;
  out.lock.resize(nv);
  for (size_t i = 0; i < nv; ++i) {
    const uint32_t v = vertices[i];
    for (int k = 0; k < 3; ++k) out.positions[3 * i + k] = f.finite[v] ? positions[3 * size_t(v) + k] * inv : 0;
    if (ac) std::memcpy(&out.attributes[ac * i], options.attributes + ac * v, ac * sizeof(float));
    out.lock[i] = uint8_t(f.lock[v] | (seam && (*seam)[i] ? QemMesh::kLockSeam : 0));
  }
  out.indices = std::move(faces);

  // Area-weighted face planes.
  out.quadrics.assign(nv, Quadric{});
  const size_t nt = out.indices.size() / 3;
  for (size_t t = 0; t < nt; ++t) {
    const float* p0 = &out.positions[3 * size_t(out.indices[3 * t])];
    const float* p1 = &out.positions[3 * size_t(out.indices[3 * t + 1])];
    const float* p2 = &out.positions[3 * size_t(out.indices[3 * t + 2])];
    const double e1[3] = {double(p1[0]) - p0[0], double(p1[1]) - p0[1], double(p1[2]) - p0[2]};
    const double e2[3] = {double(p2[0]) - p0[0], double(p2[1]) - p0[1], double(p2[2]) - p0[2]};
    double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0)) continue;  // zero-area faces carry no plane
    for (double& x : n) x /= len;
    const double d = -(n[0] * p0[0] + n[1] * p0[1] + n[2] * p0[2]);
    for (int k = 0; k < 3; ++k) quadric_add_plane(out.quadrics[out.indices[3 * t + k]], n[0], n[1], n[2], d, 0.5 * len);
  }
  // Attribute quadrics, on every face; a shared vertex gets them in one part only (as its
  // point quadric), so that merging adds them once.
  if (ac && options.attribute_weight > 0) {
    const size_t channels = std::min(ac, kAttributeQuadricChannels);
    const double w2 = double(options.attribute_weight) * options.attribute_weight;
    out.attribute_quadrics.assign(nv, AttributeQuadric{});
    out.attribute_channels = channels;
    out.attribute_gradients.assign(kGradientWords * channels * nv, 0.0);
    AttributeQuadric unused;
    double unused_gradients[kGradientWords * kAttributeQuadricChannels];
    for (size_t t = 0; t < nt; ++t) {
      const uint32_t* c = &out.indices[3 * t];
      const float* p0 = &out.positions[3 * size_t(c[0])];
      const float* p1 = &out.positions[3 * size_t(c[1])];
      const float* p2 = &out.positions[3 * size_t(c[2])];
      const double e1[3] = {double(p1[0]) - p0[0], double(p1[1]) - p0[1], double(p1[2]) - p0[2]};
      const double e2[3] = {double(p2[0]) - p0[0], double(p2[1]) - p0[1], double(p2[2]) - p0[2]};
      const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
      const double area = 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      AttributeQuadric* corners[3];
      double* corner_gradients[3];
      for (int k = 0; k < 3; ++k) {
        const bool skip = seam && (*seam)[c[k]] && !point_terms_on_seam;
        corners[k] = skip ? &unused : &out.attribute_quadrics[c[k]];
        corner_gradients[k] = skip ? unused_gradients : gradients_of(out, c[k]);
      }
      add_face_attributes(corners, corner_gradients, p0, p1, p2, &out.attributes[ac * c[0]], &out.attributes[ac * c[1]],
                          &out.attributes[ac * c[2]], channels, w2 * area);
    }
  }
  for (size_t v = 0; v < nv; ++v) {
    Quadric& q = out.quadrics[v];
    if (!(q.w > 0) || (seam && (*seam)[v] && !point_terms_on_seam)) continue;
    const double wv = f.point_weight;
    const double x = out.positions[3 * v], y = out.positions[3 * v + 1], z = out.positions[3 * v + 2];
    q.a00 += wv, q.a11 += wv, q.a22 += wv;
    q.b0 -= wv * x, q.b1 -= wv * y, q.b2 -= wv * z;
    q.c += wv * (x * x + y * y + z * z);
  }
}

}  // namespace

void qem_prepare(QemMesh& out, const float* positions, size_t vertex_count, const uint32_t* indices,
                 size_t index_count, const QemOptions& options) {
  Frame f;
  make_frame(f, positions, vertex_count, indices, index_count, options);
  std::vector<uint32_t> all(vertex_count);
  for (size_t v = 0; v < vertex_count; ++v) all[v] = uint32_t(v);
  build_part(out, positions, vertex_count, f, all, std::move(f.faces), nullptr, true, options);
}

namespace {

// Constraint planes through border edges, once per mesh, from the classification the first
// simplification makes anyway; edges between two vertices shared with another part are the
// cut, not a border. Seam edges (open on each side, the surface continuing on the other) get
// seam_weight instead, just enough to keep a seam on its line as it is simplified.
void add_border_planes(const Work& w, QemMesh& mesh, float border_weight, float seam_weight) {
  const size_t nv = mesh.positions.size() / 3;
  for (size_t v = 0; v < nv; ++v) {
    const uint32_t b = w.next[v];
    if (b == ~0u) continue;
    if ((mesh.lock[v] & QemMesh::kLockSeam) && (mesh.lock[b] & QemMesh::kLockSeam)) continue;
    uint32_t c = ~0u;  // apex of the border edge's face
    for (uint32_t i = w.offset[v]; i < w.offset[v + 1]; ++i)
      if (w.ring[2 * i] == b) c = w.ring[2 * i + 1];
    if (c == ~0u) continue;
    const float* pa = &mesh.positions[3 * v];
    const float* pb = &mesh.positions[3 * size_t(b)];
    const float* pc = &mesh.positions[3 * size_t(c)];
    const double e[3] = {double(pb[0]) - pa[0], double(pb[1]) - pa[1], double(pb[2]) - pa[2]};
    const double g[3] = {double(pc[0]) - pa[0], double(pc[1]) - pa[1], double(pc[2]) - pa[2]};
    const double n[3] = {e[1] * g[2] - e[2] * g[1], e[2] * g[0] - e[0] * g[2], e[0] * g[1] - e[1] * g[0]};
    // The constraint plane contains the edge and is perpendicular to the face.
    double m[3] = {e[1] * n[2] - e[2] * n[1], e[2] * n[0] - e[0] * n[2], e[0] * n[1] - e[1] * n[0]};
    const double len = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    if (!(len > 0)) continue;
    for (double& x : m) x /= len;
    const double d = -(m[0] * pa[0] + m[1] * pa[1] + m[2] * pa[2]);
    const double wgt = (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]) * (w.seam_out[v] ? seam_weight : border_weight);
    if (!(wgt > 0)) continue;
    // Constraint planes add error but no area: the cost stays a mean over the surface.
    for (uint32_t x : {uint32_t(v), b}) {
      const double keep = mesh.quadrics[x].w;
      quadric_add_plane(mesh.quadrics[x], m[0], m[1], m[2], d, wgt);
      mesh.quadrics[x].w = keep;
    }
  }
}

}  // namespace

size_t qem_simplify_mesh(ChainLevelOut* levels, QemMesh& mesh, const size_t* target_triangles,
                         size_t level_count, const QemOptions& options) {
  Work w;
  w.reserve(mesh.positions.size() / 3, mesh.indices.size() / 3);
  const double limit = options.max_error > 0 ? double(options.max_error) / mesh.scale : 0;
  const double cost_limit = options.max_error > 0 ? limit * limit : std::numeric_limits<double>::max();
  size_t compacted_at = mesh.triangle_count();
  bool hit_limit = false;
  size_t previous_target = mesh.triangle_count();
  build_lists(w, mesh);
  classify(w, mesh, options.lock_border, options.move_nonmanifold);
  if (!mesh.border_planes) {
    if (options.border_weight > 0 || options.seam_weight > 0)
      add_border_planes(w, mesh, options.border_weight, options.seam_weight);
    mesh.border_planes = true;
  }
  bool lists_current = true;
  for (size_t l = 0; l < level_count; ++l) {
    const size_t target = std::min(target_triangles[l], previous_target);
    previous_target = target;
    for (int pass = 0; pass < kMaxPassesPerLevel && mesh.triangle_count() > target && !hit_limit; ++pass) {
      if (2 * mesh.triangle_count() < compacted_at) {
        compact_vertices(w, mesh);
        compacted_at = mesh.triangle_count();
        lists_current = false;
      }
      // no edges can be collapsed any more: topology, locks or the error limit
      const size_t removed = collapse_pass(w, mesh, target, cost_limit, hit_limit, lists_current);
      lists_current = false;
      if (removed == 0) break;
    }
    levels[l].target_triangles = target_triangles[l];
    levels[l].reached = mesh.triangle_count() <= target;
    snapshot(levels[l], w, mesh);
  }
  return level_count;
}

size_t qem_simplify_chain(ChainLevelOut* levels, const float* positions, size_t vertex_count,
                          const uint32_t* indices, size_t index_count, const size_t* target_triangles,
                          size_t level_count, const QemOptions& options) {
  QemMesh mesh;
  qem_prepare(mesh, positions, vertex_count, indices, index_count, options);
  return qem_simplify_mesh(levels, mesh, target_triangles, level_count, options);
}

size_t qem_split(QemMesh* parts, const QemMesh& whole) {
  const size_t nt = whole.triangle_count();
  const size_t nv = whole.positions.size() / 3;
  if (nt < kMinSplitTriangles) {
    parts[0] = whole;
    return 1;
  }
  // Longest axis of the used vertices.
  float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
  for (uint32_t v : whole.indices)
    for (int k = 0; k < 3; ++k)
      lo[k] = std::min(lo[k], whole.positions[3 * size_t(v) + k]), hi[k] = std::max(hi[k], whole.positions[3 * size_t(v) + k]);
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
  std::vector<float> centre(nt);
  for (size_t t = 0; t < nt; ++t) {
    float s = 0;
    for (int k = 0; k < 3; ++k) s += whole.positions[3 * size_t(whole.indices[3 * t + k]) + axis];
    centre[t] = s;
  }
  std::vector<float> sorted = centre;
  std::nth_element(sorted.begin(), sorted.begin() + nt / 2, sorted.end());
  const float median = sorted[nt / 2];

  std::vector<uint8_t> side(nt), used(nv, 0);
  for (size_t t = 0; t < nt; ++t) {
    side[t] = centre[t] < median ? 0 : 1;
    for (int k = 0; k < 3; ++k) used[whole.indices[3 * t + k]] |= uint8_t(1u << side[t]);
  }
  const size_t ac = whole.attribute_count;
  for (int p = 0; p < 2; ++p) {
    QemMesh& part = parts[p];
    part = QemMesh{};
    part.attribute_count = ac;
    part.attribute_channels = whole.attribute_channels;
    part.input_vertex_count = whole.input_vertex_count;
    part.scale = whole.scale;
    part.error = whole.error;
    part.border_planes = whole.border_planes;
    std::vector<uint32_t> local(nv, ~0u);
    for (size_t v = 0; v < nv; ++v) {
      if (!(used[v] & (1u << p))) continue;
      local[v] = uint32_t(part.source_vertex.size());
      const bool seam = used[v] == 3;
      part.positions.insert(part.positions.end(), &whole.positions[3 * v], &whole.positions[3 * v] + 3);
      if (ac) part.attributes.insert(part.attributes.end(), &whole.attributes[ac * v], &whole.attributes[ac * v] + ac);
      // A shared vertex's quadric goes to part 0 only, so merging can simply add them.
      part.quadrics.push_back(seam && p == 1 ? Quadric{} : whole.quadrics[v]);
      if (!whole.attribute_quadrics.empty()) {
        part.attribute_quadrics.push_back(seam && p == 1 ? AttributeQuadric{} : whole.attribute_quadrics[v]);
        const double* g = gradients_of(whole, uint32_t(v));
        const size_t gw = kGradientWords * whole.attribute_channels;
        if (seam && p == 1) part.attribute_gradients.resize(part.attribute_gradients.size() + gw, 0.0);
        else part.attribute_gradients.insert(part.attribute_gradients.end(), g, g + gw);
      }
      part.source_vertex.push_back(whole.source_vertex[v]);
      part.lock.push_back(uint8_t(whole.lock[v] | (seam ? QemMesh::kLockSeam : 0)));
    }
    for (size_t t = 0; t < nt; ++t) {
      if (side[t] != p) continue;
      for (int k = 0; k < 3; ++k) part.indices.push_back(local[whole.indices[3 * t + k]]);
    }
  }
  return 2;
}

void qem_merge(QemMesh& out, const QemMesh* parts, size_t part_count) {
  out = QemMesh{};
  if (part_count == 0) return;
  const size_t ac = parts[0].attribute_count;
  out.attribute_count = ac;
  out.attribute_channels = parts[0].attribute_channels;
  const size_t gw = kGradientWords * out.attribute_channels;
  out.input_vertex_count = parts[0].input_vertex_count;
  out.scale = parts[0].scale;
  std::vector<uint32_t> merged(out.input_vertex_count, ~0u);
  for (size_t p = 0; p < part_count; ++p) {
    const QemMesh& part = parts[p];
    out.error = std::max(out.error, part.error);
    out.border_planes = out.border_planes || part.border_planes;
    const size_t nv = part.source_vertex.size();
    std::vector<uint32_t> local(nv, ~0u);
    // Only live vertices survive the merge.
    for (uint32_t v : part.indices) local[v] = 0;
    for (size_t v = 0; v < nv; ++v) {
      if (local[v] == ~0u) continue;
      const uint32_t src = part.source_vertex[v];
      if ((part.lock[v] & QemMesh::kLockSeam) && merged[src] != ~0u) {
        local[v] = merged[src];
        quadric_add(out.quadrics[merged[src]], part.quadrics[v]);
        if (!part.attribute_quadrics.empty()) {
          attribute_add(out.attribute_quadrics[merged[src]], part.attribute_quadrics[v]);
          gradients_add(gradients_of(out, merged[src]), gradients_of(part, uint32_t(v)), out.attribute_channels);
        }
        continue;
      }
      local[v] = uint32_t(out.source_vertex.size());
      merged[src] = local[v];
      out.positions.insert(out.positions.end(), &part.positions[3 * v], &part.positions[3 * v] + 3);
      if (ac) out.attributes.insert(out.attributes.end(), &part.attributes[ac * v], &part.attributes[ac * v] + ac);
      out.quadrics.push_back(part.quadrics[v]);
      if (!part.attribute_quadrics.empty()) {
        out.attribute_quadrics.push_back(part.attribute_quadrics[v]);
        const double* g = gradients_of(part, uint32_t(v));
        out.attribute_gradients.insert(out.attribute_gradients.end(), g, g + gw);
      }
      out.source_vertex.push_back(src);
      out.lock.push_back(uint8_t(part.lock[v] & ~QemMesh::kLockSeam));
    }
    for (uint32_t v : part.indices) out.indices.push_back(local[v]);
  }
}

void chain_level_merge(ChainLevelOut& out, const ChainLevelOut* parts, size_t part_count) {
  out = ChainLevelOut{};
  if (part_count == 0) return;
  uint32_t max_source = 0;
  for (size_t p = 0; p < part_count; ++p)
    for (uint32_t s : parts[p].source_vertex) max_source = std::max(max_source, s);
  std::vector<uint32_t> merged(size_t(max_source) + 1, ~0u);
  const size_t ac = parts[0].positions.empty() ? 0 : parts[0].attributes.size() / (parts[0].positions.size() / 3);
  out.target_triangles = 0;
  out.reached = true;
  for (size_t p = 0; p < part_count; ++p) {
    const ChainLevelOut& part = parts[p];
    out.target_triangles += part.target_triangles;
    out.reached = out.reached && part.reached;
    out.error = std::max(out.error, part.error);
    const size_t nv = part.source_vertex.size();
    std::vector<uint32_t> local(nv);
    for (size_t v = 0; v < nv; ++v) {
      const uint32_t src = part.source_vertex[v];
      if (merged[src] != ~0u) {
        local[v] = merged[src];  // a shared (locked) vertex: same position in every part
        continue;
      }
      local[v] = merged[src] = uint32_t(out.source_vertex.size());
      out.positions.insert(out.positions.end(), &part.positions[3 * v], &part.positions[3 * v] + 3);
      if (ac) out.attributes.insert(out.attributes.end(), &part.attributes[ac * v], &part.attributes[ac * v] + ac);
      out.source_vertex.push_back(src);
    }
    for (uint32_t v : part.indices) out.indices.push_back(local[v]);
  }
}

size_t qem_simplify_chain_split(ChainLevelOut* levels, const float* positions, size_t vertex_count,
                                const uint32_t* indices, size_t index_count,
                                const size_t* target_triangles, size_t level_count,
                                const QemOptions& options, const ParallelFor& parallel_for) {
  Frame f;
  make_frame(f, positions, vertex_count, indices, index_count, options);
  const size_t nt = f.faces.size() / 3;
  if (nt < kMinSplitTriangles) {
    QemMesh whole;
    std::vector<uint32_t> all(vertex_count);
    for (size_t v = 0; v < vertex_count; ++v) all[v] = uint32_t(v);
    build_part(whole, positions, vertex_count, f, all, std::move(f.faces), nullptr, true, options);
    return qem_simplify_mesh(levels, whole, target_triangles, level_count, options);
  }

  // Halves at the median face centre along the longest axis; every part is then built and
  // simplified on its own thread, so only this split is serial.
  const float inv = 1 / f.scale;
  float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
  for (uint32_t v : f.faces)
    for (int k = 0; k < 3; ++k)
      lo[k] = std::min(lo[k], positions[3 * size_t(v) + k] * inv), hi[k] = std::max(hi[k], positions[3 * size_t(v) + k] * inv);
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
  std::vector<float> centre(nt);
  for (size_t t = 0; t < nt; ++t) {
    float c = 0;
    for (int k = 0; k < 3; ++k) c += positions[3 * size_t(f.faces[3 * t + k]) + axis] * inv;
    centre[t] = c;
  }
  std::vector<float> sorted = centre;
  std::nth_element(sorted.begin(), sorted.begin() + std::ptrdiff_t(nt / 2), sorted.end());
  const float median = sorted[nt / 2];
  std::vector<uint8_t> side(nt), used(vertex_count, 0);
  size_t faces_in[2] = {0, 0};
  for (size_t t = 0; t < nt; ++t) {
    side[t] = centre[t] < median ? 0 : 1;
    faces_in[side[t]]++;
    for (int k = 0; k < 3; ++k) used[f.faces[3 * t + k]] |= uint8_t(1u << side[t]);
  }
  // Shared vertices, and copies of an attribute seam split between the halves (each half
  // holds one and locks it): both stay put until the halves are merged.
  std::vector<uint8_t> sides(vertex_count, 0);
  for (size_t v = 0; v < vertex_count; ++v)
    if (f.lock[v] & QemMesh::kCopy) sides[f.first_copy[v]] |= used[v];
  size_t seam = 0;
  for (size_t v = 0; v < vertex_count; ++v)
    seam += used[v] == 3 || (used[v] && (f.lock[v] & QemMesh::kCopy) && sides[f.first_copy[v]] == 3);

  // The halves run alone while their locked shared border is small next to the target.
  constexpr size_t kSeamFactor = 12;
  const size_t handoff = std::min(nt, kSeamFactor * seam);
  size_t parallel_levels = 0;
  while (parallel_levels < level_count && target_triangles[parallel_levels] >= handoff) parallel_levels++;

  QemMesh parts[2];
  std::vector<ChainLevelOut> part_levels[2];
  parallel_for(2, [&](size_t p) {
    std::vector<uint32_t> local(vertex_count, ~0u), vertices, faces;
    std::vector<uint8_t> on_seam;
    faces.reserve(3 * faces_in[p]);
    for (size_t t = 0; t < nt; ++t) {
      if (side[t] != p) continue;
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = f.faces[3 * t + k];
        if (local[v] == ~0u) {
          local[v] = uint32_t(vertices.size());
          vertices.push_back(v);
          on_seam.push_back(used[v] == 3);
        }
        faces.push_back(local[v]);
      }
    }
    build_part(parts[p], positions, vertex_count, f, vertices, std::move(faces), &on_seam, p == 0, options);
    const double share = double(faces_in[p]) / double(nt);
    std::vector<size_t> targets;
    for (size_t l = 0; l < parallel_levels; ++l) targets.push_back(size_t(std::llround(target_triangles[l] * share)));
    const size_t last = parallel_levels ? target_triangles[parallel_levels - 1] : nt;
    if (parallel_levels < level_count && handoff < last) targets.push_back(size_t(std::llround(handoff * share)));
    part_levels[p].resize(targets.size());
    qem_simplify_mesh(part_levels[p].data(), parts[p], targets.data(), targets.size(), options);
  });
  for (size_t l = 0; l < parallel_levels; ++l) {
    const ChainLevelOut pair[2] = {std::move(part_levels[0][l]), std::move(part_levels[1][l])};
    chain_level_merge(levels[l], pair, 2);
    levels[l].target_triangles = target_triangles[l];
  }
  if (parallel_levels == level_count) return level_count;
  QemMesh whole;
  qem_merge(whole, parts, 2);
  parts[0] = parts[1] = QemMesh{};
  qem_simplify_mesh(levels + parallel_levels, whole, target_triangles + parallel_levels,
                    level_count - parallel_levels, options);
  return level_count;
}

}  // namespace lod
