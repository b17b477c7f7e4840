// Vertex hierarchy builder: passes of independent legal edge collapses on flat arrays.
//
// Berkey and Song, "Dynamic View Dependent Level of Detail": merge tree, region-of-influence marking,
// dependencies = neighbours at collapse time, tv1/tv2 wings. Hoppe 1997 ("View-dependent
// refinement of progressive meshes"): normal cones, bounding spheres, error per node.
// Garland & Heckbert 1997: quadrics. Each pass: vertex->face lists from the current faces,
// every edge once with its face count (sorted keys), costs, sort, then greedy collapses with
// both endpoints' one-rings locked for the rest of the pass, so the adjacency built at the
// start of the pass stays exact wherever a collapse may still happen.
#include "preprocess/vertex_hierarchy.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include "preprocess/edge_parameter.h"
#include "preprocess/position_copies.h"

namespace lod {

namespace {

struct Quad {
  double a00 = 0, a11 = 0, a22 = 0, a01 = 0, a02 = 0, a12 = 0;
  double b0 = 0, b1 = 0, b2 = 0, c = 0;
  double w = 0;

  void add_plane(double nx, double ny, double nz, double d, double weight) {
    a00 += weight * nx * nx, a11 += weight * ny * ny, a22 += weight * nz * nz;
    a01 += weight * nx * ny, a02 += weight * nx * nz, a12 += weight * ny * nz;
    b0 += weight * nx * d, b1 += weight * ny * d, b2 += weight * nz * d;
    c += weight * d * d;
    w += weight;
  }
  void add(const Quad& q) {
    a00 += q.a00, a11 += q.a11, a22 += q.a22, a01 += q.a01, a02 += q.a02, a12 += q.a12;
    b0 += q.b0, b1 += q.b1, b2 += q.b2, c += q.c, w += q.w;
  }
  double eval(const double* p) const {
    const double x = p[0], y = p[1], z = p[2];
    const double e = a00 * x * x + a11 * y * y + a22 * z * z + 2 * (a01 * x * y + a02 * x * z + a12 * y * z) +
                     2 * (b0 * x + b1 * y + b2 * z) + c;
    return e > 0 ? e : 0;
  }
  // Minimiser of the quadric; false when A is near singular (flat or linear neighbourhoods).
  bool optimum(double* out) const {
    const double c00 = a11 * a22 - a12 * a12, c01 = a02 * a12 - a01 * a22, c02 = a01 * a12 - a02 * a11;
    const double det = a00 * c00 + a01 * c01 + a02 * c02;
    const double scale = std::abs(a00) + std::abs(a11) + std::abs(a22);
    if (!(std::abs(det) > 1e-10 * scale * scale * scale) || scale == 0) return false;
    const double c11 = a00 * a22 - a02 * a02, c12 = a01 * a02 - a00 * a12, c22 = a00 * a11 - a01 * a01;
    const double inv = -1.0 / det;
    out[0] = inv * (c00 * b0 + c01 * b1 + c02 * b2);
    out[1] = inv * (c01 * b0 + c11 * b1 + c12 * b2);
    out[2] = inv * (c02 * b0 + c12 * b1 + c22 * b2);
    return std::isfinite(out[0]) && std::isfinite(out[1]) && std::isfinite(out[2]);
  }
};

struct Vec {
  double x = 0, y = 0, z = 0;
};
inline Vec sub(const Vec& a, const Vec& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec cross(const Vec& a, const Vec& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double dot(const Vec& a, const Vec& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline double length(const Vec& a) { return std::sqrt(dot(a, a)); }

// Normal cone as axis + half-angle (radians); half-angle < 0 marks "no normals yet".
struct Cone {
  Vec axis;
  double half = -1;
};

Cone merge_cones(const Cone& a, const Cone& b) {
  if (a.half < 0) return b;
  if (b.half < 0) return a;
  const double phi = std::acos(std::clamp(dot(a.axis, b.axis), -1.0, 1.0));
  if (phi + b.half <= a.half) return a;
  if (phi + a.half <= b.half) return b;
  const double half = 0.5 * (phi + a.half + b.half);
  if (half >= M_PI || phi < 1e-9) return {a.axis, std::min(half, M_PI)};
  // Rotate a's axis towards b's by (half - a.half) along the great circle.
  const double t = (half - a.half) / phi;
  const double s = std::sin(phi);
  const double wa = std::sin((1 - t) * phi) / s, wb = std::sin(t * phi) / s;
  Vec axis{wa * a.axis.x + wb * b.axis.x, wa * a.axis.y + wb * b.axis.y, wa * a.axis.z + wb * b.axis.z};
  const double len = length(axis);
  if (!(len > 1e-12)) return {a.axis, M_PI};
  return {{axis.x / len, axis.y / len, axis.z / len}, half};
}

// A leaf normal as the tree keeps it: the input's when unit (within kTreeNormalTolerance) or
// zero, else normalised (OBJ's vn need not be unit).
void unit_or_zero(float* n) {
  const double len = std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
  if (len == 0 || std::abs(len - 1) <= 0.5 * kTreeNormalTolerance) return;
  for (int k = 0; k < 3; ++k) n[k] = static_cast<float>(n[k] / len);
}

// An optional per-vertex column of the mesh: `width` values per vertex, finite and not huge.
Status check_attribute(const MeshData& mesh, const std::vector<float>& values, size_t width,
                       const char* what) {
  if (values.empty()) return Status::success();
  if (values.size() != width * mesh.vertex_count())
    return Status::error(mesh.source + ": " + std::to_string(values.size()) + " " + what + " values for " +
                         std::to_string(mesh.vertex_count()) + " vertices (" + std::to_string(width) +
                         " each)");
  for (size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i]) || std::abs(values[i]) > kMaxTreeMagnitude)
      return Status::error(mesh.source + ": vertex " + std::to_string(i / width) +
                           " has a non-finite or huge " + what);
  return Status::success();
}

class Builder {
 public:
  Builder(const HierarchyOptions& options) : opt_(options) {}

  Status run(VertexTree& out, const MeshData& mesh);

 private:
  Vec pos(uint32_t v) const { return {pos_[3 * v], pos_[3 * v + 1], pos_[3 * v + 2]}; }
  void build_adjacency();
  void collect_edges();
  bool try_collapse(uint32_t a, uint32_t b);
  void finish(VertexTree& out);
  void mark_split_fans();
  void pin_part_seams();
  void pin_attribute_seams(const MeshData& mesh, const std::vector<int32_t>& face_material);
  void renumber_passes();
  void push_parent_normal(uint32_t a, uint32_t b, float t, const Cone& cone);
  std::vector<uint32_t> pass_start_;  // first node id made by each pass

  HierarchyOptions opt_;
  uint32_t leaf_count_ = 0;
  std::vector<double> pos_;  // per node
  std::vector<float> uv_;    // per node, 2 each, when the mesh has uvs
  std::vector<float> uv1_;   // per node, 2 each, when the mesh has a second uv set
  std::vector<float> color_;   // per node, 4 each (linear RGBA), when the mesh has colours
  std::vector<float> normal_;  // per node, 3 each (unit or zero), when the mesh has normals
  std::vector<Quad> quad_;   // per node
  std::vector<Cone> cone_;   // per node
  std::vector<float> radius_, error_;
  std::vector<uint32_t> parent_;

  std::vector<uint32_t> leaves_;  // input corners, 3 per kept face
  std::vector<uint32_t> face_;    // current corners (node ids), 3 per face
  std::vector<uint8_t> face_alive_;
  std::vector<uint32_t> face_owner_;
  std::vector<uint32_t> alive_faces_;  // faces alive at the start of the pass

  // Per pass: vertex -> alive faces (CSR over node ids), flags, locks.
  std::vector<uint32_t> vf_off_, vf_;
  std::vector<uint8_t> border_, complex_, locked_;
  std::vector<uint8_t> nonmanifold_;  // input vertices never collapsed: split fans, part seams
  std::vector<uint32_t> stamp_, stamp_b_;
  uint32_t stamp_now_ = 0;

  struct Edge {
    uint32_t a, b;
    double cost;
  };
  std::vector<Edge> edges_;
  std::vector<uint64_t> keys_, key_scratch_;
  std::vector<Edge> sorted_;

  // Interior node records, appended per collapse.
  std::vector<uint32_t> children_, split_faces_, wings_;
  std::vector<uint32_t> dep_off_{0}, deps_, inc_off_{0}, inc_;

  // Scratch per collapse.
  std::vector<uint32_t> nbr_a_, nbr_b_, faces_ab_;
};

void Builder::build_adjacency() {
  const size_t n = parent_.size();
  vf_off_.assign(n + 1, 0);
  alive_faces_.clear();
  for (uint32_t f = 0; f < face_alive_.size(); ++f) {
    if (!face_alive_[f]) continue;
    alive_faces_.push_back(f);
    for (int k = 0; k < 3; ++k) ++vf_off_[face_[3 * f + k] + 1];
  }
  for (size_t v = 0; v < n; ++v) vf_off_[v + 1] += vf_off_[v];
  vf_.resize(vf_off_[n]);
  std::vector<uint32_t> fill(vf_off_.begin(), vf_off_.end() - 1);
  for (uint32_t f : alive_faces_)
    for (int k = 0; k < 3; ++k) vf_[fill[face_[3 * f + k]]++] = f;
  border_.assign(n, 0);
  complex_.assign(n, 0);
  locked_.assign(n, 0);
  if (stamp_.size() < n) stamp_.resize(n, 0), stamp_b_.resize(n, 0);
}

// LSD radix sort of 64-bit keys, 16 bits per pass; passes whose digit never varies are skipped.
void radix_sort(std::vector<uint64_t>& keys, std::vector<uint64_t>& scratch) {
  scratch.resize(keys.size());
  std::vector<uint32_t> count(1 << 16);
  for (int shift = 0; shift < 64; shift += 16) {
    std::fill(count.begin(), count.end(), 0u);
    for (uint64_t k : keys) ++count[(k >> shift) & 0xffff];
    if (!keys.empty() && count[(keys[0] >> shift) & 0xffff] == keys.size()) continue;
    uint32_t sum = 0;
    for (uint32_t& c : count) {
      const uint32_t n = c;
      c = sum;
      sum += n;
    }
    for (uint64_t k : keys) scratch[count[(k >> shift) & 0xffff]++] = k;
    keys.swap(scratch);
  }
}

// Every edge once, from each vertex to its larger neighbours, with its face count.
void Builder::collect_edges() {
  std::vector<uint8_t> border_edges(parent_.size(), 0);
  edges_.clear();
  std::vector<std::pair<uint32_t, uint32_t>> around;  // (neighbour, faces on the edge)
  for (uint32_t a = 0; a < parent_.size(); ++a) {
    if (vf_off_[a] == vf_off_[a + 1]) continue;
    around.clear();
    for (uint32_t k = vf_off_[a]; k < vf_off_[a + 1]; ++k) {
      const uint32_t* c = &face_[3 * vf_[k]];
      for (int j = 0; j < 3; ++j) {
        const uint32_t u = c[j];
        if (u <= a) continue;
        auto it = std::find_if(around.begin(), around.end(), [&](const auto& e) { return e.first == u; });
        if (it == around.end())
          around.push_back({u, 1});
        else
          ++it->second;
      }
    }
    for (const auto& [b, count] : around) {
      if (count == 1) {
        border_[a] = border_[b] = 1;
        border_edges[a] = static_cast<uint8_t>(std::min(border_edges[a] + 1, 255));
        border_edges[b] = static_cast<uint8_t>(std::min(border_edges[b] + 1, 255));
      } else if (count > 2) {
        complex_[a] = complex_[b] = 1;
      }
      edges_.push_back({a, b, 0});
    }
  }
  // A manifold border vertex has exactly two border edges; more is a bow-tie.
  for (size_t v = 0; v < border_edges.size(); ++v)
    if ((border_edges[v] != 0 && border_edges[v] != 2) || (v < nonmanifold_.size() && nonmanifold_[v]))
      complex_[v] = 1;

  size_t kept = 0;
  for (const Edge& e : edges_) {
    if (complex_[e.a] || complex_[e.b]) continue;
    double cost;
    if (opt_.order == CollapseOrder::shortest) {
      const Vec d = sub(pos(e.a), pos(e.b));
      cost = dot(d, d);
    } else {
      Quad q = quad_[e.a];
      q.add(quad_[e.b]);
      double p[3];
      if (q.optimum(p)) {
        cost = q.eval(p);
      } else {
        double mid[3] = {0.5 * (pos_[3 * e.a] + pos_[3 * e.b]), 0.5 * (pos_[3 * e.a + 1] + pos_[3 * e.b + 1]),
                         0.5 * (pos_[3 * e.a + 2] + pos_[3 * e.b + 2])};
        cost = std::min({q.eval(&pos_[3 * e.a]), q.eval(&pos_[3 * e.b]), q.eval(mid)});
      }
    }
    edges_[kept++] = {e.a, e.b, cost};
  }
  edges_.resize(kept);
  // Cheapest first; costs are >= 0, so their float bits order like the values, and the edge
  // index in the low bits breaks ties deterministically.
  keys_.resize(kept);
  for (size_t i = 0; i < kept; ++i)
    keys_[i] = uint64_t(std::bit_cast<uint32_t>(static_cast<float>(edges_[i].cost))) << 32 | i;
  radix_sort(keys_, key_scratch_);
  sorted_.resize(kept);
  for (size_t i = 0; i < kept; ++i) sorted_[i] = edges_[static_cast<uint32_t>(keys_[i])];
  edges_.swap(sorted_);
}

bool Builder::try_collapse(uint32_t a, uint32_t b) {
  // Neighbours of a (stamped in stamp_) and of b (in stamp_b_), and the faces on the edge.
  const uint32_t sa = ++stamp_now_;
  nbr_a_.clear();
  nbr_b_.clear();
  faces_ab_.clear();
  auto gather = [&](uint32_t v, std::vector<uint32_t>& out, std::vector<uint32_t>& stamp) {
    for (uint32_t k = vf_off_[v]; k < vf_off_[v + 1]; ++k) {
      const uint32_t f = vf_[k];
      for (int c = 0; c < 3; ++c) {
        const uint32_t u = face_[3 * f + c];
        if (u != v && stamp[u] != sa) stamp[u] = sa, out.push_back(u);
      }
    }
  };
  gather(a, nbr_a_, stamp_);
  gather(b, nbr_b_, stamp_b_);
  for (uint32_t k = vf_off_[a]; k < vf_off_[a + 1]; ++k) {
    const uint32_t f = vf_[k];
    const uint32_t* c = &face_[3 * f];
    if (c[0] == b || c[1] == b || c[2] == b) faces_ab_.push_back(f);
  }
  const size_t k_faces = faces_ab_.size();
  if (k_faces == 0 || k_faces > 2) return false;
  const bool interior_edge = k_faces == 2;
  if (interior_edge && border_[a] && border_[b]) return false;  // would pinch two borders together

  // Link condition: the common neighbours are exactly the wings.
  uint32_t wing[2] = {kNoNode, kNoNode};
  for (size_t i = 0; i < k_faces; ++i) {
    const uint32_t* c = &face_[3 * faces_ab_[i]];
    for (int j = 0; j < 3; ++j)
      if (c[j] != a && c[j] != b) wing[i] = c[j];
  }
  if (interior_edge && wing[0] == wing[1]) return false;
  size_t common = 0;
  for (uint32_t u : nbr_b_)
    if (u != a && stamp_[u] == sa) ++common;
  if (common != k_faces) return false;

  // Fans stay proper: a wing loses one neighbour, the new vertex keeps a fan of faces.
  for (size_t i = 0; i < k_faces; ++i) {
    const uint32_t w = wing[i];
    uint32_t faces_w = 0;  // alive now: an earlier collapse of this pass may have removed some
    for (uint32_t k = vf_off_[w]; k < vf_off_[w + 1]; ++k) faces_w += face_alive_[vf_[k]];
    const uint32_t degree = faces_w + (border_[w] ? 1 : 0);
    if (degree - 1 < (border_[w] ? 2u : 3u)) return false;
  }
  const uint32_t faces_after =
      (vf_off_[a + 1] - vf_off_[a]) + (vf_off_[b + 1] - vf_off_[b]) - 2 * uint32_t(k_faces);
  if (faces_after == 0) return false;  // keep at least one triangle of every component
  if (!border_[a] && !border_[b] && faces_after < 3) return false;

  // Placement: optimal, else the cheapest of the endpoints and the midpoint that folds nothing.
  Quad q = quad_[a];
  q.add(quad_[b]);
  double cand[4][3];
  int cand_count = 0;
  const Vec pa = pos(a), pb = pos(b);
  if (opt_.order == CollapseOrder::shortest) {
    cand[cand_count][0] = 0.5 * (pa.x + pb.x), cand[cand_count][1] = 0.5 * (pa.y + pb.y);
    cand[cand_count++][2] = 0.5 * (pa.z + pb.z);
  } else {
    if (q.optimum(cand[cand_count])) ++cand_count;
    cand[cand_count][0] = 0.5 * (pa.x + pb.x), cand[cand_count][1] = 0.5 * (pa.y + pb.y);
    cand[cand_count++][2] = 0.5 * (pa.z + pb.z);
    cand[cand_count][0] = pa.x, cand[cand_count][1] = pa.y, cand[cand_count++][2] = pa.z;
    cand[cand_count][0] = pb.x, cand[cand_count][1] = pb.y, cand[cand_count++][2] = pb.z;
    // Border vertices stay on the border: prefer the border endpoint when only one is.
    if (border_[a] != border_[b]) {
      const Vec keep = border_[a] ? pa : pb;
      cand[0][0] = keep.x, cand[0][1] = keep.y, cand[0][2] = keep.z;
      cand_count = 1;
    }
  }
  int best = -1;
  double best_cost = 0;
  for (int ci = 0; ci < cand_count; ++ci) {
    const Vec p{cand[ci][0], cand[ci][1], cand[ci][2]};
    bool ok = true;
    for (uint32_t v : {a, b}) {
      for (uint32_t k = vf_off_[v]; k < vf_off_[v + 1] && ok; ++k) {
        const uint32_t f = vf_[k];
        if (std::find(faces_ab_.begin(), faces_ab_.end(), f) != faces_ab_.end()) continue;
        Vec c[3], d[3];
        for (int j = 0; j < 3; ++j) {
          c[j] = pos(face_[3 * f + j]);
          d[j] = (face_[3 * f + j] == v) ? p : c[j];
        }
        const Vec n0 = cross(sub(c[1], c[0]), sub(c[2], c[0]));
        const Vec n1 = cross(sub(d[1], d[0]), sub(d[2], d[0]));
        const double l0 = length(n0), l1 = length(n1);
        if (l0 == 0) continue;  // was degenerate already: nothing to fold
        if (!(l1 > 0) || dot(n0, n1) < opt_.min_normal_cos * l0 * l1) ok = false;
      }
    }
    if (!ok) continue;
    const double cost = q.eval(cand[ci]);
    if (best < 0 || cost < best_cost) best = ci, best_cost = cost;
  }
  if (best < 0) return false;

  // Commit: new node p.
  const uint32_t p = static_cast<uint32_t>(parent_.size());
  parent_.push_back(kNoNode);
  parent_[a] = parent_[b] = p;
  pos_.insert(pos_.end(), cand[best], cand[best] + 3);
  quad_.push_back(q);
  cone_.push_back(merge_cones(cone_[a], cone_[b]));
  if (!uv_.empty() || !uv1_.empty() || !color_.empty() || !normal_.empty()) {
    // Both endpoints lie in one chart (seam copies never collapse), so their attributes interpolate.
    const float fa[3] = {float(pa.x), float(pa.y), float(pa.z)}, fb[3] = {float(pb.x), float(pb.y), float(pb.z)};
    const float fp[3] = {float(cand[best][0]), float(cand[best][1]), float(cand[best][2])};
    const float t = edge_parameter(fa, fb, fp);
    auto interpolate = [&](std::vector<float>& column, size_t width) {
      for (size_t k = 0; k < width; ++k) {
        const float ua = column[width * a + k], ub = column[width * b + k];
        column.push_back(std::clamp((1 - t) * ua + t * ub, std::min(ua, ub), std::max(ua, ub)));
      }
    };
    if (!uv_.empty()) interpolate(uv_, 2);
    if (!uv1_.empty()) interpolate(uv1_, 2);
    if (!color_.empty()) interpolate(color_, 4);
    if (!normal_.empty()) push_parent_normal(a, b, t, cone_.back());
  }
  const Vec pp = pos(p);
  radius_.push_back(
      static_cast<float>(std::max(length(sub(pp, pa)) + radius_[a], length(sub(pp, pb)) + radius_[b])));
  const double rms = q.w > 0 ? std::sqrt(best_cost / q.w) : 0.0;
  const double floor = 0.05 * length(sub(pa, pb));  // so that a flat region still refines when close
  error_.push_back(static_cast<float>(std::max({double(error_[a]), double(error_[b]), rms, floor})));

  children_.push_back(a);
  children_.push_back(b);
  for (size_t i = 0; i < 2; ++i) {
    const uint32_t f = i < k_faces ? faces_ab_[i] : kNoNode;
    split_faces_.push_back(f);
    wings_.push_back(i < k_faces ? wing[i] : kNoNode);
    if (f != kNoNode) {
      face_alive_[f] = 0;
      face_owner_[f] = p;
    }
  }
  // Dependencies: p's neighbours (a's and b's but for each other).
  for (uint32_t u : nbr_a_)
    if (u != b) deps_.push_back(u);
  for (uint32_t u : nbr_b_)
    if (u != a && stamp_[u] != sa) deps_.push_back(u);
  dep_off_.push_back(static_cast<uint32_t>(deps_.size()));
  // Incident faces after the collapse: a's and b's surviving faces, corners renamed to p.
  for (uint32_t v : {a, b})
    for (uint32_t k = vf_off_[v]; k < vf_off_[v + 1]; ++k) {
      const uint32_t f = vf_[k];
      if (!face_alive_[f]) continue;
      uint32_t* c = &face_[3 * f];
      if (c[0] != v && c[1] != v && c[2] != v) continue;  // already renamed (shared with the other)
      for (int j = 0; j < 3; ++j)
        if (c[j] == v) c[j] = p;
      inc_.push_back(f);
    }
  inc_off_.push_back(static_cast<uint32_t>(inc_.size()));

  // Region of influence: both one-rings stay untouched for the rest of the pass.
  locked_[a] = locked_[b] = 1;
  for (uint32_t u : nbr_a_) locked_[u] = 1;
  for (uint32_t u : nbr_b_) locked_[u] = 1;
  return true;
}

// Collapses of one pass are independent (their regions never overlap), so their nodes may be
// numbered in any order without breaking "parents and dependencies come later". Numbering
// each pass's nodes along a Morton curve puts neighbours in space next to each other in
// memory, which is what the front's random walks over nodes and dependencies need.
void Builder::renumber_passes() {
  const uint32_t n = static_cast<uint32_t>(parent_.size());
  if (n == leaf_count_) return;
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (uint32_t v = 0; v < n; ++v)
    for (int k = 0; k < 3; ++k)
      lo[k] = std::min(lo[k], pos_[3 * v + k]), hi[k] = std::max(hi[k], pos_[3 * v + k]);
  auto spread = [](uint32_t x) {  // 10 bits -> every third bit
    x &= 0x3ff;
    x = (x | (x << 16)) & 0x030000ff;
    x = (x | (x << 8)) & 0x0300f00f;
    x = (x | (x << 4)) & 0x030c30c3;
    x = (x | (x << 2)) & 0x09249249;
    return x;
  };
  auto morton = [&](uint32_t v) {
    uint32_t code = 0;
    for (int k = 0; k < 3; ++k) {
      const double ext = hi[k] - lo[k];
      const double u = ext > 0 ? (pos_[3 * v + k] - lo[k]) / ext : 0;
      code |= spread(static_cast<uint32_t>(std::clamp(u, 0.0, 1.0) * 1023)) << k;
    }
    return code;
  };
  std::vector<uint32_t> old_of(n), new_of(n);
  std::iota(old_of.begin(), old_of.end(), 0u);
  std::vector<uint64_t> keys;
  for (size_t pi = 0; pi + 1 < pass_start_.size(); ++pi) {
    const uint32_t s = pass_start_[pi], e = pass_start_[pi + 1];
    keys.clear();
    for (uint32_t v = s; v < e; ++v) keys.push_back(uint64_t(morton(v)) << 32 | v);
    std::sort(keys.begin(), keys.end());
    for (uint32_t k = 0; k < e - s; ++k) old_of[s + k] = static_cast<uint32_t>(keys[k]);
  }
  for (uint32_t v = 0; v < n; ++v) new_of[old_of[v]] = v;
  auto map = [&](uint32_t v) { return v == kNoNode ? kNoNode : new_of[v]; };

  std::vector<double> pos(pos_.size());
  std::vector<float> uv(uv_.size()), uv1(uv1_.size()), color(color_.size()), normal(normal_.size());
  std::vector<Cone> cone(n);
  std::vector<float> radius(n), error(n);
  std::vector<uint32_t> parent(n);
  const uint32_t inner = n - leaf_count_;
  std::vector<uint32_t> children(2 * size_t(inner)), split_faces(2 * size_t(inner)), wings(2 * size_t(inner));
  std::vector<uint32_t> dep_off{0}, deps, inc_off{0}, inc;
  deps.reserve(deps_.size());
  inc.reserve(inc_.size());
  for (uint32_t v = 0; v < n; ++v) {
    const uint32_t o = old_of[v];
    for (int k = 0; k < 3; ++k) pos[3 * v + k] = pos_[3 * o + k];
    if (!uv_.empty()) uv[2 * size_t(v)] = uv_[2 * size_t(o)], uv[2 * size_t(v) + 1] = uv_[2 * size_t(o) + 1];
    if (!uv1_.empty()) std::copy_n(&uv1_[2 * size_t(o)], 2, &uv1[2 * size_t(v)]);
    if (!color_.empty()) std::copy_n(&color_[4 * size_t(o)], 4, &color[4 * size_t(v)]);
    if (!normal_.empty()) std::copy_n(&normal_[3 * size_t(o)], 3, &normal[3 * size_t(v)]);
    cone[v] = cone_[o];
    radius[v] = radius_[o];
    error[v] = error_[o];
    parent[v] = map(parent_[o]);
    if (v < leaf_count_) continue;
    const uint32_t i = v - leaf_count_, oi = o - leaf_count_;
    for (int k = 0; k < 2; ++k) {
      children[2 * i + k] = map(children_[2 * oi + k]);
      split_faces[2 * i + k] = split_faces_[2 * oi + k];
      wings[2 * i + k] = map(wings_[2 * oi + k]);
    }
    for (uint32_t k = dep_off_[oi]; k < dep_off_[oi + 1]; ++k) deps.push_back(map(deps_[k]));
    dep_off.push_back(static_cast<uint32_t>(deps.size()));
    for (uint32_t k = inc_off_[oi]; k < inc_off_[oi + 1]; ++k) inc.push_back(inc_[k]);
    inc_off.push_back(static_cast<uint32_t>(inc.size()));
  }
  for (uint32_t& owner : face_owner_) owner = map(owner);
  pos_.swap(pos);
  uv_.swap(uv);
  uv1_.swap(uv1);
  color_.swap(color);
  normal_.swap(normal);
  cone_.swap(cone);
  radius_.swap(radius);
  error_.swap(error);
  parent_.swap(parent);
  children_.swap(children);
  split_faces_.swap(split_faces);
  wings_.swap(wings);
  dep_off_.swap(dep_off);
  deps_.swap(deps);
  inc_off_.swap(inc_off);
  inc_.swap(inc);
}

// Input vertices whose faces do not form one fan (two cones touching at a vertex) are never
// collapsed. Legal collapses never make new ones, so the input is checked once.
void Builder::mark_split_fans() {
  nonmanifold_.assign(leaf_count_, 0);
  std::vector<std::pair<uint32_t, uint32_t>> around;  // (other corner, local face)
  std::vector<uint32_t> root;
  for (uint32_t v = 0; v < leaf_count_; ++v) {
    const uint32_t count = vf_off_[v + 1] - vf_off_[v];
    if (count < 2) continue;
    around.clear();
    root.resize(count);
    std::iota(root.begin(), root.end(), 0u);
    for (uint32_t k = 0; k < count; ++k) {
      const uint32_t f = vf_[vf_off_[v] + k];
      for (int c = 0; c < 3; ++c)
        if (face_[3 * f + c] != v) around.push_back({face_[3 * f + c], k});
    }
    std::sort(around.begin(), around.end());
    auto find = [&](uint32_t x) {
      while (root[x] != x) x = root[x] = root[root[x]];
      return x;
    };
    for (size_t k = 1; k < around.size(); ++k)
      if (around[k].first == around[k - 1].first) root[find(around[k].second)] = find(around[k - 1].second);
    uint32_t fans = 0;
    for (uint32_t k = 0; k < count; ++k) fans += find(k) == k;
    nonmanifold_[v] = fans > 1;
  }
}

// Cuts the faces into opt_.parts spatial parts and pins the vertices two parts share.
void Builder::pin_part_seams() {
  const uint32_t fc = static_cast<uint32_t>(leaves_.size() / 3);
  if (opt_.parts <= 1 || fc < 2) return;
  std::vector<float> centre(3 * size_t(fc));
  for (uint32_t f = 0; f < fc; ++f)
    for (int k = 0; k < 3; ++k)
      centre[3 * size_t(f) + k] = static_cast<float>(
          (pos_[3 * size_t(leaves_[3 * f]) + k] + pos_[3 * size_t(leaves_[3 * f + 1]) + k] +
           pos_[3 * size_t(leaves_[3 * f + 2]) + k]) / 3);
  std::vector<uint32_t> order(fc);
  std::iota(order.begin(), order.end(), 0u);
  std::vector<uint32_t> part(fc, 0);
  // Recursive median cuts: [lo, hi) of `order` becomes `parts` parts numbered from first_part.
  auto cut = [&](auto&& self, uint32_t lo, uint32_t hi, uint32_t parts, uint32_t first_part) -> void {
    if (parts <= 1 || hi - lo < 2) {
      for (uint32_t k = lo; k < hi; ++k) part[order[k]] = first_part;
      return;
    }
    float bmin[3] = {1e30f, 1e30f, 1e30f}, bmax[3] = {-1e30f, -1e30f, -1e30f};
    for (uint32_t k = lo; k < hi; ++k)
      for (int a = 0; a < 3; ++a) {
        bmin[a] = std::min(bmin[a], centre[3 * size_t(order[k]) + a]);
        bmax[a] = std::max(bmax[a], centre[3 * size_t(order[k]) + a]);
      }
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (bmax[a] - bmin[a] > bmax[axis] - bmin[axis]) axis = a;
    const uint32_t left = parts / 2;
    const uint32_t mid = lo + static_cast<uint32_t>(uint64_t(hi - lo) * left / parts);
    // Ties broken by face id so the cut does not depend on the sort's implementation.
    std::nth_element(order.begin() + lo, order.begin() + mid, order.begin() + hi, [&](uint32_t x, uint32_t y) {
      const float cx = centre[3 * size_t(x) + axis], cy = centre[3 * size_t(y) + axis];
      return cx < cy || (cx == cy && x < y);
    });
    self(self, lo, mid, left, first_part);
    self(self, mid, hi, parts - left, first_part + left);
  };
  cut(cut, 0, fc, opt_.parts, 0);
  std::vector<uint32_t> seen(leaf_count_, kNoNode);
  for (uint32_t f = 0; f < fc; ++f)
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = leaves_[3 * f + k];
      if (seen[v] == kNoNode)
        seen[v] = part[f];
      else if (seen[v] != part[f])
        nonmanifold_[v] = 1;
    }
}

// A parent's normal: its children's interpolated along the collapse and normalised; where they
// cancel out (opposite normals), the parent's normal-cone axis, else a child's non-zero normal.
void Builder::push_parent_normal(uint32_t a, uint32_t b, float t, const Cone& cone) {
  const float* na = &normal_[3 * size_t(a)];
  const float* nb = &normal_[3 * size_t(b)];
  double n[3];
  for (int k = 0; k < 3; ++k) n[k] = (1 - double(t)) * na[k] + double(t) * nb[k];
  double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (!(len > 1e-6)) {
    const bool has_cone = cone.half >= 0 && length(cone.axis) > 0.5;
    const bool a_zero = na[0] == 0 && na[1] == 0 && na[2] == 0;
    const float* child = a_zero ? nb : na;
    n[0] = has_cone ? cone.axis.x : child[0], n[1] = has_cone ? cone.axis.y : child[1];
    n[2] = has_cone ? cone.axis.z : child[2];
    len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  }
  for (int k = 0; k < 3; ++k) normal_.push_back(len > 0 ? static_cast<float>(n[k] / len) : 0.f);
}

// Attribute seams are pinned (the simplest rule that keeps a texture whole; the discrete QEM
// instead moves a seam pair along its seam, which a vertex split cannot express for two
// vertices at once): copies at one position (find_position_copies, the test QEM uses) and
// vertices between faces of two materials never collapse, so every collapse stays inside one
// uv chart and one material, and both sides of a seam keep their shared vertices.
void Builder::pin_attribute_seams(const MeshData& mesh, const std::vector<int32_t>& face_material) {
  std::vector<uint32_t> first(leaf_count_), copies(leaf_count_);
  find_position_copies(first, copies, mesh.positions.data(), leaf_count_);
  for (uint32_t v = 0; v < leaf_count_; ++v)
    if (copies[v] >= 2) nonmanifold_[v] = 1;
  if (face_material.empty()) return;
  std::vector<int64_t> seen(leaf_count_, INT64_MIN);
  for (size_t f = 0; f < face_material.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = leaves_[3 * f + k];
      if (seen[v] == INT64_MIN)
        seen[v] = face_material[f];
      else if (seen[v] != face_material[f])
        nonmanifold_[v] = 1;
    }
}

void Builder::finish(VertexTree& out) {
  const uint32_t n = static_cast<uint32_t>(parent_.size());
  out = VertexTree{};
  out.leaf_count = leaf_count_;
  out.face_count = static_cast<uint32_t>(face_owner_.size());
  out.positions.resize(3 * size_t(n));
  for (size_t i = 0; i < 3 * size_t(n); ++i) out.positions[i] = static_cast<float>(pos_[i]);
  out.uvs = std::move(uv_);
  out.uvs1 = std::move(uv1_);
  out.colors = std::move(color_);
  out.normals = std::move(normal_);
  out.seams_pinned = true;
  out.parent = parent_;
  out.radius = radius_;
  out.error = error_;
  out.cone_axis.resize(3 * size_t(n));
  out.cone_cos.resize(n);
  for (uint32_t v = 0; v < n; ++v) {
    const Cone& c = cone_[v];
    out.cone_axis[3 * v] = static_cast<float>(c.axis.x);
    out.cone_axis[3 * v + 1] = static_cast<float>(c.axis.y);
    out.cone_axis[3 * v + 2] = static_cast<float>(c.axis.z);
    // Half-angles of 90 degrees or more (or unknown) can never be back-facing.
    out.cone_cos[v] = (c.half < 0 || c.half >= 0.5 * M_PI) ? 0.f : static_cast<float>(std::cos(c.half));
  }
  // Depth-first leaf order: sizes bottom-up (children have smaller ids), offsets top-down.
  std::vector<uint32_t> size(n, 0);
  for (uint32_t v = 0; v < leaf_count_; ++v) size[v] = 1;
  const uint32_t inner = n - leaf_count_;
  for (uint32_t i = 0; i < inner; ++i)
    size[leaf_count_ + i] = size[children_[2 * i]] + size[children_[2 * i + 1]];
  out.leaf_lo.assign(n, 0);
  out.leaf_hi.assign(n, 0);
  uint32_t next = 0;
  for (uint32_t v = 0; v < n; ++v)
    if (parent_[v] == kNoNode) out.leaf_lo[v] = next, next += size[v];
  for (uint32_t v = n; v-- > leaf_count_;) {
    const uint32_t i = v - leaf_count_;
    out.leaf_lo[children_[2 * i]] = out.leaf_lo[v];
    out.leaf_lo[children_[2 * i + 1]] = out.leaf_lo[v] + size[children_[2 * i]];
  }
  for (uint32_t v = 0; v < n; ++v) out.leaf_hi[v] = out.leaf_lo[v] + size[v];
  out.leaf_rank.assign(out.leaf_lo.begin(), out.leaf_lo.begin() + leaf_count_);

  out.face_leaves = std::move(leaves_);
  out.face_owner = face_owner_;
  out.children = std::move(children_);
  out.split_faces = std::move(split_faces_);
  out.wings = std::move(wings_);
  out.dep_offsets = std::move(dep_off_);
  out.deps = std::move(deps_);
  out.inc_offsets = std::move(inc_off_);
  out.inc_faces = std::move(inc_);
  pack_vertex_bounds(out);
}

Status Builder::run(VertexTree& out, const MeshData& mesh) {
  const size_t vc = mesh.vertex_count();
  if (mesh.positions.size() % 3 != 0)
    return Status::error(mesh.source + ": positions hold " + std::to_string(mesh.positions.size()) +
                         " floats, not a multiple of 3");
  if (mesh.indices.size() % 3 != 0)
    return Status::error(mesh.source + ": " + std::to_string(mesh.indices.size()) +
                         " indices, not a multiple of 3");
  if (vc >= kNoNode / 2) return Status::error(mesh.source + ": too many vertices for a hierarchy");
  for (size_t i = 0; i < mesh.positions.size(); ++i)
    if (!std::isfinite(mesh.positions[i]))
      return Status::error(mesh.source + ": vertex " + std::to_string(i / 3) + " has a non-finite position");
  if (!mesh.uvs.empty() && mesh.uvs.size() != 2 * vc)
    return Status::error(mesh.source + ": " + std::to_string(mesh.uvs.size()) + " uv values for " +
                         std::to_string(vc) + " vertices (2 each)");
  for (size_t i = 0; i < mesh.uvs.size(); ++i)
    if (!std::isfinite(mesh.uvs[i]) || std::abs(mesh.uvs[i]) > kMaxTreeMagnitude)
      return Status::error(mesh.source + ": vertex " + std::to_string(i / 2) + " has a non-finite or huge uv");
  if (Status st = check_attribute(mesh, mesh.uvs1, 2, "uv1"); !st) return st;
  if (Status st = check_attribute(mesh, mesh.colors, 4, "colour"); !st) return st;
  if (Status st = check_attribute(mesh, mesh.normals, 3, "normal"); !st) return st;
  // Per input triangle its material (-1 = default), from the submesh runs.
  std::vector<int32_t> input_material;
  if (!mesh.submeshes.empty()) {
    input_material.assign(mesh.triangle_count(), -1);
    for (const Submesh& run : mesh.submeshes) {
      if (run.first_triangle > mesh.triangle_count() || run.triangle_count > mesh.triangle_count() - run.first_triangle)
        return Status::error(mesh.source + ": submesh at triangle " + std::to_string(run.first_triangle) + " of " +
                             std::to_string(run.triangle_count) + " triangles runs past the " +
                             std::to_string(mesh.triangle_count()));
      std::fill_n(input_material.begin() + run.first_triangle, run.triangle_count, run.material);
    }
  }
  std::vector<uint32_t> leaves;
  std::vector<int32_t> face_material;
  leaves.reserve(mesh.indices.size());
  for (size_t f = 0; f < mesh.triangle_count(); ++f) {
    const uint32_t* c = &mesh.indices[3 * f];
    for (int k = 0; k < 3; ++k)
      if (c[k] >= vc)
        return Status::error(mesh.source + ": face " + std::to_string(f) + " references vertex " +
                             std::to_string(c[k]) + " of " + std::to_string(vc));
    if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) continue;
    leaves.insert(leaves.end(), c, c + 3);
    if (!input_material.empty()) face_material.push_back(input_material[f]);
  }
  leaf_count_ = static_cast<uint32_t>(vc);
  const size_t fc = leaves.size() / 3;

  pos_.reserve(6 * vc);
  pos_.assign(mesh.positions.begin(), mesh.positions.end());
  if (!mesh.uvs.empty()) {
    uv_.reserve(4 * vc);
    uv_.assign(mesh.uvs.begin(), mesh.uvs.end());
  }
  if (!mesh.uvs1.empty()) uv1_.reserve(4 * vc), uv1_.assign(mesh.uvs1.begin(), mesh.uvs1.end());
  if (!mesh.colors.empty()) color_.reserve(8 * vc), color_.assign(mesh.colors.begin(), mesh.colors.end());
  if (!mesh.normals.empty()) {
    normal_.reserve(6 * vc);
    normal_.assign(mesh.normals.begin(), mesh.normals.end());
    for (size_t v = 0; v < vc; ++v) unit_or_zero(&normal_[3 * v]);
  }
  parent_.reserve(2 * vc);
  parent_.assign(vc, kNoNode);
  quad_.reserve(2 * vc);
  quad_.assign(vc, Quad{});
  cone_.reserve(2 * vc);
  cone_.assign(vc, Cone{});
  radius_.reserve(2 * vc);
  radius_.assign(vc, 0.f);
  error_.reserve(2 * vc);
  error_.assign(vc, 0.f);
  face_ = leaves;
  leaves_ = std::move(leaves);
  face_alive_.assign(fc, 1);
  face_owner_.assign(fc, kNoNode);

  // Leaf quadrics (area-weighted planes) and normal cones (area-weighted axis, widest normal).
  std::vector<Vec> normal_sum(vc);
  std::vector<Vec> face_n(fc);
  for (size_t f = 0; f < fc; ++f) {
    const Vec p0 = pos(face_[3 * f]), p1 = pos(face_[3 * f + 1]), p2 = pos(face_[3 * f + 2]);
    const Vec n = cross(sub(p1, p0), sub(p2, p0));
    const double len = length(n);
    if (!(len > 0)) continue;
    const Vec u{n.x / len, n.y / len, n.z / len};
    face_n[f] = u;
    const double area = 0.5 * len;
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = face_[3 * f + k];
      quad_[v].add_plane(u.x, u.y, u.z, -dot(u, p0), area);
      normal_sum[v].x += n.x, normal_sum[v].y += n.y, normal_sum[v].z += n.z;
    }
  }
  for (size_t v = 0; v < vc; ++v) {
    const double len = length(normal_sum[v]);
    if (len > 0) cone_[v] = {{normal_sum[v].x / len, normal_sum[v].y / len, normal_sum[v].z / len}, 0};
  }
  for (size_t f = 0; f < fc; ++f) {
    if (length(face_n[f]) == 0) continue;
    for (int k = 0; k < 3; ++k) {
      Cone& c = cone_[face_[3 * f + k]];
      if (c.half < 0) continue;
      c.half = std::max(c.half, std::acos(std::clamp(dot(c.axis, face_n[f]), -1.0, 1.0)));
    }
  }

  build_adjacency();
  mark_split_fans();
  pin_part_seams();
  pin_attribute_seams(mesh, face_material);
  collect_edges();
  // Border constraint planes (through the border edge, perpendicular to its face) hold the
  // outline of open meshes in place.
  if (opt_.order == CollapseOrder::quadric) {
    for (uint32_t f = 0; f < fc; ++f) {
      if (length(face_n[f]) == 0) continue;
      for (int k = 0; k < 3; ++k) {
        const uint32_t u = face_[3 * f + k], v = face_[3 * f + (k + 1) % 3];
        if (!border_[u] || !border_[v]) continue;
        // Border edge when no other face has it.
        bool shared = false;
        for (uint32_t j = vf_off_[u]; j < vf_off_[u + 1] && !shared; ++j) {
          const uint32_t g = vf_[j];
          if (g == f) continue;
          const uint32_t* c = &face_[3 * g];
          shared = c[0] == v || c[1] == v || c[2] == v;
        }
        if (shared) continue;
        const Vec e = sub(pos(v), pos(u));
        const Vec n = cross(e, face_n[f]);
        const double len = length(n);
        if (!(len > 0)) continue;
        const Vec m{n.x / len, n.y / len, n.z / len};
        const double weight = opt_.border_weight * dot(e, e);
        quad_[u].add_plane(m.x, m.y, m.z, -dot(m, pos(u)), weight);
        quad_[v].add_plane(m.x, m.y, m.z, -dot(m, pos(u)), weight);
      }
    }
    collect_edges();  // costs with the border planes
  }

  for (;;) {
    pass_start_.push_back(static_cast<uint32_t>(parent_.size()));
    size_t collapsed = 0;
    for (const Edge& e : edges_) {
      if (locked_[e.a] || locked_[e.b]) continue;
      if (try_collapse(e.a, e.b)) ++collapsed;
    }
    if (collapsed == 0) break;
    build_adjacency();
    collect_edges();
  }
  pass_start_.push_back(static_cast<uint32_t>(parent_.size()));
  renumber_passes();
  finish(out);
  return Status::success();
}

}  // namespace

Status build_vertex_hierarchy(VertexTree& out, const MeshData& mesh, const HierarchyOptions& options) {
  VertexTree tree;
  Builder builder(options);
  Status s = builder.run(tree, mesh);
  if (!s) return s;
  out = std::move(tree);
  return s;
}

}  // namespace lod
