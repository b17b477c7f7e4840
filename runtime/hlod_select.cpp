// HLOD cut selection (Zhou and Tian 3.3): one breadth-first visit of the wanted cut, one pass deciding
// which wanted openings the children's residency allows, one top-down pass emitting the cut,
// then, over the budget, undoing as budgeted selection does (a min-heap of screen-space errors) or the same
// steps refining from the root (a max-heap).
#include "runtime/hlod_select.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>

#include "runtime/world_bounds.h"

namespace lod {
namespace {

constexpr float kHuge = std::numeric_limits<float>::max();

// Low bits: what the visit decided; high bits: where the node stands in the emitted cut.
enum : uint8_t {
  kCulled = 1,
  kMissing = 2,   // visible, not resident: requested
  kDraw = 3,      // drawn at scratch.layer (if in the cut)
  kWantOpen = 4,  // no layer is fine enough; resolved to kOpened or kDraw
  kOpened = 5,
  kKindMask = 0x0f,
  kInCut = 0x10,             // its parent is opened and in the cut (or it is the root)
  kCovered = 0x20,           // some ancestor is drawn in the cut
  kOpenBeforeBudget = 0x40,  // opened in the wanted cut (the refining pass's target)
  kOutside = 0x80,           // outside the frustum, covered (HlodCulledNodes::cover)
};

uint8_t kind(uint8_t s) { return s & kKindMask; }
bool in_cut(uint8_t s) { return (s & kInCut) != 0; }

// The coarsest layer whose error meets E at this (object-space) distance, or -1.
int wanted_layer(const HlodNode& n, float distance, float error_per_distance) {
  const float threshold = distance * error_per_distance;  // hlod_error_threshold, one multiply
  for (int l = int(n.layer_count) - 1; l >= 0; --l) {
    if (n.layers[l].error <= threshold) return l;
  }
  return -1;
}

// Screen-space error, pixels: e * scale * focal / d (world distance); huge inside the bounds.
float sse_of(const HlodCutScratch& s, const HlodNode& n, uint32_t id, uint32_t layer) {
  const float d = s.distance[id];
  return d > 0 ? n.layers[layer].error * s.sse_numerator / d : n.layers[layer].error * kHuge;
}

// The view in the tree's object space, so that no node is transformed: with world =
// position + scale * R(object), a world plane (n, w) is (R^T n, (n . position + w) / scale)
// over object-space spheres, distances shrink by the scale and so do the errors they meet.
struct ObjectView {
  glm::vec3 eye;
  glm::vec4 planes[6];
  float scale;
};

ObjectView object_view(const Transform& transform, const HlodView& view) {
  float q[4];
  normalized_rotation(transform, q);
  const float inverse[4] = {-q[0], -q[1], -q[2], q[3]};
  const glm::vec3 position(transform.position[0], transform.position[1], transform.position[2]);
  ObjectView o;
  o.scale = transform.scale;
  const glm::vec3 rel = (view.eye - position) / transform.scale;
  rotate_by_quaternion(inverse, &rel.x, &o.eye.x);
  for (int k = 0; k < 6; ++k) {
    const glm::vec4& p = view.frustum.planes[k];
    glm::vec3 n;
    rotate_by_quaternion(inverse, &p.x, &n.x);
    // Culling off: planes every sphere is inside of.
    o.planes[k] = view.cull ? glm::vec4(n, (glm::dot(glm::vec3(p), position) + p.w) / transform.scale)
                            : glm::vec4(0, 0, 0, 1);
  }
  return o;
}

bool outside(const ObjectView& o, const Sphere& b) {
  for (const glm::vec4& p : o.planes) {
    if (p.x * b.center[0] + p.y * b.center[1] + p.z * b.center[2] + p.w < -b.radius) return true;
  }
  return false;
}

// Breadth-first from the root: measure, cull, choose the wanted layer, queue wanted children.
void visit(HlodCut& cut, HlodCutScratch& s, const HlodTree& tree, std::span<const uint8_t> resident,
           const ObjectView& o, const HlodView& view, const HlodSelectParams& params) {
  const float error_per_distance = params.pixel_error / view.focal_px;  // E = d * P / focal
  s.sse_numerator = view.focal_px * o.scale;
  s.queue.clear();
  s.queue.push_back(0);
  for (size_t head = 0; head < s.queue.size(); ++head) {
    const uint32_t id = s.queue[head];
    const HlodNode& n = tree.nodes[id];
    const bool out = outside(o, n.bounds);
    if (out && (id == 0 || params.culled == HlodCulledNodes::skip)) {
      s.state[id] = kCulled;
      cut.culled.push_back(id);
      continue;
    }
    const float dx = n.bounds.center[0] - o.eye.x, dy = n.bounds.center[1] - o.eye.y,
                dz = n.bounds.center[2] - o.eye.z;
    const float d = std::max(0.0f, std::sqrt(dx * dx + dy * dy + dz * dz) - n.bounds.radius);  // object space
    s.distance[id] = d * o.scale;
    if (out) {  // covered: drawn at its coarsest, never opened; requested last when missing
      s.state[id] = resident[id] ? uint8_t(kDraw | kOutside) : uint8_t(kMissing | kOutside);
      s.layer[id] = uint8_t(n.layer_count - 1);
      if (resident[id]) cut.kept.push_back(id);
      continue;
    }
    if (!resident[id]) {
      s.state[id] = kMissing;
      continue;
    }
    cut.kept.push_back(id);
    const int l = wanted_layer(n, d, error_per_distance);
    s.layer[id] = static_cast<uint8_t>(std::max(l, 0));
    if (l >= 0 || n.leaf()) {
      s.state[id] = kDraw;
      continue;
    }
    s.state[id] = kWantOpen;
    for (uint32_t k = 0; k < n.child_count; ++k) s.queue.push_back(n.first_child + k);
  }
}

// Never a hole: an opening is honoured only when every visible child is resident; otherwise
// the node stays drawn at its finest layer.
void resolve_openings(HlodCutScratch& s, const HlodTree& tree) {
  for (uint32_t id : s.queue) {
    if (kind(s.state[id]) != kWantOpen) continue;
    const HlodNode& n = tree.nodes[id];
    bool all_there = true;
    for (uint32_t k = 0; k < n.child_count; ++k) all_there &= kind(s.state[n.first_child + k]) != kMissing;
    s.state[id] = all_there ? kOpened : kDraw;
  }
}

// Top-down in visiting order (parents first): which nodes are in the cut, the triangles, the
// requests and the holes.
void emit(HlodCut& cut, HlodCutScratch& s, const HlodTree& tree, const HlodSelectParams& params) {
  for (uint32_t id : s.queue) {
    const HlodNode& n = tree.nodes[id];
    uint8_t st = s.state[id];
    if (n.parent < 0) {
      st |= kInCut;
    } else {
      const uint8_t ps = s.state[n.parent];
      if (in_cut(ps) && kind(ps) == kOpened) st |= kInCut;
      if ((ps & kCovered) || (in_cut(ps) && kind(ps) == kDraw)) st |= kCovered;
    }
    s.state[id] = st;
    if (kind(st) == kMissing) {
      const float deficit = n.parent < 0 ? kHuge
                            : st & kOutside
                                ? -kHuge  // invisible: after every visible request
                                : sse_of(s, tree.nodes[n.parent], uint32_t(n.parent), 0) - params.pixel_error;
      cut.requests.push_back({id, deficit, s.distance[id]});
      if (!(st & kCovered)) ++cut.holes;
    }
    if (!in_cut(st)) continue;
    if (kind(st) == kDraw) cut.triangles += n.layers[s.layer[id]].triangles;
    if (kind(st) == kOpened) cut.triangles += n.boundary_triangles;
  }
}

// Heap entries are one integer: the error's bits (a float >= 0 orders as its bits) above the
// complemented node id, so one comparison orders by error, then by id: a min-heap pops the
// smallest error, then the deeper (larger id) node; a max-heap the largest, then the
// shallower. Branch-free compares: the heap is the budget passes' whole cost.
uint64_t heap_key(float sse, uint32_t id) {
  uint32_t bits;
  std::memcpy(&bits, &sse, sizeof bits);
  return uint64_t(bits) << 32 | uint32_t(~id);
}
float key_sse(uint64_t key) {
  const uint32_t bits = uint32_t(key >> 32);
  float sse;
  std::memcpy(&sse, &bits, sizeof sse);
  return sse;
}
uint32_t key_node(uint64_t key) { return ~uint32_t(key); }
constexpr std::greater<uint64_t> undo_after{};

void push_undo(HlodCutScratch& s, float sse, uint32_t id) {
  s.heap.push_back(heap_key(sse, id));
  std::push_heap(s.heap.begin(), s.heap.end(), undo_after);
}

uint32_t opened_children(const HlodCutScratch& s, const HlodNode& n) {
  uint32_t count = 0;
  for (uint32_t k = 0; k < n.child_count; ++k) count += kind(s.state[n.first_child + k]) == kOpened;
  return count;
}

// The undo an in-cut node offers now: one layer coarser when drawn, closing when opened with
// no opened child. False when it offers none.
bool next_undo(const HlodCutScratch& s, const HlodTree& tree, uint32_t id, float* sse) {
  const HlodNode& n = tree.nodes[id];
  const uint8_t st = s.state[id];
  if (!in_cut(st)) return false;
  if (kind(st) == kDraw && s.layer[id] + 1u < n.layer_count) {
    *sse = sse_of(s, n, id, s.layer[id] + 1u);
    return true;
  }
  if (kind(st) == kOpened && s.open_children[id] == 0) {
    *sse = sse_of(s, n, id, 0);
    return true;
  }
  return false;
}

void offer_undo(HlodCutScratch& s, const HlodTree& tree, uint32_t id) {
  float sse;
  if (next_undo(s, tree, id, &sse)) push_undo(s, sse, id);
}

// Applies one undo; returns the triangles it changed (signed: a closed node may cost more).
int64_t apply_undo(HlodCutScratch& s, const HlodTree& tree, uint32_t id) {
  const HlodNode& n = tree.nodes[id];
  if (kind(s.state[id]) == kDraw) {
    const uint8_t l = s.layer[id]++;
    return int64_t(n.layers[l + 1].triangles) - int64_t(n.layers[l].triangles);
  }
  int64_t delta = int64_t(n.layers[0].triangles) - int64_t(n.boundary_triangles);
  for (uint32_t k = 0; k < n.child_count; ++k) {
    const uint32_t c = n.first_child + k;
    if (in_cut(s.state[c]) && kind(s.state[c]) == kDraw) delta -= tree.nodes[c].layers[s.layer[c]].triangles;
    s.state[c] &= uint8_t(~kInCut);
  }
  s.state[id] = uint8_t((s.state[id] & ~kKindMask) | kDraw);
  s.layer[id] = 0;
  if (n.parent >= 0) --s.open_children[n.parent];
  return delta;
}

// Undoing from the wanted cut: cheap when the cut is a little over the budget.
void undo_to_budget(HlodCut& cut, HlodCutScratch& s, const HlodTree& tree, uint64_t budget) {
  s.heap.clear();
  for (uint32_t id : s.queue) {
    if (kind(s.state[id]) == kOpened) s.open_children[id] = uint8_t(opened_children(s, tree.nodes[id]));
  }
  for (uint32_t id : s.queue) offer_undo(s, tree, id);
  int64_t triangles = int64_t(cut.triangles);
  while (triangles > int64_t(budget) && !s.heap.empty()) {
    std::pop_heap(s.heap.begin(), s.heap.end(), undo_after);
    const uint64_t key = s.heap.back();
    s.heap.pop_back();
    const struct {
      float sse;
      uint32_t node;
    } u{key_sse(key), key_node(key)};
    float sse;
    // Entries go stale when a node leaves the cut or changes; only the current offer counts.
    if (!next_undo(s, tree, u.node, &sse) || sse != u.sse) continue;
    const bool closing = kind(s.state[u.node]) == kOpened;
    triangles += apply_undo(s, tree, u.node);
    ++cut.undone;
    offer_undo(s, tree, u.node);
    // Closing the last opened child lets the parent close in turn.
    const int32_t p = tree.nodes[u.node].parent;
    if (closing && p >= 0) offer_undo(s, tree, uint32_t(p));
  }
  cut.triangles = uint64_t(triangles);
  cut.over_budget = triangles > int64_t(budget);
}

// Refining from the root towards the wanted cut, the largest error first, until the next
// step would not fit: the same steps in reverse order, so the same cut when every undo
// lowers the triangles (errors and triangle counts monotonic up the tree); cheap when the
// wanted cut is far over the budget, since only the budgeted cut is walked.
using RefineBefore = std::less<uint64_t>;  // max-heap: the largest error, then the smaller id

uint64_t coarsest_triangles(const HlodNode& n) { return n.layers[n.layer_count - 1].triangles; }

// The refinement a drawn node offers: one layer finer towards its wanted layer, then opening.
bool next_refine(const HlodCutScratch& s, const HlodTree& tree, uint32_t id, float* sse, int64_t* delta) {
  const HlodNode& n = tree.nodes[id];
  const uint8_t l = s.layer[id];
  if (l > s.wanted_layer[id]) {
    *sse = sse_of(s, n, id, l);
    *delta = int64_t(n.layers[l - 1].triangles) - int64_t(n.layers[l].triangles);
    return true;
  }
  if (l != 0 || !(s.state[id] & kOpenBeforeBudget) || kind(s.state[id]) != kDraw) return false;
  *sse = sse_of(s, n, id, 0);
  *delta = int64_t(n.boundary_triangles) - int64_t(n.layers[0].triangles);
  for (uint32_t k = 0; k < n.child_count; ++k) {
    const uint32_t c = n.first_child + k;
    if (kind(s.state[c]) != kCulled) *delta += int64_t(coarsest_triangles(tree.nodes[c]));
  }
  return true;
}

void offer_refine(HlodCutScratch& s, const HlodTree& tree, uint32_t id) {
  float sse;
  int64_t delta;
  if (!next_refine(s, tree, id, &sse, &delta)) return;
  s.heap.push_back(heap_key(sse, id));
  std::push_heap(s.heap.begin(), s.heap.end(), RefineBefore{});
}

// A node starts drawn at its coarsest layer (culled ones stay culled).
void start_coarsest(HlodCutScratch& s, const HlodTree& tree, uint32_t id) {
  s.state[id] |= kInCut;
  if (kind(s.state[id]) == kCulled) return;
  s.state[id] = uint8_t((s.state[id] & ~kKindMask) | kDraw);
  s.layer[id] = uint8_t(tree.nodes[id].layer_count - 1);
}

void refine_to_budget(HlodCut& cut, HlodCutScratch& s, const HlodTree& tree, uint64_t budget) {
  uint32_t wanted_steps = 0;
  for (uint32_t id : s.queue) {
    uint8_t& st = s.state[id];
    if (in_cut(st) && kind(st) == kDraw) wanted_steps += tree.nodes[id].layer_count - 1u - s.layer[id];
    if (in_cut(st) && kind(st) == kOpened)
      wanted_steps += tree.nodes[id].layer_count, st |= kOpenBeforeBudget;
    s.wanted_layer[id] = s.layer[id];
    st &= uint8_t(~kInCut);
  }
  s.heap.clear();
  start_coarsest(s, tree, 0);
  int64_t triangles = kind(s.state[0]) == kCulled ? 0 : int64_t(coarsest_triangles(tree.nodes[0]));
  offer_refine(s, tree, 0);
  uint32_t steps = 0;
  while (!s.heap.empty()) {
    const uint32_t id = key_node(s.heap.front());
    float sse = 0;
    int64_t delta = 0;
    next_refine(s, tree, id, &sse, &delta);          // always true: one live entry per node
    if (triangles + delta > int64_t(budget)) break;  // the undoing pass would stop here too
    std::pop_heap(s.heap.begin(), s.heap.end(), RefineBefore{});
    s.heap.pop_back();
    triangles += delta;
    ++steps;
    if (s.layer[id] > s.wanted_layer[id]) {
      --s.layer[id];
      offer_refine(s, tree, id);
      continue;
    }
    s.state[id] = uint8_t((s.state[id] & ~kKindMask) | kOpened);
    const HlodNode& n = tree.nodes[id];
    for (uint32_t k = 0; k < n.child_count; ++k) {
      start_coarsest(s, tree, n.first_child + k);
      offer_refine(s, tree, n.first_child + k);
    }
  }
  cut.triangles = uint64_t(triangles);
  cut.undone = wanted_steps - steps;
  cut.over_budget = triangles > int64_t(budget);
}

void list_cut(HlodCut& cut, const HlodCutScratch& s) {
  cut.drawn.clear();
  cut.opened.clear();
  for (uint32_t id : s.queue) {
    const uint8_t st = s.state[id];
    if (!in_cut(st)) continue;
    if (kind(st) == kDraw) cut.drawn.push_back({id, s.layer[id]});
    if (kind(st) == kOpened) cut.opened.push_back(id);
  }
}

}  // namespace

HlodView hlod_view_of(const View& v) {
  HlodView h;
  h.eye = v.eye;
  h.focal_px = focal_pixels(v);
  h.frustum = frustum_of(v);
  return h;
}

bool request_before(const HlodRequest& a, const HlodRequest& b) {
  if (a.deficit != b.deficit) return a.deficit > b.deficit;
  if (a.distance != b.distance) return a.distance < b.distance;
  return a.node < b.node;
}

void prepare_hlod_cut(HlodCut& cut, HlodCutScratch& s, const HlodTree& tree) {
  const size_t n = tree.nodes.size();
  s.distance.assign(n, 0);
  s.state.assign(n, 0);
  s.layer.assign(n, 0);
  s.wanted_layer.assign(n, 0);
  s.open_children.assign(n, 0);
  s.queue.reserve(n);
  s.heap.reserve(7 * n);  // an offer per node, two per undo, at most three undos per node
  for (auto* v : {&cut.opened, &cut.culled, &cut.kept}) v->reserve(n);
  cut.drawn.reserve(n);
  cut.requests.reserve(n);
}

uint32_t select_hlod_cut(HlodCut& cut, HlodCutScratch& s, const HlodTree& tree,
                         std::span<const uint8_t> resident, const Transform& transform, const HlodView& view,
                         const HlodSelectParams& params) {
  cut.drawn.clear();
  cut.opened.clear();
  cut.culled.clear();
  cut.requests.clear();
  cut.kept.clear();
  cut.triangles = cut.wanted_triangles = 0;
  cut.undone = cut.holes = 0;
  cut.over_budget = false;
  if (tree.nodes.empty()) return 0;
  assert(resident.size() == tree.nodes.size() && s.state.size() == tree.nodes.size());
  visit(cut, s, tree, resident, object_view(transform, view), view, params);
  resolve_openings(s, tree);
  emit(cut, s, tree, params);
  cut.wanted_triangles = cut.triangles;
  if (cut.triangles > params.triangle_budget) {
    // The pass with fewer steps: undo when the cut is less than twice the budget.
    const bool refine =
        params.budget_pass == HlodBudgetPass::refine ||
        (params.budget_pass == HlodBudgetPass::automatic && cut.triangles / 2 > params.triangle_budget);
    if (refine) {
      refine_to_budget(cut, s, tree, params.triangle_budget);
    } else {
      undo_to_budget(cut, s, tree, params.triangle_budget);
    }
  }
  list_cut(cut, s);
  std::sort(cut.requests.begin(), cut.requests.end(), request_before);
  return uint32_t(cut.drawn.size());
}

}  // namespace lod
