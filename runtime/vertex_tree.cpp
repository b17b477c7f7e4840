// VertexTree structural checks: what an asset reader must confirm before the front update
// (which only asserts) may walk the arrays.
#include "runtime/vertex_tree.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace lod {

namespace {

bool fail(std::string* message, std::string text) {
  if (message) *message = std::move(text);
  return false;
}

std::string num(uint64_t v) { return std::to_string(v); }

bool check_csr(const std::vector<uint32_t>& offsets, size_t rows, size_t values, const char* what,
               std::string* message) {
  if (offsets.size() != rows + 1)
    return fail(message, std::string(what) + " offsets hold " + num(offsets.size()) + " entries, expected " +
                             num(rows + 1));
  if (offsets[0] != 0) return fail(message, std::string(what) + " offsets do not start at 0");
  for (size_t i = 0; i < rows; ++i)
    if (offsets[i + 1] < offsets[i] || offsets[i + 1] > values)
      return fail(message, std::string(what) + " offsets of interior node " + num(i) + " are out of order");
  if (offsets[rows] != values)
    return fail(message,
                std::string(what) + " offsets end at " + num(offsets[rows]) + " but hold " + num(values));
  return true;
}

// Replays the build's collapses in node order (a valid order by construction: children and
// dependencies come first) and checks that every node's arrays are what that collapse makes:
// its split faces are the faces on its edge, with one corner under each child and the third
// at the wing; its incident faces are exactly the faces alive after the collapse with a corner
// below it (each with exactly one such corner: front_update rewrites that corner alone); its
// dependencies are exactly its neighbours then (the corners of those faces and the wings). So
// every dependency is active when the node is made and its parent comes later, which bounds
// force_split's climb (each forced split goes to a later node), and the split and collapse of
// a front touch exactly the faces they must. Base faces keep three distinct roots. Union-find
// over the collapses: linear in the arrays.
bool check_collapse_order(const VertexTree& t, std::string* message) {
  const uint32_t n = t.node_count(), leaves = t.leaf_count;
  std::vector<uint32_t> rep(n);
  for (uint32_t v = 0; v < n; ++v) rep[v] = v;
  auto find = [&](uint32_t v) {
    while (rep[v] != v) v = rep[v] = rep[rep[v]];
    return v;
  };
  // Per active node: faces alive with a corner below it.
  std::vector<uint32_t> alive(n, 0);
  for (uint32_t l : t.face_leaves) ++alive[l];
  std::vector<uint32_t> face_mark(t.face_count, kNoNode), near(n, kNoNode), dep_mark(n, kNoNode);
  for (uint32_t v = leaves; v < n; ++v) {
    const size_t i = v - leaves;
    const uint32_t c1 = t.children[2 * i], c2 = t.children[2 * i + 1];
    uint32_t made = 0;
    for (int k = 0; k < 2; ++k) {
      const uint32_t f = t.split_faces[2 * i + k];
      if (f == kNoNode) continue;
      ++made;
      const uint32_t w = t.wings[2 * i + k];
      uint32_t at_c1 = 0, at_c2 = 0, at_w = 0;
      for (int j = 0; j < 3; ++j) {
        const uint32_t r = find(t.face_leaves[3 * size_t(f) + j]);
        at_c1 += r == c1, at_c2 += r == c2, at_w += r == w;
      }
      if (at_c1 != 1 || at_c2 != 1 || at_w != 1)
        return fail(message, "node " + num(v) + " split face " + num(f) + " does not join its children " +
                                 num(c1) + ", " + num(c2) + " and its wing " + num(w));
      --alive[w];
    }
    rep[c1] = rep[c2] = v;
    const uint64_t expect = uint64_t(alive[c1]) + alive[c2] - 2 * made;
    const uint32_t lo = t.inc_offsets[i], hi = t.inc_offsets[i + 1];
    if (hi - lo != expect)
      return fail(message, "node " + num(v) + " lists " + num(hi - lo) + " incident faces but has " + num(expect));
    alive[v] = static_cast<uint32_t>(expect);
    uint32_t neighbours = 0;
    auto meet = [&](uint32_t u) {
      if (near[u] != v) near[u] = v, ++neighbours;
    };
    for (uint32_t k = lo; k < hi; ++k) {
      const uint32_t f = t.inc_faces[k];
      if (face_mark[f] == v) return fail(message, "node " + num(v) + " lists incident face " + num(f) + " twice");
      face_mark[f] = v;
      if (t.face_owner[f] != kNoNode && t.face_owner[f] <= v)
        return fail(message, "node " + num(v) + " incident face " + num(f) + " is gone by then (made by node " +
                                 num(t.face_owner[f]) + ")");
      uint32_t below = 0;
      for (int j = 0; j < 3; ++j) {
        const uint32_t r = find(t.face_leaves[3 * size_t(f) + j]);
        if (r == v)
          ++below;
        else
          meet(r);
      }
      if (below != 1)
        return fail(message, "node " + num(v) + " incident face " + num(f) + " has " + num(below) +
                                 " corners below it, not 1");
    }
    for (int k = 0; k < 2; ++k)
      if (t.wings[2 * i + k] != kNoNode) meet(t.wings[2 * i + k]);
    const uint32_t dlo = t.dep_offsets[i], dhi = t.dep_offsets[i + 1];
    for (uint32_t k = dlo; k < dhi; ++k) {
      const uint32_t d = t.deps[k];
      if (d >= n || near[d] != v)
        return fail(message, "node " + num(v) + " dependency " + num(d) + " is not one of its neighbours");
      if (dep_mark[d] == v) return fail(message, "node " + num(v) + " lists dependency " + num(d) + " twice");
      dep_mark[d] = v;
    }
    if (dhi - dlo != neighbours)
      return fail(message, "node " + num(v) + " lists " + num(dhi - dlo) + " dependencies but has " +
                               num(neighbours) + " neighbours");
  }
  for (uint32_t f = 0; f < t.face_count; ++f) {
    if (t.face_owner[f] != kNoNode) continue;
    const uint32_t a = find(t.face_leaves[3 * size_t(f)]), b = find(t.face_leaves[3 * size_t(f) + 1]),
                   c = find(t.face_leaves[3 * size_t(f) + 2]);
    if (a == b || b == c || a == c)
      return fail(message, "base face " + num(f) + " has two corners under one root");
  }
  return true;
}

}  // namespace

namespace {

// One optional column of `width` values per node: finite, and (boxed) a parent's inside its
// children's box, what interpolating along the collapse and clamping gives.
bool check_node_column(const VertexTree& t, const std::vector<float>& values, size_t width, const char* what,
                       bool boxed, std::string* message) {
  const size_t n = t.parent.size();
  if (values.size() != width * n)
    return fail(message, std::string("hierarchy ") + what + "s hold " + num(values.size()) +
                             " values, expected " + num(width * n));
  for (size_t i = 0; i < width * n; ++i)
    if (!std::isfinite(values[i]) || std::abs(values[i]) > kMaxTreeMagnitude)
      return fail(message, "node " + num(i / width) + " has a non-finite or huge " + what);
  if (n < t.leaf_count || t.children.size() != 2 * (n - t.leaf_count))
    return fail(message, "hierarchy children do not match its nodes");
  for (size_t i = 0; i < n - t.leaf_count; ++i) {
    const uint32_t a = t.children[2 * i], b = t.children[2 * i + 1];
    if (a >= n || b >= n) return fail(message, "node " + num(t.leaf_count + i) + " has a child out of range");
    if (!boxed) continue;
    for (size_t k = 0; k < width; ++k) {
      const float u = values[width * (t.leaf_count + i) + k], ua = values[width * a + k],
                  ub = values[width * b + k];
      if (u < std::min(ua, ub) || u > std::max(ua, ub))
        return fail(message, "node " + num(t.leaf_count + i) + " " + what + " lies outside its children's (" +
                                 num(a) + ", " + num(b) + ")");
    }
  }
  return true;
}

}  // namespace

// Uvs: one pair per node, finite, and a parent's inside its children's box (what interpolating
// along the collapse gives): so no node's texture coordinate leaves the range of its leaves'.
bool validate_vertex_tree_uvs(const VertexTree& t, std::string* message) {
  return check_node_column(t, t.uvs, 2, "uv", true, message);
}

bool validate_vertex_tree_attributes(const VertexTree& t, std::string* message) {
  if (!t.uvs.empty() && !validate_vertex_tree_uvs(t, message)) return false;
  if (!t.uvs1.empty() && !check_node_column(t, t.uvs1, 2, "uv1", true, message)) return false;
  if (!t.colors.empty() && !check_node_column(t, t.colors, 4, "colour", true, message)) return false;
  if (t.normals.empty()) return true;
  if (!check_node_column(t, t.normals, 3, "normal", false, message)) return false;
  for (size_t v = 0; v < t.parent.size(); ++v) {
    const float* q = &t.normals[3 * v];
    const double len = std::sqrt(double(q[0]) * q[0] + double(q[1]) * q[1] + double(q[2]) * q[2]);
    if (len != 0 && std::abs(len - 1) > kTreeNormalTolerance)
      return fail(message, "node " + num(v) + " normal has length " + std::to_string(len) + ", not 1 or 0");
  }
  return true;
}

bool validate_vertex_tree(const VertexTree& t, std::string* message) {
  const size_t n = t.parent.size();
  if (n < t.leaf_count) return fail(message, "hierarchy has fewer nodes than leaves");
  if (n >= kNoNode) return fail(message, "hierarchy has too many nodes");
  const size_t inner = n - t.leaf_count;
  auto sized = [&](const auto& v, size_t want, const char* what) {
    if (v.size() == want) return true;
    return fail(message, std::string("hierarchy ") + what + " holds " + num(v.size()) + " values, expected " +
                             num(want));
  };
  if (!sized(t.positions, 3 * n, "positions") || !sized(t.radius, n, "radius") ||
      !sized(t.cone_axis, 3 * n, "cone axes") || !sized(t.cone_cos, n, "cone angles") ||
      !sized(t.error, n, "errors") || !sized(t.leaf_lo, n, "leaf ranges") ||
      !sized(t.leaf_hi, n, "leaf ranges") || !sized(t.leaf_rank, t.leaf_count, "leaf ranks") ||
      !sized(t.face_leaves, 3 * size_t(t.face_count), "faces") ||
      !sized(t.face_owner, t.face_count, "face owners") || !sized(t.children, 2 * inner, "children") ||
      !sized(t.split_faces, 2 * inner, "split faces") || !sized(t.wings, 2 * inner, "wings"))
    return false;
  if (!check_csr(t.dep_offsets, inner, t.deps.size(), "dependency", message)) return false;
  if (!check_csr(t.inc_offsets, inner, t.inc_faces.size(), "incidence", message)) return false;

  // Finite and far from float's limits: the front squares and sums these (its extent, reach
  // and bucket indices must stay finite).
  auto sane = [](float x) { return std::isfinite(x) && std::abs(x) <= kMaxTreeMagnitude; };
  for (size_t i = 0; i < 3 * n; ++i)
    if (!sane(t.positions[i]) || !std::isfinite(t.cone_axis[i]))
      return fail(message, "node " + num(i / 3) + " has a non-finite or huge position, or a non-finite cone");
  for (size_t v = 0; v < n; ++v) {
    if (!sane(t.radius[v]) || !(t.radius[v] >= 0) || !sane(t.error[v]) || !(t.error[v] >= 0) ||
        !std::isfinite(t.cone_cos[v]))
      return fail(message, "node " + num(v) + " has a bad radius, error or cone angle");
    const uint32_t p = t.parent[v];
    if (p != kNoNode && (p >= n || p <= v || p < t.leaf_count))
      return fail(message, "node " + num(v) + " has parent " + num(p) + " of " + num(n));
    if (p != kNoNode && t.children[2 * size_t(p - t.leaf_count)] != v &&
        t.children[2 * size_t(p - t.leaf_count) + 1] != v)
      return fail(message, "node " + num(v) + " has parent " + num(p) + " which does not list it as a child");
    if (t.leaf_lo[v] > t.leaf_hi[v] || t.leaf_hi[v] > t.leaf_count)
      return fail(message, "node " + num(v) + " has leaf range [" + num(t.leaf_lo[v]) + ", " +
                               num(t.leaf_hi[v]) + ")");
  }
  std::vector<uint8_t> rank_seen(t.leaf_count, 0);
  for (uint32_t l = 0; l < t.leaf_count; ++l) {
    if (t.leaf_rank[l] >= t.leaf_count) return fail(message, "leaf " + num(l) + " has rank out of range");
    if (rank_seen[t.leaf_rank[l]]++)
      return fail(message, "leaf " + num(l) + " has rank " + num(t.leaf_rank[l]) + " of another leaf");
    if (t.leaf_lo[l] != t.leaf_rank[l] || t.leaf_hi[l] != t.leaf_rank[l] + 1)
      return fail(message, "leaf " + num(l) + " range does not match its rank");
  }
  for (size_t i = 0; i < inner; ++i) {
    const uint32_t v = static_cast<uint32_t>(t.leaf_count + i);
    for (int k = 0; k < 2; ++k) {
      const uint32_t c = t.children[2 * i + k];
      if (c >= v || t.parent[c] != v)
        return fail(message,
                    "node " + num(v) + " child " + num(c) + " of " + num(n) + " does not name it as parent");
      const uint32_t f = t.split_faces[2 * i + k];
      if (f != kNoNode && (f >= t.face_count || t.face_owner[f] != v))
        return fail(message, "node " + num(v) + " split face " + num(f) + " of " + num(t.face_count) +
                                 " is not owned by it");
      const uint32_t w = t.wings[2 * i + k];
      if ((f == kNoNode) != (w == kNoNode) || (w != kNoNode && w >= v))
        return fail(message, "node " + num(v) + " wing " + num(w) + " of " + num(n) + " is out of range");
    }
    if (t.split_faces[2 * i] == kNoNode) return fail(message, "node " + num(v) + " creates no face");
    if (t.split_faces[2 * i] == t.split_faces[2 * i + 1])
      return fail(message, "node " + num(v) + " creates face " + num(t.split_faces[2 * i]) + " twice");
    const uint32_t a = t.children[2 * i], b = t.children[2 * i + 1];
    if (t.leaf_lo[v] != std::min(t.leaf_lo[a], t.leaf_lo[b]) ||
        t.leaf_hi[v] != std::max(t.leaf_hi[a], t.leaf_hi[b]) ||
        t.leaf_hi[v] - t.leaf_lo[v] != (t.leaf_hi[a] - t.leaf_lo[a]) + (t.leaf_hi[b] - t.leaf_lo[b]))
      return fail(message, "node " + num(v) + " leaf range is not its children's");
    for (uint32_t k = t.dep_offsets[i]; k < t.dep_offsets[i + 1]; ++k)
      if (t.deps[k] >= v)
        return fail(message, "node " + num(v) + " depends on node " + num(t.deps[k]) + " made after it");
    for (uint32_t k = t.inc_offsets[i]; k < t.inc_offsets[i + 1]; ++k)
      if (t.inc_faces[k] >= t.face_count)
        return fail(message,
                    "node " + num(v) + " incident face " + num(t.inc_faces[k]) + " of " + num(t.face_count));
  }
  for (size_t f = 0; f < t.face_count; ++f) {
    for (int k = 0; k < 3; ++k)
      if (t.face_leaves[3 * f + k] >= t.leaf_count)
        return fail(message, "face " + num(f) + " references vertex " + num(t.face_leaves[3 * f + k]) +
                                 " of " + num(t.leaf_count));
    const uint32_t* l = &t.face_leaves[3 * f];
    if (l[0] == l[1] || l[1] == l[2] || l[0] == l[2])
      return fail(message, "face " + num(f) + " repeats a vertex (" + num(l[0]) + ", " + num(l[1]) + ", " +
                               num(l[2]) + ")");
    const uint32_t o = t.face_owner[f];
    if (o != kNoNode && (o < t.leaf_count || o >= n))
      return fail(message, "face " + num(f) + " owner " + num(o) + " is not an interior node");
    if (o != kNoNode) {
      const size_t i = o - t.leaf_count;
      if (t.split_faces[2 * i] != f && t.split_faces[2 * i + 1] != f)
        return fail(message, "face " + num(f) + " owner " + num(o) + " does not list it");
    }
  }
  if (!validate_vertex_tree_attributes(t, message)) return false;
  return check_collapse_order(t, message);
}

void pack_vertex_bounds(VertexTree& t) {
  const uint32_t n = t.node_count();
  t.bounds.resize(n);
  for (uint32_t v = 0; v < n; ++v) {
    VertexBounds& b = t.bounds[v];
    b.x = t.positions[3 * size_t(v)];
    b.y = t.positions[3 * size_t(v) + 1];
    b.z = t.positions[3 * size_t(v) + 2];
    b.radius = t.radius[v];
    b.error = t.error[v];
    for (int k = 0; k < 3; ++k)
      b.axis[k] =
          static_cast<int16_t>(std::lround(std::clamp(t.cone_axis[3 * size_t(v) + k], -1.f, 1.f) * 32767));
    // Rounded down, less a little for the axis rounding: the packed cone holds the real one.
    const float c = std::clamp(t.cone_cos[v], -1.f, 1.f) - 2e-4f;
    b.cone_cos = static_cast<int16_t>(std::floor(std::max(c, -1.f) * 32767));
    b.parent = t.parent[v];
  }
  t.face_ranks.resize(t.face_leaves.size());
  for (size_t k = 0; k < t.face_leaves.size(); ++k) t.face_ranks[k] = t.leaf_rank[t.face_leaves[k]];
  t.inc_corner.assign(t.inc_faces.size(), 0);
  for (uint32_t i = 0; i < t.interior_count(); ++i) {
    const uint32_t v = t.leaf_count + i;
    for (uint32_t k = t.inc_offsets[i]; k < t.inc_offsets[i + 1]; ++k) {
      const uint32_t f = t.inc_faces[k];
      for (uint32_t j = 0; j < 3; ++j) {
        const uint32_t r = t.face_ranks[3 * size_t(f) + j];
        if (r >= t.leaf_lo[v] && r < t.leaf_hi[v]) {
          t.inc_corner[k] = r * 4 + j;
          break;
        }
      }
    }
  }
}

uint32_t vertex_tree_regions(std::vector<uint8_t>& region, const VertexTree& t, uint32_t max_regions) {
  const uint32_t n = t.node_count();
  max_regions = std::clamp(max_regions, 1u, 254u);
  region.assign(n, 0);
  std::vector<uint32_t> root(n);
  for (uint32_t v = 0; v < n; ++v) root[v] = v;
  auto find = [&](uint32_t x) {
    while (root[x] != x) x = root[x] = root[root[x]];
    return x;
  };
  auto fixed = [&](uint32_t v) { return t.is_leaf(v) && t.parent[v] == kNoNode; };
  auto join = [&](uint32_t a, uint32_t b) {
    a = find(a), b = find(b);
    if (a != b) root[std::max(a, b)] = std::min(a, b);  // smallest id represents: deterministic
  };
  for (uint32_t i = 0; i < t.interior_count(); ++i) {
    const uint32_t x = t.leaf_count + i;
    join(x, t.children[2 * i]);
    join(x, t.children[2 * i + 1]);
    for (uint32_t k = t.dep_offsets[i]; k < t.dep_offsets[i + 1]; ++k)
      if (!fixed(t.deps[k])) join(x, t.deps[k]);
  }
  for (uint32_t f = 0; f < t.face_count; ++f) {
    uint32_t first = kNoNode;
    for (int j = 0; j < 3; ++j) {
      const uint32_t l = t.face_leaves[3 * size_t(f) + j];
      if (fixed(l)) continue;
      if (first == kNoNode)
        first = l;
      else
        join(first, l);
    }
  }
  // Components by leaf count, largest first (ties: smaller representative first).
  std::vector<uint32_t> leaves(n, 0);
  for (uint32_t l = 0; l < t.leaf_count; ++l)
    if (!fixed(l)) ++leaves[find(l)];
  std::vector<uint32_t> comps;
  for (uint32_t v = 0; v < n; ++v)
    if (!fixed(v) && find(v) == v) comps.push_back(v);
  std::stable_sort(comps.begin(), comps.end(), [&](uint32_t a, uint32_t b) { return leaves[a] > leaves[b]; });
  const uint32_t used = std::max<uint32_t>(1, std::min<uint32_t>(max_regions, static_cast<uint32_t>(comps.size())));
  std::vector<uint64_t> load(used, 0);
  std::vector<uint8_t> of_comp(n, 0);
  for (uint32_t c : comps) {
    const auto least = std::min_element(load.begin(), load.end()) - load.begin();
    of_comp[c] = static_cast<uint8_t>(least);
    load[least] += std::max<uint32_t>(leaves[c], 1);
  }
  for (uint32_t v = 0; v < n; ++v) region[v] = fixed(v) ? kSharedRegion : of_comp[find(v)];
  return used;
}

uint8_t face_region(const VertexTree& t, std::span<const uint8_t> region, uint32_t face) {
  for (int j = 0; j < 3; ++j) {
    const uint8_t r = region[t.face_leaves[3 * size_t(face) + j]];
    if (r != kSharedRegion) return r;
  }
  return 0;
}

RegionNumbering number_regions(const VertexTree& t, std::vector<uint8_t> region, uint32_t count) {
  RegionNumbering out;
  const uint32_t n = t.node_count();
  out.local.assign(n, 0);
  out.leaves.assign(count, 0);
  out.nodes.assign(count, 0);
  out.faces.assign(count, 0);
  for (uint32_t v = 0; v < t.leaf_count; ++v)
    if (region[v] == kSharedRegion) out.local[v] = out.shared++;
  std::fill(out.nodes.begin(), out.nodes.end(), out.shared);
  auto number = [&](uint32_t begin, uint32_t end) {
    for (uint32_t v = begin; v < end; ++v)
      if (region[v] < count) out.local[v] = out.nodes[region[v]]++;
  };
  number(0, t.leaf_count);  // leaves first, so a region's leaves precede its interior nodes
  out.leaves = out.nodes;
  number(t.leaf_count, n);
  out.local_face.assign(t.face_count, 0);
  for (uint32_t f = 0; f < t.face_count; ++f) {
    const uint8_t r = face_region(t, region, f);
    if (r < count) out.local_face[f] = out.faces[r]++;
  }
  out.region = std::move(region);
  return out;
}

}  // namespace lod
