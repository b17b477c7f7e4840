#include "runtime/roam.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>

namespace lod {
namespace detail {

struct Cell {
  int32_t x, y;
};

// Where a diamond's corners lie: base ends p, q and apices a[0], a[1] (apices may lie outside
// the grid for border diamonds). Square diamonds (both coordinates odd multiples of t) have a
// diagonal base; the base ends are the corners that are coarser square centres or grid corners,
// the apices the coarser edge-diamond centres. Edge diamonds (one coordinate an odd multiple of
// s) have their base along that coordinate.
struct DiamondShape {
  Cell p, q, a[2];
};

inline int32_t lowbit(int32_t v) { return v & -v; }

DiamondShape diamond_shape(int32_t x, int32_t y) {
  const int32_t t = lowbit(x | y);
  const bool x_odd = (x / t) & 1, y_odd = (y / t) & 1;
  DiamondShape s{};
  if (x_odd && y_odd) {
    const Cell corners[4] = {{x - t, y - t}, {x + t, y - t}, {x + t, y + t}, {x - t, y + t}};
    int np = 0, na = 0;
    for (const Cell& c : corners) {
      const bool one_odd = (((c.x / (2 * t)) & 1) ^ ((c.y / (2 * t)) & 1)) != 0;
      if (one_odd)
        s.a[na++] = c;
      else
        (np++ == 0 ? s.p : s.q) = c;
    }
    assert(np == 2 && na == 2);
  } else if (x_odd) {
    s.p = {x - t, y}, s.q = {x + t, y}, s.a[0] = {x, y - t}, s.a[1] = {x, y + t};
  } else {
    s.p = {x, y - t}, s.q = {x, y + t}, s.a[0] = {x - t, y}, s.a[1] = {x + t, y};
  }
  return s;
}

struct Grid {
  int32_t size, max;
  bool inside(Cell c) const { return c.x >= 0 && c.y >= 0 && c.x <= max && c.y <= max; }
  bool corner(Cell c) const { return (c.x == 0 || c.x == max) && (c.y == 0 || c.y == max); }
  int32_t id(Cell c) const { return c.y * size + c.x; }
  // A diamond centre: inside, not a grid corner.
  int32_t diamond(Cell c) const { return inside(c) && !corner(c) ? id(c) : -1; }
};

// Depth in the bintree of diamonds: root 0, finest edge diamonds 2n - 1.
int depth_of(int32_t x, int32_t y, uint32_t levels) {
  const int32_t t = lowbit(x | y);
  const int k = std::countr_zero(uint32_t(t));
  const bool square = ((x / t) & 1) && ((y / t) & 1);
  return 2 * (int(levels) - 1 - k) + (square ? 0 : 1);
}

void build_links(RoamTerrain& T, const Grid& g) {
  for (int32_t y = 0; y <= g.max; ++y)
    for (int32_t x = 0; x <= g.max; ++x) {
      const int32_t d = g.id({x, y});
      T.parents[d] = {-1, -1};
      T.children[d] = {-1, -1, -1, -1};
      if (g.corner({x, y})) continue;
      const DiamondShape s = diamond_shape(x, y);
      const bool finest = lowbit(x | y) == 1 && !((x & 1) && (y & 1));
      for (int i = 0; i < 2; ++i) {
        if (!g.inside(s.a[i])) continue;
        ++T.triangles[d];
        T.parents[d][i] = g.diamond(s.a[i]);
        if (finest) continue;
        // The two child triangles on this apex's side have bases (p, a) and (a, q).
        T.children[d][2 * i] = g.id({(s.p.x + s.a[i].x) / 2, (s.p.y + s.a[i].y) / 2});
        T.children[d][2 * i + 1] = g.id({(s.q.x + s.a[i].x) / 2, (s.q.y + s.a[i].y) / 2});
      }
    }
}

// Bottom-up (finest depth first): own base error and corner reach, then the children's nested
// bounds, so a parent's wedgie and sphere contain every descendant's.
void build_bounds(RoamTerrain& T, const Grid& g) {
  std::vector<std::vector<int32_t>> by_depth(2 * T.levels);
  for (int32_t y = 0; y <= g.max; ++y)
    for (int32_t x = 0; x <= g.max; ++x)
      if (g.diamond({x, y}) >= 0) by_depth[depth_of(x, y, T.levels)].push_back(g.id({x, y}));
  for (size_t level = by_depth.size(); level-- > 0;)
    for (int32_t d : by_depth[level]) {
      const DiamondShape s = diamond_shape(d % g.size, d / g.size);
      const glm::vec3 c = T.positions[d];
      const glm::vec3 p = T.positions[g.id(s.p)], q = T.positions[g.id(s.q)];
      float e = std::abs(c.y - 0.5f * (p.y + q.y));
      float reach = std::max(glm::length(p - c), glm::length(q - c));
      for (const Cell& a : s.a)
        if (g.inside(a)) reach = std::max(reach, glm::length(T.positions[g.id(a)] - c));
      // The surface lies within the own error of the own triangles, vertically; the
      // children's spheres already hold their own slack.
      float r = reach + std::abs(c.y - 0.5f * (p.y + q.y));
      for (int32_t k : T.children[d])
        if (k >= 0) {
          e = std::max(e, T.error[k]);
          r = std::max(r, glm::length(T.positions[k] - c) + T.radius[k]);
        }
      T.error[d] = e;
      T.radius[d] = r;
    }
}

// ---- the two indexed heaps ----

inline bool ahead(const RoamQueue& q, const std::vector<float>& pr, int32_t a, int32_t b) {
  const float ka = q.sign * pr[a], kb = q.sign * pr[b];
  return ka > kb || (ka == kb && a < b);
}

void place(RoamQueue& q, size_t i, int32_t d) {
  q.heap[i] = d;
  q.slot[d] = int32_t(i);
}

void sift_up(RoamQueue& q, const std::vector<float>& pr, size_t i) {
  const int32_t d = q.heap[i];
  while (i > 0) {
    const size_t up = (i - 1) / 2;
    if (!ahead(q, pr, d, q.heap[up])) break;
    place(q, i, q.heap[up]);
    i = up;
  }
  place(q, i, d);
}

void sift_down(RoamQueue& q, const std::vector<float>& pr, size_t i) {
  const size_t n = q.heap.size();
  const int32_t d = q.heap[i];
  for (;;) {
    size_t best = 2 * i + 1;
    if (best >= n) break;
    if (best + 1 < n && ahead(q, pr, q.heap[best + 1], q.heap[best])) ++best;
    if (!ahead(q, pr, q.heap[best], d)) break;
    place(q, i, q.heap[best]);
    i = best;
  }
  place(q, i, d);
}

void queue_insert(RoamQueue& q, const std::vector<float>& pr, int32_t d) {
  if (q.slot[d] >= 0) return;
  assert(q.heap.size() < q.heap.capacity());  // reserved for every diamond: never reallocates
  q.heap.push_back(d);
  sift_up(q, pr, q.heap.size() - 1);
}

void queue_remove(RoamQueue& q, const std::vector<float>& pr, int32_t d) {
  const int32_t i = q.slot[d];
  if (i < 0) return;
  q.slot[d] = -1;
  const int32_t last = q.heap.back();
  q.heap.pop_back();
  if (last == d) return;
  place(q, size_t(i), last);
  sift_up(q, pr, size_t(i));
  sift_down(q, pr, size_t(q.slot[last]));
}

void heapify(RoamQueue& q, const std::vector<float>& pr) {
  for (size_t i = q.heap.size() / 2; i-- > 0;) sift_down(q, pr, i);
}

void reset_queue(RoamQueue& q, size_t diamonds, float sign) {
  q.sign = sign;
  q.heap.clear();
  q.heap.reserve(diamonds);
  q.slot.assign(diamonds, -1);
}

// ---- split / merge bookkeeping ----

bool parents_split(const RoamState& S, const RoamTerrain& T, int32_t d) {
  for (int32_t p : T.parents[d])
    if (p >= 0 && !S.split[p]) return false;
  return true;
}

bool any_child_split(const RoamState& S, const RoamTerrain& T, int32_t d) {
  for (int32_t c : T.children[d])
    if (c >= 0 && S.split[c]) return true;
  return false;
}

void queue_rekey(RoamQueue& q, const std::vector<float>& keys, int32_t d) {
  sift_up(q, keys, size_t(q.slot[d]));
  sift_down(q, keys, size_t(q.slot[d]));
}

// How far the eye may move (without turning) before d's decision against tau can change: the
// distance to its sphere and each plane's margin change by at most the eye's travel. A rounding
// allowance keeps the bound safe for recomputed frustum normals.
float slack_of(const RoamState& S, const RoamTerrain& T, int32_t d) {
  if (T.error[d] * S.focal <= 0) return 3e38f;  // never above tau
  const glm::vec3 c = T.positions[d];
  const float r = T.radius[d];
  float plane_margin = 3e38f;
  bool culled = false;
  for (const glm::vec4& pl : S.frustum.planes) {
    const float m = glm::dot(glm::vec3(pl), c) + pl.w + r;
    plane_margin = std::min(plane_margin, std::abs(m));
    culled |= m < 0;
  }
  const float dist = glm::length(S.eye - c);
  float slack = plane_margin;
  if (!culled) {
    const float gap = std::max(dist - r, S.near_plane) - T.error[d] * S.focal / S.tau;
    slack = std::min(slack, std::abs(gap));
  }
  return slack - 1e-4f * (1 + dist + r);
}

void track(RoamState& S, const RoamTerrain& T, int32_t d) {
  S.deadline[d] = S.travel + std::max(slack_of(S, T, d), 0.f);
  if (S.deadline_queue.slot[d] >= 0)
    queue_rekey(S.deadline_queue, S.deadline, d);
  else
    queue_insert(S.deadline_queue, S.deadline, d);
}

void enqueue(RoamQueue& q, RoamState& S, const RoamTerrain& T, int32_t d) {
  if (q.slot[d] >= 0) return;
  S.priority[d] = roam_projected_error(S, T, d);
  queue_insert(q, S.priority, d);
  if (S.defer) track(S, T, d);
}

void dequeue(RoamQueue& q, RoamState& S, int32_t d) {
  if (q.slot[d] < 0) return;
  queue_remove(q, S.priority, d);
  if (S.defer) queue_remove(S.deadline_queue, S.deadline, d);
}

void rekey(RoamState& S, const RoamTerrain& T, RoamQueue& q) {
  for (int32_t d : q.heap) S.priority[d] = roam_projected_error(S, T, d);
  heapify(q, S.priority);
}

// Whole-front re-key; with deferral on, every front diamond gets a fresh deadline.
uint32_t rekey_all(RoamState& S, const RoamTerrain& T) {
  rekey(S, T, S.split_queue);
  rekey(S, T, S.merge_queue);
  for (int32_t d : S.deadline_queue.heap) S.deadline_queue.slot[d] = -1;
  S.deadline_queue.heap.clear();
  if (S.defer)
    for (const RoamQueue* q : {&S.split_queue, &S.merge_queue})
      for (int32_t d : q->heap) {
        S.deadline[d] = S.travel + std::max(slack_of(S, T, d), 0.f);
        S.deadline_queue.slot[d] = int32_t(S.deadline_queue.heap.size());
        S.deadline_queue.heap.push_back(d);
      }
  heapify(S.deadline_queue, S.deadline);
  return uint32_t(S.split_queue.heap.size() + S.merge_queue.heap.size());
}

// Re-keys only the diamonds whose deadline the travel has passed.
uint32_t rekey_due(RoamState& S, const RoamTerrain& T) {
  uint32_t n = 0;
  const size_t front = S.deadline_queue.heap.size();  // each is re-keyed at most once
  while (n < front && S.deadline[S.deadline_queue.heap.front()] < S.travel) {
    const int32_t d = S.deadline_queue.heap.front();
    S.priority[d] = roam_projected_error(S, T, d);
    queue_rekey(S.split_queue.slot[d] >= 0 ? S.split_queue : S.merge_queue, S.priority, d);
    track(S, T, d);
    ++n;
  }
  return n;
}

bool same_orientation(const View& a, const View& b) {
  const glm::vec3 fa = glm::normalize(a.target - a.eye), fb = glm::normalize(b.target - b.eye);
  return glm::length(fa - fb) < 1e-6f && a.up == b.up && a.fov_y_deg == b.fov_y_deg && a.width == b.width &&
         a.height == b.height && a.near_plane == b.near_plane && a.far_plane == b.far_plane;
}

// ---- the targets ----

// Operations left this frame, and the deadline when a clock is lent.
struct Budget {
  uint32_t left;
  const RoamClock* clock = nullptr;
  double deadline = 0;
  uint32_t until_read = kRoamClockStride;
  bool expired = false;
  bool take() {
    if (left == 0 || expired) return false;
    if (clock && --until_read == 0) {
      until_read = kRoamClockStride;
      if (clock->now_ms(clock->context) >= deadline) return !(expired = true);
    }
    --left;
    return true;
  }
};

float top_priority(const RoamState& S, const RoamQueue& q) { return S.priority[q.heap.front()]; }

bool merge_down_to(RoamState& S, const RoamTerrain& T, uint32_t target, int32_t watch);

bool merge_wanted(const RoamState& S, float tau) {
  return !S.merge_queue.heap.empty() && top_priority(S, S.merge_queue) <= tau;
}
bool split_wanted(const RoamState& S, float tau) {
  return !S.split_queue.heap.empty() && top_priority(S, S.split_queue) > tau;
}

void run_pixel_target(RoamState& S, const RoamTerrain& T, const RoamParams& P, Budget& b,
                      RoamFrameStats& st) {
  // Merges first (what merges has projected error <= tau and will not split again; it frees
  // room for the splits); against a clock the two alternate, so a frame cut short did both.
  bool merge_turn = true;
  for (;;) {
    const bool merge = merge_wanted(S, P.pixel_error);
    const bool split = split_wanted(S, P.pixel_error) && S.triangle_count < P.max_triangles;
    if (!merge && !split) break;
    if (!b.take()) break;
    if (merge && (!split || merge_turn)) roam_merge(S, T, S.merge_queue.heap.front());
    else roam_split(S, T, S.split_queue.heap.front());
    merge_turn = b.clock ? !merge_turn : true;
  }
  if (split_wanted(S, P.pixel_error) || merge_wanted(S, P.pixel_error)) st.budget_bound = 1;
  // A cap below the mesh (a share that shrank) or passed by a split's forced parents: merge
  // the least error away until it holds; the cap is a budget, not a hint.
  if (S.triangle_count > P.max_triangles) {
    st.budget_bound = 1;
    merge_down_to(S, T, std::max<uint32_t>(P.max_triangles, 2), -1);
  }
}

// Merges the lowest-error diamonds until the count is at most the target; true when `watch`
// (the diamond just split) was merged back, i.e. swapping cannot improve at this budget.
bool merge_down_to(RoamState& S, const RoamTerrain& T, uint32_t target, int32_t watch) {
  bool undone = false;
  while (S.triangle_count > target && !S.merge_queue.heap.empty()) {
    const int32_t d = S.merge_queue.heap.front();
    undone |= d == watch;
    roam_merge(S, T, d);
  }
  return undone;
}

void run_count_target(RoamState& S, const RoamTerrain& T, const RoamParams& P, Budget& b,
                      RoamFrameStats& st) {
  const uint32_t target = std::max<uint32_t>(P.triangle_count, 2);
  // Grow while short of the target (visible diamonds only), then trim to it.
  while (S.triangle_count < target && !S.split_queue.heap.empty() && top_priority(S, S.split_queue) > 0) {
    if (!b.take()) {
      st.budget_bound = 1;
      break;
    }
    roam_split(S, T, S.split_queue.heap.front());
  }
  merge_down_to(S, T, target, -1);
  // Then trade: split the worst leaf while it is worse than the best merge, Duchaineau's loop.
  while (!S.split_queue.heap.empty() && !S.merge_queue.heap.empty() &&
         top_priority(S, S.split_queue) > top_priority(S, S.merge_queue)) {
    if (!b.take()) {
      st.budget_bound = 1;
      break;
    }
    const int32_t d = S.split_queue.heap.front();
    roam_split(S, T, d);
    if (merge_down_to(S, T, target, d)) break;
  }
  merge_down_to(S, T, target, -1);
}

bool sphere_outside(const Frustum& f, glm::vec3 c, float r) {
  for (const glm::vec4& pl : f.planes)
    if (glm::dot(glm::vec3(pl), c) + pl.w < -r) return true;
  return false;
}

// Walks a bintree triangle down to the mesh's leaves (split: one flag per sample). With a
// frustum, a subtree whose diamond sphere (which holds the triangle and every descendant) is
// outside the view is skipped whole.
void emit(std::vector<uint32_t>& out, const uint8_t* split, const Frustum* cull, const RoamTerrain& T, Cell apex,
          Cell l, Cell r) {
  const int32_t size = int32_t(T.size);
  const bool divisible = ((l.x + r.x) % 2 == 0) && ((l.y + r.y) % 2 == 0);
  const Cell m{(l.x + r.x) / 2, (l.y + r.y) / 2};
  const int32_t d = m.y * size + m.x;
  if (divisible && cull && sphere_outside(*cull, T.positions[d], T.radius[d])) return;
  if (divisible && split[d]) {
    emit(out, split, cull, T, m, apex, l);
    emit(out, split, cull, T, m, r, apex);
    return;
  }
  out.push_back(uint32_t(apex.y * size + apex.x));
  out.push_back(uint32_t(l.y * size + l.x));
  out.push_back(uint32_t(r.y * size + r.x));
}

size_t emit_mesh(std::vector<uint32_t>& indices, const uint8_t* split, const Frustum* cull, const RoamTerrain& T) {
  indices.clear();
  const int32_t m = int32_t(T.size - 1);
  emit(indices, split, cull, T, {m, 0}, {m, m}, {0, 0});
  emit(indices, split, cull, T, {0, m}, {0, 0}, {m, m});
  return indices.size() / 3;
}

}  // namespace detail

bool roam_size_valid(uint32_t width, uint32_t height) {
  if (width != height || width < 3) return false;
  const uint32_t m = width - 1;
  return (m & (m - 1)) == 0 && m <= (1u << 15);
}

RoamTerrain build_roam_terrain(const HeightField& field) {
  assert(roam_size_valid(field.width, field.height));
  RoamTerrain T;
  T.size = field.width;
  T.levels = uint32_t(std::countr_zero(T.size - 1));
  const size_t n = field.sample_count();
  T.positions.resize(n);
  for (uint32_t y = 0; y < T.size; ++y)
    for (uint32_t x = 0; x < T.size; ++x)
      T.positions[size_t(y) * T.size + x] = {
          float(x) * field.cell_size_x, field.at(x, y) * field.vertical_scale, float(y) * field.cell_size_y};
  T.error.assign(n, 0.f);
  T.radius.assign(n, 0.f);
  T.parents.resize(n);
  T.children.resize(n);
  T.triangles.assign(n, 0);
  const detail::Grid g{int32_t(T.size), int32_t(T.size - 1)};
  T.root = g.id({g.max / 2, g.max / 2});
  detail::build_links(T, g);
  detail::build_bounds(T, g);
  return T;
}

void roam_reset(RoamState& S, const RoamTerrain& T) {
  const size_t n = T.positions.size();
  S.split.assign(n, 0);
  S.priority.assign(n, 0.f);
  detail::reset_queue(S.split_queue, n, 1.f);
  detail::reset_queue(S.merge_queue, n, -1.f);
  detail::reset_queue(S.deadline_queue, n, -1.f);
  S.deadline.assign(n, 0.f);
  S.defer = 0;
  S.travel = 0;
  S.triangle_count = 2;
  S.splits = S.merges = 0;
  S.events.clear();
  S.events.reserve(4096);
  detail::enqueue(S.split_queue, S, T, T.root);
}

void roam_set_view(RoamState& S, const View& view) {
  S.eye = view.eye;
  S.focal = focal_pixels(view);
  S.near_plane = view.near_plane;
  S.frustum = frustum_of(view);
}

float roam_projected_error(const RoamState& S, const RoamTerrain& T, int32_t d) {
  const glm::vec3 c = T.positions[d];
  const float r = T.radius[d];
  if (detail::sphere_outside(S.frustum, c, r)) return 0.f;
  const float dist = std::max(glm::length(S.eye - c) - r, S.near_plane);
  return T.error[d] * S.focal / dist;
}

void roam_split(RoamState& S, const RoamTerrain& T, int32_t d) {
  assert(T.triangles[d] > 0);  // grid corners are no diamonds
  if (S.split[d]) return;
  for (int32_t p : T.parents[d])
    if (p >= 0) roam_split(S, T, p);  // forced: the base neighbour's parent first
  detail::dequeue(S.split_queue, S, d);
  S.split[d] = 1;
  S.triangle_count += T.triangles[d];
  ++S.splits;
  S.events.push_back(d);
  detail::enqueue(S.merge_queue, S, T, d);
  for (int32_t p : T.parents[d])
    if (p >= 0) detail::dequeue(S.merge_queue, S, p);
  for (int32_t c : T.children[d])
    if (c >= 0 && detail::parents_split(S, T, c)) detail::enqueue(S.split_queue, S, T, c);
}

void roam_merge(RoamState& S, const RoamTerrain& T, int32_t d) {
  assert(S.split[d] && !detail::any_child_split(S, T, d));
  detail::dequeue(S.merge_queue, S, d);
  S.split[d] = 0;
  S.triangle_count -= T.triangles[d];
  ++S.merges;
  S.events.push_back(~d);
  detail::enqueue(S.split_queue, S, T, d);
  for (int32_t c : T.children[d])
    if (c >= 0) detail::dequeue(S.split_queue, S, c);
  for (int32_t p : T.parents[d])
    if (p >= 0 && !detail::any_child_split(S, T, p)) detail::enqueue(S.merge_queue, S, T, p);
}

RoamFrameStats roam_update(RoamState& S, const RoamTerrain& T, const View& view, const RoamParams& P) {
  RoamFrameStats st;
  const double start_ms = P.max_ms > 0 && P.clock.now_ms ? P.clock.now_ms(P.clock.context) : 0;
  const uint32_t splits0 = S.splits, merges0 = S.merges;
  const glm::vec3 last_eye = S.eye;
  S.events.clear();
  roam_set_view(S, view);
  const bool pixel = P.target == RoamTarget::pixel_error;
  if (pixel && S.defer && S.tau == P.pixel_error && detail::same_orientation(S.anchor, view)) {
    S.travel += glm::length(view.eye - last_eye);
    st.rekeyed = detail::rekey_due(S, T);
  } else {
    S.defer = pixel ? 1 : 0;
    S.tau = P.pixel_error;
    S.anchor = view;
    S.travel = 0;
    st.rekeyed = detail::rekey_all(S, T);
  }
  detail::Budget budget{P.max_operations};
  if (P.max_ms > 0 && P.clock.now_ms) {
    budget.clock = &P.clock;
    budget.deadline = start_ms + double(P.max_ms);
  }
  if (P.target == RoamTarget::pixel_error)
    detail::run_pixel_target(S, T, P, budget, st);
  else
    detail::run_count_target(S, T, P, budget, st);
  st.splits = S.splits - splits0;
  st.merges = S.merges - merges0;
  st.triangles = S.triangle_count;
  st.time_bound = budget.expired ? 1 : 0;
  st.budget_bound |= st.time_bound;
  return st;
}

size_t roam_triangles(std::vector<uint32_t>& indices, const RoamState& S, const RoamTerrain& T) {
  return detail::emit_mesh(indices, S.split.data(), nullptr, T);
}

size_t roam_visible_triangles(std::vector<uint32_t>& indices, const RoamState& S, const RoamTerrain& T) {
  return detail::emit_mesh(indices, S.split.data(), &S.frustum, T);
}

size_t roam_triangles_of(std::vector<uint32_t>& indices, std::span<const uint8_t> split, const RoamTerrain& T) {
  assert(split.size() == T.positions.size());
  return detail::emit_mesh(indices, split.data(), nullptr, T);
}

std::array<int32_t, 2> roam_base_ends(const RoamTerrain& T, int32_t d) {
  const int32_t size = int32_t(T.size);
  const detail::DiamondShape s = detail::diamond_shape(d % size, d / size);
  return {s.p.y * size + s.p.x, s.q.y * size + s.q.x};
}

int roam_depth(const RoamTerrain& T, int32_t d) {
  const int32_t size = int32_t(T.size);
  return detail::depth_of(d % size, d / size, T.levels);
}

int32_t roam_diamond_of(const RoamTerrain& T, uint32_t a, uint32_t b) {
  const uint32_t ax = a % T.size, ay = a / T.size, bx = b % T.size, by = b / T.size;
  if ((ax + bx) % 2 || (ay + by) % 2) return -1;
  return int32_t(((ay + by) / 2) * T.size + (ax + bx) / 2);
}

}  // namespace lod
