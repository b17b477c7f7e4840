// Active-front update over flat arrays: split/collapse with dependencies, a motion calendar
// so a frame visits only nodes whose decision may have changed, threshold feedback.
#include "runtime/vertex_front.h"

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>

namespace lod {
namespace {

constexpr uint32_t kBuckets = 4096;
constexpr uint16_t kUnfiled = 0xffff;
constexpr double kInf = std::numeric_limits<double>::infinity();

struct Decision {
  bool refine;
  // How much view motion `refine` survives: eye travel plus plane offset change in object
  // units (calendar 0) and plane turning in radians (calendar 1); infinity when that motion
  // cannot change it.
  double slack_eye, slack_turn;
};

// Hoppe 1997's criteria for one node, with how far the view may move before each could flip.
// A plane's signed distance at the node's centre c changes between views by at most
// |dn| |c - eye'| + |d eye| + |d offset| (offset: the eye's own signed distance to the plane),
// and |c - eye'| <= d + eye travel. So a frustum margin S holds while the eye part stays under
// `split` * S and the summed turning under (1 - split) S / (d + split S); `split` only trades
// one calendar against the other and any value in (0, 1) is safe.
Decision evaluate(const VertexTree& t, uint32_t v, const FrontView& view, float threshold, double reach,
                  double split) {
  const VertexBounds& nb = t.bounds[v];
  const float c[3] = {nb.x, nb.y, nb.z};
  const double ax = c[0] - double(view.eye[0]), ay = c[1] - double(view.eye[1]),
               az = c[2] - double(view.eye[2]);
  const double d = std::sqrt(ax * ax + ay * ay + az * az);
  // Frustum: outside when some plane has the whole sphere behind it.
  const double r = nb.radius;
  double outside_by = -kInf, inside_by = kInf;
  for (const auto& pl : view.planes) {
    const double s = double(pl[0]) * c[0] + double(pl[1]) * c[1] + double(pl[2]) * c[2] + pl[3];
    outside_by = std::max(outside_by, -r - s);
    inside_by = std::min(inside_by, s + r);
  }
  const bool in_frustum = outside_by <= 0;
  const double slack_frustum = in_frustum ? inside_by : outside_by;

  // Normal cone: every normal in the cone points away from every point of the sphere.
  bool facing = true;
  double slack_facing = kInf;
  const double cos_alpha = nb.cone_cos * (1.0 / 32767);
  if (cos_alpha > 0 && d > r) {
    const double n[3] = {nb.axis[0] * (1.0 / 32767), nb.axis[1] * (1.0 / 32767), nb.axis[2] * (1.0 / 32767)};
    const double cos_beta = (ax * n[0] + ay * n[1] + az * n[2]) / d;
    const double sin_alpha = std::sqrt(std::max(0.0, 1 - cos_alpha * cos_alpha));
    const double sin_gamma = r / d, cos_gamma = std::sqrt(std::max(0.0, 1 - sin_gamma * sin_gamma));
    // alpha + gamma < 90 degrees and beta + alpha + gamma < 90 degrees.
    const double cos_sum = cos_alpha * cos_gamma - sin_alpha * sin_gamma;
    const double sin_sum = sin_alpha * cos_gamma + cos_alpha * sin_gamma;
    facing = !(cos_sum > 0 && cos_beta > sin_sum);
    // An eye move of m turns the direction to the centre by at most m / d and widens the
    // sphere's angle by at most m r / (d (d - r)): together m / (d - r) radians, and the
    // margin in angle is at least the margin in cosine.
    slack_facing = std::abs(cos_beta - sin_sum) * std::max(d - r, 0.0);
  }
  // Screen-space error: e * focal / distance > threshold while distance < critical.
  const double dist = std::max(d - r, 1e-6);
  const double critical = double(nb.error) * view.focal_pixels / threshold;
  const bool coarse = dist < critical;
  const double slack_error = std::min(std::abs(dist - critical), reach);

  const double frustum_eye = split * slack_frustum;
  const double frustum_turn = (1 - split) * slack_frustum / (d + frustum_eye);
  const bool refine = in_frustum && facing && coarse;
  if (refine) return {true, std::min({slack_facing, slack_error, frustum_eye}), frustum_turn};
  // Stays false while any failing criterion keeps failing: outside the frustum is enough.
  if (!in_frustum) return {false, frustum_eye, frustum_turn};
  double slack = 0;
  if (!facing) slack = std::max(slack, slack_facing);
  if (!coarse) slack = std::max(slack, slack_error);
  return {false, slack, kInf};
}

// LSD radix sort of node ids, 11 bits per pass, only as many passes as the ids need;
// `scratch` holds `count` ids.
void sort_ids(uint32_t* ids, uint32_t count, uint32_t* scratch, uint32_t id_limit) {
  if (count < 64) return std::sort(ids, ids + count);
  constexpr uint32_t kBits = 11, kBins = 1u << kBits;
  uint32_t histogram[kBins];
  uint32_t* from = ids;
  uint32_t* to = scratch;
  int passes = 0;
  for (uint32_t shift = 0; shift < 32 && (id_limit >> shift) > 0; shift += kBits, ++passes) {
    std::fill(histogram, histogram + kBins, 0u);
    for (uint32_t k = 0; k < count; ++k) ++histogram[(from[k] >> shift) & (kBins - 1)];
    uint32_t sum = 0;
    for (uint32_t& h : histogram) {
      const uint32_t c = h;
      h = sum;
      sum += c;
    }
    for (uint32_t k = 0; k < count; ++k) to[histogram[(from[k] >> shift) & (kBins - 1)]++] = from[k];
    std::swap(from, to);
  }
  if (passes % 2 == 1) std::copy_n(from, count, ids);
}

class Updater {
 public:
  Updater(VertexFront& f, const VertexTree& t, const FrontParams& p) : f_(f), t_(t), p_(p) {}

  FrontStats run(const FrontView& view);

  void split(uint32_t x);
  void collapse(uint32_t p);
  void unfile(uint32_t v);
  void file(uint32_t v, double slack_eye, double slack_frustum);
  void file(uint32_t v, int c, double slack);
  void file_next_frame(uint32_t v);
  void drain(uint32_t b, int c);
  VertexFront::Bucket& bucket(int c, uint32_t b);
  void append(int c, uint32_t b, uint32_t v);
  uint32_t take_chunk();
  void compact(int c, uint32_t b);
  void release_chunks(uint32_t chunk);
  void stop_waiting(uint32_t v);
  void wait_for(uint32_t v, uint32_t d);
  void wake(uint32_t d);

 private:
  // First dependency of p that is not active, or kNoNode. The states are scattered: all are
  // requested before the first is read, so their misses overlap.
  uint32_t missing_dep(uint32_t p) const {
    const uint32_t i = p - t_.leaf_count;
    const uint32_t lo = t_.dep_offsets[i], hi = t_.dep_offsets[i + 1];
    for (uint32_t k = lo; k < hi; ++k) __builtin_prefetch(&f_.state[f_.at(t_.deps[k])]);
    for (uint32_t k = lo; k < hi; ++k)
      if (f_.state[f_.at(t_.deps[k])] != VertexFront::kActive) return t_.deps[k];
    return kNoNode;
  }
  bool deps_active(uint32_t p) const { return missing_dep(p) == kNoNode; }
  bool children_active(uint32_t p) const { return (f_.kids[f_.at(p)] & VertexFront::kKidsMask) == 2; }
  bool watches_parent(uint32_t v) const { return f_.kids[f_.at(v)] & VertexFront::kFirstChild; }
  bool is_pending(uint32_t p) const { return f_.pending_count && f_.pending_until[f_.inner_at(p)] >= 0; }
  uint32_t new_faces(uint32_t x) const {
    const uint32_t i = x - t_.leaf_count;
    return (t_.split_faces[2 * i] != kNoNode) + (t_.split_faces[2 * i + 1] != kNoNode);
  }
  bool force_split(uint32_t v);
  void emit(uint32_t node, FrontEventKind kind) {
    if (f_.event_count < f_.events.size()) f_.events[f_.event_count++] = {node, kind};
  }
  void push(uint32_t v) {
    if (tail_ < limit_)
      f_.queue[tail_++] = v;
    else
      file_next_frame(v);  // queue full (cannot happen with the sizes front_init picks)
  }
  // A visit reads scattered records of the node and of its parent; fetching them a few queue
  // entries ahead overlaps those misses instead of paying them one after another.
  void prefetch_ahead() {
    // A compiler barrier keeps these prefetches at the top of each visit: left free, GCC sank
    // them behind the inlined visit and the bench ran ~1.5x slower (1.15 vs 0.75 ms).
    asm volatile("" ::: "memory");
    constexpr uint32_t kNear = 6, kFar = 12, kLocal = 18;
    // A region's front also reads each node's local id, and its parent's: fetched a step
    // earlier, so the state prefetches below do not wait on them.
    if (f_.node_local && head_ + kLocal < tail_) {
      const uint32_t v = f_.queue[head_ + kLocal];
      __builtin_prefetch(&t_.bounds[v]);
      __builtin_prefetch(&f_.node_local[v]);
    }
    if (head_ + kFar < tail_) {
      const uint32_t v = f_.queue[head_ + kFar];
      if (f_.node_local) {
        if (const uint32_t p = t_.bounds[v].parent; p != kNoNode) __builtin_prefetch(&f_.node_local[p]);
      } else {
        __builtin_prefetch(&t_.bounds[v]);
      }
      const uint32_t at = f_.at(v);
      __builtin_prefetch(&f_.state[at]);
      __builtin_prefetch(&f_.kids[at]);
      __builtin_prefetch(&f_.filing[at]);
      if (f_.waiting) __builtin_prefetch(&f_.wait_on[at]);
    }
    if (head_ + kNear < tail_) {
      const uint32_t p = t_.bounds[f_.queue[head_ + kNear]].parent;
      if (p != kNoNode) {
        __builtin_prefetch(&t_.bounds[p]);
        __builtin_prefetch(&f_.kids[f_.at(p)]);
      }
    }
  }
  void begin_pending(uint32_t p);
  void end_pending(uint32_t p);
  bool consider(uint32_t v, bool phase_two);

  VertexFront& f_;
  const VertexTree& t_;
  const FrontParams& p_;
  FrontView view_;
  double reach_ = 0;
  double split_ = 0.5;

 public:
  bool bulk_ = false;  // refine_all / coarsen_all: everything is judged again next frame anyway

 private:
  uint32_t head_ = 0, tail_ = 0;
  bool phase_two_ = false;
  uint32_t limit_ = 0;
  float hysteresis_ = 1;
  uint32_t ops_ = 0;
  FrontStats stats_;
};

VertexFront::Bucket& Updater::bucket(int c, uint32_t b) { return f_.buckets[size_t(c) * (kBuckets + 1) + b]; }

// Takes v out of every bucket: its entries die with the old stamp.
void Updater::unfile(uint32_t v) {
  VertexFront::Filing& fl = f_.filing[f_.at(v)];
  ++fl.stamp;  // first: a compaction below must already see v's entries as dead
  for (int c = 0; c < 2; ++c) {
    if (fl.bucket[c] == kUnfiled) continue;
    const uint32_t b = fl.bucket[c];
    fl.bucket[c] = kUnfiled;
    VertexFront::Bucket& bk = bucket(c, b);
    --bk.live;
    if (bk.total > 4 * bk.live + 4 * VertexFront::kChunkEntries) compact(c, b);
  }
}

// Drops the dead entries of a bucket in place (the live ones keep their order) and returns the
// emptied chunks to the pool. Amortised: it runs when at least three quarters are dead.
void Updater::compact(int c, uint32_t b) {
  VertexFront::Bucket& bk = bucket(c, b);
  uint32_t w_chunk = bk.head, w = 0, kept = 0;
  for (uint32_t r_chunk = bk.head; r_chunk != kNoNode;) {
    VertexFront::Chunk& rc = f_.chunks[r_chunk];
    for (uint32_t i = 0; i < rc.count; ++i) {
      const uint32_t v = rc.node[i];
      if (f_.filing[f_.at(v)].stamp != rc.stamp[i]) continue;
      if (w == VertexFront::kChunkEntries) {
        f_.chunks[w_chunk].count = w;
        w_chunk = f_.chunks[w_chunk].next;
        w = 0;
      }
      f_.chunks[w_chunk].node[w] = v;
      f_.chunks[w_chunk].stamp[w] = rc.stamp[i];
      ++w, ++kept;
    }
    r_chunk = rc.next;
  }
  if (kept == 0) {
    release_chunks(bk.head);
    bk.head = kNoNode;
  } else {
    f_.chunks[w_chunk].count = w;
    release_chunks(f_.chunks[w_chunk].next);
    f_.chunks[w_chunk].next = kNoNode;
  }
  bk.total = bk.live = kept;
}

void Updater::release_chunks(uint32_t chunk) {
  while (chunk != kNoNode) {
    const uint32_t next = f_.chunks[chunk].next;
    f_.chunks[chunk].next = f_.free_chunk;
    f_.free_chunk = chunk;
    chunk = next;
  }
}

// A recycled chunk, else a fresh one: front_init reserves the pool for the worst case the
// compaction rule allows but touches none of it, so a front's memory follows its buckets'
// use, not that bound (about 25 MB of chunks per front, most never used). Should the reserve
// fall short, everything is compacted before the pool grows.
uint32_t Updater::take_chunk() {
  if (f_.free_chunk == kNoNode && f_.chunks.size() < f_.chunks.capacity()) {
    f_.chunks.emplace_back();  // within the reserve: no allocation
    return static_cast<uint32_t>(f_.chunks.size() - 1);
  }
  if (f_.free_chunk == kNoNode)
    for (int cc = 0; cc < 2; ++cc)
      for (uint32_t bb = 0; bb <= kBuckets; ++bb) compact(cc, bb);
  if (f_.free_chunk == kNoNode) {  // only a copied front (a vector copy keeps no reserve)
    f_.chunks.reserve(std::max<size_t>(64, 2 * f_.chunks.capacity()));
    f_.chunks.emplace_back();
    return static_cast<uint32_t>(f_.chunks.size() - 1);
  }
  const uint32_t k = f_.free_chunk;
  f_.free_chunk = f_.chunks[k].next;
  return k;
}

void Updater::append(int c, uint32_t b, uint32_t v) {
  VertexFront::Bucket& bk = bucket(c, b);
  if (bk.head == kNoNode || f_.chunks[bk.head].count == VertexFront::kChunkEntries) {
    const uint32_t k = take_chunk();
    f_.chunks[k].next = bk.head;
    f_.chunks[k].count = 0;
    bk.head = k;
  }
  VertexFront::Chunk& ch = f_.chunks[bk.head];
  ch.node[ch.count] = v;
  ch.stamp[ch.count] = f_.filing[f_.at(v)].stamp;
  ++ch.count;
  ++bk.live, ++bk.total;
  f_.filing[f_.at(v)].bucket[c] = static_cast<uint16_t>(b);
}

void Updater::file(uint32_t v, int c, double slack) {
  if (slack == kInf) return;  // that motion can never change the decision
  // Never into a bucket this frame already visited; far deadlines wait in the last bucket.
  const int64_t cur = f_.cursor[c];
  const double at = (f_.motion[c] + slack) / f_.bucket_width[c];
  int64_t abs_bucket =
      at < double(cur + kBuckets - 1) ? static_cast<int64_t>(std::floor(at)) : cur + kBuckets - 1;
  abs_bucket = std::max(abs_bucket, cur);
  append(c, static_cast<uint32_t>(abs_bucket % kBuckets), v);
}

void Updater::file(uint32_t v, double slack_eye, double slack_frustum) {
  unfile(v);
  if (slack_eye <= 0 || slack_frustum <= 0) return file_next_frame(v);
  file(v, 0, slack_eye);
  file(v, 1, slack_frustum);
}

// Retry next frame whether or not the view moves (blocked by a limit or a neighbour).
void Updater::file_next_frame(uint32_t v) {
  unfile(v);
  append(0, kBuckets, v);
}

// Every live node of bucket b of calendar c into the queue; the bucket's chunks go back.
void Updater::drain(uint32_t b, int c) {
  VertexFront::Bucket& bk = bucket(c, b);
  for (uint32_t k = bk.head; k != kNoNode; k = f_.chunks[k].next) {
    const VertexFront::Chunk& ch = f_.chunks[k];
    for (uint32_t i = 0; i < ch.count; ++i) {
      const uint32_t v = ch.node[i];
      VertexFront::Filing& fl = f_.filing[f_.at(v)];
      if (fl.stamp != ch.stamp[i]) continue;  // unfiled or filed again since
      fl.bucket[c] = kUnfiled;                 // this bucket is going away
      unfile(v);                               // judged now: out of the other calendar too
      push(v);
    }
  }
  release_chunks(bk.head);
  bk = VertexFront::Bucket{};
}

void Updater::stop_waiting(uint32_t v) {
  if (f_.waiting == 0) return;
  const uint32_t d = f_.wait_on[f_.at(v)];
  if (d == kNoNode) return;
  --f_.waiting;
  const uint32_t n = f_.wait_next[f_.at(v)], pr = f_.wait_prev[f_.at(v)];
  if (pr != kNoNode)
    f_.wait_next[f_.at(pr)] = n;
  else
    f_.wait_head[f_.at(d)] = n;
  if (n != kNoNode) f_.wait_prev[f_.at(n)] = pr;
  f_.wait_on[f_.at(v)] = kNoNode;
}

void Updater::wait_for(uint32_t v, uint32_t d) {
  stop_waiting(v);
  ++f_.waiting;
  f_.wait_on[f_.at(v)] = d;
  f_.wait_prev[f_.at(v)] = kNoNode;
  f_.wait_next[f_.at(v)] = f_.wait_head[f_.at(d)];
  if (f_.wait_next[f_.at(v)] != kNoNode) f_.wait_prev[f_.at(f_.wait_next[f_.at(v)])] = v;
  f_.wait_head[f_.at(d)] = v;
}

// d became active: whoever waited on it is judged again (this frame in phase one).
void Updater::wake(uint32_t d) {
  if (f_.waiting == 0) return;
  while (f_.wait_head[f_.at(d)] != kNoNode) {
    const uint32_t v = f_.wait_head[f_.at(d)];
    stop_waiting(v);
    if (f_.state[f_.at(v)] != VertexFront::kActive) continue;
    unfile(v);
    if (phase_two_)
      file_next_frame(v);
    else
      push(v);
  }
}

void Updater::split(uint32_t x) {
  const uint32_t i = x - t_.leaf_count;
  const uint32_t c1 = t_.children[2 * i], c2 = t_.children[2 * i + 1];
  if (f_.pending_count) {
    const uint32_t par = t_.parent[x];
    if (par != kNoNode && f_.pending_until[f_.inner_at(par)] >= 0) end_pending(par);
  }
  unfile(x);
  stop_waiting(x);
  // Active list: x out (its slot goes to c1), c2 appended.
  f_.state[f_.at(x)] = VertexFront::kSplit;
  const uint32_t slot = f_.active_pos[f_.at(x)];
  f_.active[slot] = c1;
  f_.active_pos[f_.at(c1)] = slot;
  f_.active_pos[f_.at(c2)] = f_.active_count;
  f_.active[f_.active_count++] = c2;
  f_.state[f_.at(c1)] = f_.state[f_.at(c2)] = VertexFront::kActive;
  f_.kids[f_.at(x)] = (f_.kids[f_.at(x)] & ~VertexFront::kKidsMask) | 2;
  if (const uint32_t par = t_.parent[x]; par != kNoNode) --f_.kids[f_.at(par)];
  // Faces around x take the child holding their corner's leaf.
  const uint32_t lo1 = t_.leaf_lo[c1], hi1 = t_.leaf_hi[c1];
  for (uint32_t k = t_.inc_offsets[i]; k < t_.inc_offsets[i + 1]; ++k) {
    const uint32_t s = f_.face_slot[f_.at_face(t_.inc_faces[k])];
    if (s == kNoNode) continue;
    const uint32_t r = t_.inc_corner[k] >> 2, j = t_.inc_corner[k] & 3;
    assert(f_.tri_indices[3 * size_t(s) + j] == x);
    f_.tri_indices[3 * size_t(s) + j] = r >= lo1 && r < hi1 ? c1 : c2;
  }
  // The split's own faces, appended to the packed triangle array.
  for (int k = 0; k < 2; ++k) {
    const uint32_t face = t_.split_faces[2 * i + k];
    if (face == kNoNode) continue;
    const uint32_t s = f_.tri_count++;
    f_.face_slot[f_.at_face(face)] = s;
    f_.tri_face[s] = face;
    const uint32_t lo2 = t_.leaf_lo[c2], hi2 = t_.leaf_hi[c2];
    for (int j = 0; j < 3; ++j) {
      const uint32_t r = t_.face_ranks[3 * size_t(face) + j];
      f_.tri_indices[3 * size_t(s) + j] = r >= lo1 && r < hi1   ? c1
                                          : r >= lo2 && r < hi2 ? c2
                                                                : t_.wings[2 * i + k];
    }
  }
  emit(x, FrontEventKind::split);
  ++stats_.splits;
  ++ops_;
  wake(c1);
  wake(c2);
}

void Updater::collapse(uint32_t p) {
  const uint32_t i = p - t_.leaf_count;
  const uint32_t c1 = t_.children[2 * i], c2 = t_.children[2 * i + 1];
  if (const uint32_t pi = f_.inner_at(p); f_.pending_until[pi] >= 0) {
    f_.pending_until[pi] = -1;
    const uint32_t at = f_.pending_pos[pi], last = f_.pending[--f_.pending_count];
    f_.pending[at] = last;
    f_.pending_pos[f_.inner_at(last)] = at;
  }
  // The split's faces leave; the last triangles fill their slots.
  for (int k = 0; k < 2; ++k) {
    const uint32_t face = t_.split_faces[2 * i + k];
    if (face == kNoNode) continue;
    const uint32_t s = f_.face_slot[f_.at_face(face)], last = --f_.tri_count;
    if (s != last) {
      const uint32_t moved = f_.tri_face[last];
      std::copy_n(&f_.tri_indices[3 * size_t(last)], 3, &f_.tri_indices[3 * size_t(s)]);
      f_.tri_face[s] = moved;
      f_.face_slot[f_.at_face(moved)] = s;
    }
    f_.face_slot[f_.at_face(face)] = kNoNode;
  }
  for (uint32_t k = t_.inc_offsets[i]; k < t_.inc_offsets[i + 1]; ++k) {
    const uint32_t s = f_.face_slot[f_.at_face(t_.inc_faces[k])];
    if (s == kNoNode) continue;
    const uint32_t j = t_.inc_corner[k] & 3;
    assert(f_.tri_indices[3 * size_t(s) + j] == c1 || f_.tri_indices[3 * size_t(s) + j] == c2);
    f_.tri_indices[3 * size_t(s) + j] = p;
  }
  unfile(c1);
  unfile(c2);
  stop_waiting(c1);
  stop_waiting(c2);
  f_.state[f_.at(c1)] = f_.state[f_.at(c2)] = VertexFront::kBelow;
  f_.state[f_.at(p)] = VertexFront::kActive;
  f_.kids[f_.at(p)] &= ~VertexFront::kKidsMask;
  if (const uint32_t par = t_.parent[p]; par != kNoNode && (++f_.kids[f_.at(par)], children_active(par))) {
    // par may merge now: its watching child (maybe p's sibling) judges it again.
    const uint32_t w = t_.children[2 * (par - t_.leaf_count)];
    if (w != p && !bulk_) {
      unfile(w);
      push(w);
    }
  }
  // Active list: p takes c1's slot, c2's slot is filled by the last entry.
  const uint32_t s1 = f_.active_pos[f_.at(c1)];
  f_.active[s1] = p;
  f_.active_pos[f_.at(p)] = s1;
  const uint32_t s2 = f_.active_pos[f_.at(c2)], last = f_.active[--f_.active_count];
  f_.active[s2] = last;
  f_.active_pos[f_.at(last)] = s2;
  emit(p, FrontEventKind::collapse);
  ++stats_.collapses;
  ++ops_;
  wake(p);
}

void Updater::begin_pending(uint32_t p) {
  const uint32_t i = f_.inner_at(p);
  f_.pending_until[i] = p_.time + p_.collapse_delay;
  f_.pending_pos[i] = f_.pending_count;
  f_.pending[f_.pending_count++] = p;
  emit(p, FrontEventKind::collapse_begin);
}

void Updater::end_pending(uint32_t p) {
  const uint32_t pi = f_.inner_at(p), i = p - t_.leaf_count;
  f_.pending_until[pi] = -1;
  const uint32_t at = f_.pending_pos[pi], last = f_.pending[--f_.pending_count];
  f_.pending[at] = last;
  f_.pending_pos[f_.inner_at(last)] = at;
  emit(p, FrontEventKind::collapse_cancel);
  // Its children waited on the pending list, unfiled: judge them again next frame.
  for (int j = 0; j < 2; ++j) {
    const uint32_t c = t_.children[2 * i + j];
    if (f_.state[f_.at(c)] == VertexFront::kActive) file_next_frame(c);
  }
}

// Splits v after splitting whatever its dependencies need (Berkey and Song's forced splits), depth first
// on an explicit stack. Forced splits only go to nodes made later in the build, so it ends.
bool Updater::force_split(uint32_t v) {
  uint32_t depth = 0;
  f_.stack[depth++] = v;
  while (depth > 0) {
    const uint32_t x = f_.stack[depth - 1];
    if (f_.state[f_.at(x)] != VertexFront::kActive) {  // split on the way by an earlier entry
      --depth;
      continue;
    }
    const uint32_t i = x - t_.leaf_count;
    const uint32_t missing = missing_dep(x);
    if (missing == kNoNode) {
      if ((p_.max_triangles && f_.tri_count + new_faces(x) > p_.max_triangles) ||
          (p_.max_operations && ops_ >= p_.max_operations)) {
        ++stats_.blocked;
        return false;
      }
      split(x);
      // New nodes are judged this frame; x itself may have been queued already (harmless).
      push(t_.children[2 * i]);
      push(t_.children[2 * i + 1]);
      --depth;
      continue;
    }
    // A dependency above the front cannot happen while x is active (see vertex_tree.h).
    assert(f_.state[f_.at(missing)] == VertexFront::kBelow);
    if (f_.state[f_.at(missing)] != VertexFront::kBelow) return false;
    uint32_t a = t_.parent[missing];
    while (f_.state[f_.at(a)] != VertexFront::kActive) a = t_.parent[a];
    f_.stack[depth++] = a;
  }
  return f_.state[f_.at(v)] == VertexFront::kSplit;
}

// One node's decision. Phase one collapses its parent (now, or deferred for geomorphing) and
// returns true when the node wants to split instead; phase two splits. Otherwise the node is
// filed again by its slack.
bool Updater::consider(uint32_t v, bool phase_two) {
  if (f_.state[f_.at(v)] != VertexFront::kActive) return false;
  unfile(v);
  ++stats_.visited;
  double se = kInf, sf = kInf;
  if (!t_.is_leaf(v)) {
    const Decision d = evaluate(t_, v, view_, f_.threshold, reach_, split_);
    if (d.refine) {
      if (!phase_two) return true;
      if (force_split(v)) return false;
      if (f_.state[f_.at(v)] == VertexFront::kActive) file_next_frame(v);  // blocked: try again next frame
      return false;
    }
    se = d.slack_eye;
    sf = d.slack_turn;
  }
  // Only the first child watches the parent's merge: one judgement per pair, not two.
  const uint32_t p = t_.bounds[v].parent;
  if (p != kNoNode && watches_parent(v) && children_active(p)) {
    const Decision dp = evaluate(t_, p, view_, f_.threshold / hysteresis_, reach_, split_);
    const bool pending = is_pending(p);
    if (!dp.refine) {
      if (phase_two || (p_.max_operations && ops_ >= p_.max_operations)) {
        file_next_frame(v);
        return false;
      }
      // Still waiting on the same finer neighbour: the collapse stays blocked, and the wait
      // list entry stands (no dependency scan, no relinking).
      if (f_.waiting && f_.wait_on[f_.at(v)] != kNoNode && f_.state[f_.at(f_.wait_on[f_.at(v)])] == VertexFront::kSplit) {
        file(v, se, sf);
        return false;
      }
      const uint32_t d = missing_dep(p);
      if (d != kNoNode) {
        // A finer neighbour blocks it: wait until that neighbour is active again, and meanwhile
        // keep watching v's own decision.
        if (f_.state[f_.at(d)] == VertexFront::kSplit) {
          wait_for(v, d);
          file(v, se, sf);
        } else {
          file_next_frame(v);
        }
        return false;
      }
      if (p_.collapse_delay > 0) {
        if (!pending) begin_pending(p);
        return false;  // the pending list finishes it
      }
      collapse(p);
      push(p);
      return false;
    }
    if (pending) end_pending(p);
    se = std::min(se, dp.slack_eye);
    sf = std::min(sf, dp.slack_turn);
  }
  file(v, se, sf);
  return false;
}

FrontStats Updater::run(const FrontView& view) {
  view_ = view;
  hysteresis_ = std::max(1.f, p_.hysteresis);
  stats_ = {};
  f_.event_count = 0;
  const double ex = view.eye[0] - f_.center[0], ey = view.eye[1] - f_.center[1],
               ez = view.eye[2] - f_.center[2];
  reach_ = std::sqrt(ex * ex + ey * ey + ez * ez) + f_.extent;

  // How far may any decision have moved since the last frame (see evaluate's slacks)?
  double moved = f_.pending_motion, turned = 0;
  bool full = !f_.has_view;
  if (!full) {
    const FrontView& o = f_.last_view;
    const double dx = view.eye[0] - o.eye[0], dy = view.eye[1] - o.eye[1], dz = view.eye[2] - o.eye[2];
    double offset_change = 0;
    for (int k = 0; k < 6; ++k) {
      const float* a = view.planes[k];
      const float* b = o.planes[k];
      const double nx = double(a[0]) - b[0], ny = double(a[1]) - b[1], nz = double(a[2]) - b[2];
      turned = std::max(turned, std::sqrt(nx * nx + ny * ny + nz * nz));
      const double off_a = double(a[0]) * view.eye[0] + double(a[1]) * view.eye[1] + double(a[2]) * view.eye[2] + a[3];
      const double off_b = double(b[0]) * o.eye[0] + double(b[1]) * o.eye[1] + double(b[2]) * o.eye[2] + b[3];
      offset_change = std::max(offset_change, std::abs(off_a - off_b));
    }
    const double travel = std::sqrt(dx * dx + dy * dy + dz * dz);
    moved += travel + offset_change;
    if (view.focal_pixels != o.focal_pixels) {
      const double k = double(o.focal_pixels) / view.focal_pixels;
      moved += 2 * reach_ * (std::max(k, 1 / k) - 1);
    }
    // Share frustum margins between the calendars as this frame's motion does (travel vs
    // turning at the object's distance), so neither expires much before the other.
    const double ec = std::sqrt(ex * ex + ey * ey + ez * ez);
    const double sweep = turned * std::max(ec, 0.1 * double(f_.extent));
    if (travel + sweep > 0) split_ = std::clamp(travel / (travel + sweep), 0.1, 0.9);
  }
  f_.pending_motion = 0;
  f_.has_view = true;
  f_.last_view = view;
  f_.motion[0] += moved;
  f_.motion[1] += turned;
  head_ = tail_ = 0;
  ops_ = 0;
  const uint32_t phase_one_end = static_cast<uint32_t>(f_.queue.size() / 2);
  limit_ = phase_one_end;

  // Expired buckets of both calendars, or (first frame, teleport) the whole front.
  int64_t last[2];
  for (int c = 0; c < 2; ++c) {
    last[c] = static_cast<int64_t>(std::floor(f_.motion[c] / f_.bucket_width[c]));
    if (last[c] - f_.cursor[c] + 1 >= int64_t(kBuckets)) full = true;
  }
  if (full) {
    for (uint32_t k = 0; k < f_.active_count; ++k) {
      unfile(f_.active[k]);
      push(f_.active[k]);
    }
  } else {
    for (int c = 0; c < 2; ++c)
      for (int64_t ab = f_.cursor[c]; ab <= last[c]; ++ab) drain(static_cast<uint32_t>(ab % kBuckets), c);
  }
  for (int c = 0; c < 2; ++c) f_.cursor[c] = std::max(f_.cursor[c], last[c] + 1);
  // Node ids follow space (Morton order per pass): judging them in id order walks memory
  // far more coherently than bucket order.
  sort_ids(f_.queue.data(), tail_, f_.queue.data() + phase_one_end, t_.node_count());
  drain(kBuckets, 0);

  stats_.full_pass = full;

  // Deferred collapses whose time has come: collapse if still legal and wanted.
  for (uint32_t k = f_.pending_count; k-- > 0;) {
    const uint32_t p = f_.pending[k];
    if (f_.pending_until[f_.inner_at(p)] > p_.time) continue;
    if (children_active(p) && deps_active(p) &&
        !evaluate(t_, p, view_, f_.threshold / hysteresis_, reach_, split_).refine &&
        !(p_.max_operations && ops_ >= p_.max_operations)) {
      collapse(p);
      push(p);
    } else {
      end_pending(p);
      const uint32_t i = p - t_.leaf_count;
      for (int j = 0; j < 2; ++j) {
        const uint32_t c = t_.children[2 * i + j];
        if (f_.state[f_.at(c)] == VertexFront::kActive) {
          unfile(c);
          push(c);
        }
      }
    }
  }

  // Phase one: collapses (they free budget for phase two's splits); wanted splits move on.
  uint32_t split_tail = phase_one_end;
  while (head_ < tail_) {
    prefetch_ahead();
    const uint32_t v = f_.queue[head_++];
    if (consider(v, false)) f_.queue[split_tail++] = v;
  }
  // Phase two: splits, breadth first so the budget spreads evenly over the view.
  head_ = phase_one_end;
  tail_ = split_tail;
  limit_ = static_cast<uint32_t>(f_.queue.size());
  phase_two_ = true;
  while (head_ < tail_) consider(f_.queue[head_++], true);

  if (p_.target_triangles > 0)
    front_set_threshold(f_, front_next_threshold(f_.threshold, f_.tri_count, p_.target_triangles, p_));
  stats_.active_tris = f_.tri_count;
  stats_.active_vertices = f_.active_count;
  return stats_;
}

}  // namespace

FrontView front_view_of(const View& view, const float position[3], float scale, float yaw) {
  // R_y(yaw) as a quaternion: (0, sin(yaw / 2), 0, cos(yaw / 2)).
  const float q[4] = {0, std::sin(0.5f * yaw), 0, std::cos(0.5f * yaw)};
  return front_view_of(view, position, scale, q);
}

FrontView front_view_of(const View& view, const float position[3], float scale, const float rotation[4]) {
  // The planes in double (eye_planes_of): extracting them from the float clip matrix leaves
  // the far plane (far / near ~ 1e5) noisy by ~1e-3 of its distance, and front_update reads
  // frame-to-frame plane motion as view motion.
  using V = glm::dvec3;
  const EyePlanes planes = eye_planes_of(view);
  const V& eye = planes.eye;
  const V pos(position[0], position[1], position[2]);
  const V* normals = planes.normal;
  const double* offsets = planes.offset;

  FrontView out;
  const double inv = scale != 0 ? 1.0 / scale : 1.0;
  // Object = R^-1 (world - position) / scale, R the unit quaternion (conjugate undoes it).
  glm::dquat q{static_cast<double>(rotation[3]), static_cast<double>(rotation[0]), static_cast<double>(rotation[1]),
               static_cast<double>(rotation[2])};
  const double qn = glm::length(q);
  q = qn > 0 ? q / qn : glm::dquat(1, 0, 0, 0);
  const glm::dquat qi = glm::conjugate(q);
  auto to_object_dir = [&](const V& d) { return qi * d; };
  const V eye_o = to_object_dir(eye - pos) * inv;
  for (int k = 0; k < 3; ++k) out.eye[k] = static_cast<float>(eye_o[k]);
  for (int k = 0; k < 6; ++k) {
    const V n = glm::normalize(to_object_dir(normals[k]));
    // n_w . (R s p + pos - eye) + c = s (n_o . p) + n_w . (pos - eye) + c, divided by s.
    const double w = (glm::dot(normals[k], pos - eye) + offsets[k]) * inv;
    for (int j = 0; j < 3; ++j) out.planes[k][j] = static_cast<float>(n[j]);
    out.planes[k][3] = static_cast<float>(w);
  }
  // Error and distance scale alike, so projected error needs no scale here.
  out.focal_pixels = focal_pixels(view);
  return out;
}

size_t front_memory_bytes(const VertexFront& f) {
  auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  return bytes(f.state) + bytes(f.kids) + bytes(f.active) + bytes(f.active_pos) + bytes(f.tri_indices) +
         bytes(f.tri_face) + bytes(f.face_slot) + bytes(f.filing) + bytes(f.buckets) + f.chunks.size() * sizeof(f.chunks[0]) +
         bytes(f.wait_on) + bytes(f.wait_next) + bytes(f.wait_prev) + bytes(f.wait_head) + bytes(f.pending_until) +
         bytes(f.pending) + bytes(f.pending_pos) + bytes(f.queue) + bytes(f.stack) + bytes(f.events);
}

float front_next_threshold(float threshold, uint64_t triangles, uint64_t target, const FrontParams& p) {
  if (target == 0) return threshold;
  const double ratio = double(triangles) / double(target);
  double k = 1;
  if (ratio > 1.0)
    k = std::min(1.5, std::sqrt(ratio));
  else if (ratio < 0.85)
    k = std::max(0.8, std::sqrt(std::max(ratio, 1e-6)) / std::sqrt(0.92));
  return std::clamp(static_cast<float>(threshold * k), p.min_threshold, p.max_threshold);
}

void front_set_threshold(VertexFront& f, float threshold) {
  if (threshold == f.threshold || !(threshold > 0)) return;
  if (f.has_view) {
    // A critical distance e * focal / tau scales with 1 / tau and is at most the view's reach.
    double d2 = 0;
    for (int k = 0; k < 3; ++k) d2 += double(f.last_view.eye[k] - f.center[k]) * (f.last_view.eye[k] - f.center[k]);
    const double reach = std::sqrt(d2) + f.extent;
    const double kk = double(threshold) / f.threshold;
    f.pending_motion += 2 * reach * (std::max(kk, 1 / kk) - 1);
  }
  f.threshold = threshold;
}

void front_init(VertexFront& f, const VertexTree& t, float threshold) { front_init(f, t, threshold, nullptr, kSharedRegion); }

void front_init(VertexFront& f, const VertexTree& t, float threshold, std::span<const uint8_t> regions,
                uint8_t region) {
  if (regions.empty()) return front_init(f, t, threshold, nullptr, kSharedRegion);
  uint32_t count = 0;
  for (uint8_t r : regions)
    if (r != kSharedRegion) count = std::max<uint32_t>(count, r + 1u);
  front_init(f, t, threshold,
             std::make_shared<const RegionNumbering>(
                 number_regions(t, std::vector<uint8_t>(regions.begin(), regions.end()), std::max(count, region + 1u))),
             region);
}

namespace {

// Binds the front to its numbering and sizes the arrays each local id indexes.
void size_front(VertexFront& f, const VertexTree& t, std::shared_ptr<const RegionNumbering> numbering, uint8_t region) {
  f.numbering = std::move(numbering);
  f.region = f.numbering ? region : kSharedRegion;
  f.node_local = f.numbering ? f.numbering->local.data() : nullptr;
  f.face_local = f.numbering ? f.numbering->local_face.data() : nullptr;
  const bool whole = !f.numbering;
  const uint32_t nodes = whole ? t.node_count() : f.numbering->nodes[region];
  const uint32_t faces = whole ? t.face_count : f.numbering->faces[region];
  f.local_leaves = whole ? t.leaf_count : f.numbering->leaves[region];
  const uint32_t inner = nodes - f.local_leaves;
  f.state.assign(nodes, VertexFront::kBelow);
  f.kids.assign(nodes, 0);
  f.active.assign(nodes, 0);
  f.active_pos.assign(nodes, kNoNode);
  f.filing.assign(nodes, VertexFront::Filing{});
  f.wait_on.assign(nodes, kNoNode);
  f.wait_next.assign(nodes, kNoNode);
  f.wait_prev.assign(nodes, kNoNode);
  f.wait_head.assign(nodes, kNoNode);
  f.pending_until.assign(inner, -1.0);
  f.pending.assign(inner, 0);
  f.pending_pos.assign(inner, 0);
  f.tri_indices.assign(3 * size_t(faces), 0);
  f.tri_face.assign(faces, kNoNode);
  f.face_slot.assign(faces, kNoNode);
  f.queue.assign(8 * size_t(nodes) + 8, 0);  // phase one, then phase two from the middle
  f.stack.assign(nodes + 1, 0);
  f.events.assign(3 * size_t(inner) + 16, FrontEvent{});
}

}  // namespace

void front_init(VertexFront& f, const VertexTree& t, float threshold, std::shared_ptr<const RegionNumbering> numbering,
                uint8_t region) {
  const uint32_t n = t.node_count();
  assert(!numbering || (numbering->local.size() == n && region < numbering->nodes.size()));
  assert(t.bounds.size() == n && "pack_vertex_bounds(tree) first");
  size_front(f, t, std::move(numbering), region);
  for (uint32_t i = 0; i < t.interior_count(); ++i)
    if (const uint32_t c = t.children[2 * size_t(i)]; f.covers(c)) f.kids[f.at(c)] = VertexFront::kFirstChild;
  f.active_count = f.tri_count = 0;
  f.threshold = threshold;
  f.buckets.assign(2 * (kBuckets + 1), VertexFront::Bucket{});
  // Live entries: at most two per active node (no more active nodes than leaves); a bucket is
  // compacted before its entries pass 4 x live + 4 chunks; each bucket wastes under a chunk.
  {
    const size_t entries = 4 * 2 * size_t(f.local_leaves) + 4 * size_t(VertexFront::kChunkEntries) * f.buckets.size();
    const size_t count = entries / VertexFront::kChunkEntries + 2 * f.buckets.size() + 16;
    f.chunks.clear();
    f.chunks.reserve(count);
    f.free_chunk = kNoNode;
  }
  f.motion[0] = f.motion[1] = 0;
  f.cursor[0] = f.cursor[1] = 0;
  f.pending_motion = 0;
  f.has_view = false;
  f.waiting = 0;
  f.pending_count = 0;
  f.event_count = 0;

  // Bounds of every node position, for the reach of view changes.
  float lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  for (uint32_t v = 0; v < n; ++v)
    for (int k = 0; k < 3; ++k) {
      const float x = t.positions[3 * size_t(v) + k];
      lo[k] = v == 0 ? x : std::min(lo[k], x);
      hi[k] = v == 0 ? x : std::max(hi[k], x);
    }
  double extent = 0;
  for (int k = 0; k < 3; ++k) f.center[k] = 0.5f * (lo[k] + hi[k]);
  for (uint32_t v = 0; v < n; ++v) {
    double d2 = 0;
    for (int k = 0; k < 3; ++k) {
      const double d = t.positions[3 * size_t(v) + k] - f.center[k];
      d2 += d * d;
    }
    extent = std::max(extent, std::sqrt(d2) + t.radius[v]);
  }
  f.extent = static_cast<float>(extent);
  f.bucket_width[0] = std::max(extent, 1e-6) * 1e-3;
  f.bucket_width[1] = 1.5e-4;  // radians: a horizon of 0.6 rad of turning

  // Base mesh: the roots and the faces nobody's split makes, corners mapped to their roots.
  for (uint32_t v = 0; v < n; ++v)
    if (t.parent[v] == kNoNode && f.covers(v)) {
      f.state[f.at(v)] = VertexFront::kActive;
      f.active_pos[f.at(v)] = f.active_count;
      f.active[f.active_count++] = v;
    }
  for (uint32_t face = 0; face < t.face_count; ++face) {
    if (t.face_owner[face] != kNoNode) continue;
    if (!f.covers_face(t, face)) continue;
    const uint32_t s = f.tri_count++;
    f.face_slot[f.at_face(face)] = s;
    f.tri_face[s] = face;
    for (int j = 0; j < 3; ++j) {
      uint32_t v = t.face_leaves[3 * size_t(face) + j];
      while (t.parent[v] != kNoNode) v = t.parent[v];
      f.tri_indices[3 * size_t(s) + j] = v;
    }
  }
  // Every node of the front is judged on the first update (a full pass: nothing to file).
}

FrontStats front_update(VertexFront& front, const VertexTree& tree, const FrontView& view,
                        const FrontParams& params) {
  FrontStats s = Updater(front, tree, params).run(view);
  s.threshold = front.threshold;
  return s;
}

void front_refine_all(VertexFront& f, const VertexTree& t) {
  FrontParams p;
  Updater u(f, t, p);
  u.bulk_ = true;
  // Later nodes first: every dependency of a node was made before it, and its parent after
  // it, so when a node's turn comes its dependencies are active.
  for (uint32_t v = t.node_count(); v-- > t.leaf_count;)
    if (f.covers(v) && f.state[f.at(v)] == VertexFront::kActive) u.split(v);
  for (uint32_t k = 0; k < f.active_count; ++k) {
    u.unfile(f.active[k]);
    u.file_next_frame(f.active[k]);
  }
  f.event_count = 0;
}

void front_coarsen_all(VertexFront& f, const VertexTree& t) {
  FrontParams p;
  Updater u(f, t, p);
  u.bulk_ = true;
  for (uint32_t v = t.leaf_count; v < t.node_count(); ++v) {
    const uint32_t i = v - t.leaf_count;
    if (f.covers(v) && f.state[f.at(v)] == VertexFront::kSplit && f.state[f.at(t.children[2 * i])] == VertexFront::kActive &&
        f.state[f.at(t.children[2 * i + 1])] == VertexFront::kActive)
      u.collapse(v);
  }
  for (uint32_t k = 0; k < f.active_count; ++k) {
    u.unfile(f.active[k]);
    u.file_next_frame(f.active[k]);
  }
  f.event_count = 0;
}

bool check_front(const VertexFront& f, const VertexTree& t, EdgeCheck edges, std::string* message) {
  auto fail = [&](std::string text) {
    if (message) *message = std::move(text);
    return false;
  };
  const uint32_t n = t.node_count();
  // Active list and states agree.
  uint32_t active_states = 0;
  for (uint32_t v = 0; v < n; ++v) active_states += f.covers(v) && f.state[f.at(v)] == VertexFront::kActive;
  if (active_states != f.active_count)
    return fail(std::to_string(active_states) + " nodes are active but the list holds " +
                std::to_string(f.active_count));
  for (uint32_t k = 0; k < f.active_count; ++k) {
    const uint32_t v = f.active[k];
    if (v >= n || !f.covers(v) || f.state[f.at(v)] != VertexFront::kActive || f.active_pos[f.at(v)] != k)
      return fail("active list entry " + std::to_string(k) + " (node " + std::to_string(v) +
                  ") is not active there");
  }
  const bool all = !f.numbering;
  auto leaf_mine = [&](uint32_t l) { return f.covers(l); };
  auto face_mine = [&](uint32_t face) { return f.covers_face(t, face); };
  if (!all && edges == EdgeCheck::closed) edges = EdgeCheck::oriented;  // a region is open at its seam
  // Every leaf has exactly one active ancestor-or-self: a proper front.
  for (uint32_t l = 0; l < t.leaf_count; ++l) {
    if (!leaf_mine(l)) continue;
    uint32_t count = 0;
    for (uint32_t v = l; v != kNoNode; v = t.parent[v]) count += f.state[f.at(v)] == VertexFront::kActive;
    if (count != 1)
      return fail("leaf " + std::to_string(l) + " has " + std::to_string(count) + " active ancestors");
  }
  std::vector<uint64_t> directed;
  directed.reserve(3 * size_t(f.tri_count));
  for (uint32_t s = 0; s < f.tri_count; ++s) {
    const uint32_t face = f.tri_face[s];
    const std::string at = "triangle " + std::to_string(s) + " (face " + std::to_string(face) + ")";
    if (face >= t.face_count || !face_mine(face) || f.face_slot[f.at_face(face)] != s)
      return fail(at + " is not the face's slot");
    const uint32_t* tri = &f.tri_indices[3 * size_t(s)];
    for (int j = 0; j < 3; ++j) {
      if (tri[j] >= n || !f.covers(tri[j]))
        return fail(at + " references vertex " + std::to_string(tri[j]) + " of " + std::to_string(n) +
                    (tri[j] < n ? " outside the front's region" : ""));
      if (f.state[f.at(tri[j])] != VertexFront::kActive)
        return fail(at + " references inactive vertex " + std::to_string(tri[j]));
      uint32_t v = t.face_leaves[3 * size_t(face) + j];
      while (f.state[f.at(v)] != VertexFront::kActive) v = t.parent[v];
      if (v != tri[j])
        return fail(at + " corner " + std::to_string(j) + " is " + std::to_string(tri[j]) +
                    " but its leaf's active ancestor is " + std::to_string(v));
    }
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) return fail(at + " is degenerate");
    for (int j = 0; j < 3; ++j) directed.push_back(uint64_t(tri[j]) << 32 | tri[(j + 1) % 3]);
  }
  uint32_t face_slots = 0;
  for (uint32_t face = 0; face < t.face_count; ++face) face_slots += face_mine(face) && f.face_slot[f.at_face(face)] != kNoNode;

  if (face_slots != f.tri_count)
    return fail(std::to_string(face_slots) + " faces have slots but " + std::to_string(f.tri_count) +
                " triangles are active");
  // A face is active exactly when its corners are distinct (no face missing).
  for (uint32_t face = 0; face < t.face_count; ++face) {
    if (!face_mine(face) || f.face_slot[f.at_face(face)] != kNoNode) continue;  // another region's face: not ours to index
    uint32_t c[3];
    for (int j = 0; j < 3; ++j) {
      uint32_t v = t.face_leaves[3 * size_t(face) + j];
      while (f.state[f.at(v)] != VertexFront::kActive) v = t.parent[v];
      c[j] = v;
    }
    if (c[0] != c[1] && c[1] != c[2] && c[0] != c[2])
      return fail("face " + std::to_string(face) + " has three distinct active corners but is not drawn");
  }
  // The calendars' books: each bucket's live count is the entries that are still current,
  // every filed node sits in the bucket it says, and only active nodes are filed.
  if (!f.buckets.empty()) {
    std::vector<uint8_t> seen(2 * size_t(n), 0);
    for (int c = 0; c < 2; ++c)
      for (uint32_t b = 0; b <= kBuckets; ++b) {
        const VertexFront::Bucket& bk = f.buckets[size_t(c) * (kBuckets + 1) + b];
        uint32_t live = 0, total = 0;
        for (uint32_t k = bk.head; k != kNoNode; k = f.chunks[k].next)
          for (uint32_t i = 0; i < f.chunks[k].count; ++i, ++total) {
            const uint32_t v = f.chunks[k].node[i];
            if (v >= n || !f.covers(v))
              return fail("calendar " + std::to_string(c) + " holds node " + std::to_string(v) + " outside the front");
            if (f.filing[f.at(v)].stamp != f.chunks[k].stamp[i]) continue;
            if (f.filing[f.at(v)].bucket[c] != b || seen[2 * size_t(v) + c]++)
              return fail("calendar " + std::to_string(c) + " bucket " + std::to_string(b) + " holds node " +
                          std::to_string(v) + " which is filed elsewhere");
            if (f.state[f.at(v)] != VertexFront::kActive)
              return fail("calendar holds node " + std::to_string(v) + " which is not active");
            ++live;
          }
        if (live != bk.live || total != bk.total)
          return fail("calendar " + std::to_string(c) + " bucket " + std::to_string(b) + " counts " +
                      std::to_string(bk.live) + " live of " + std::to_string(bk.total) + " but holds " +
                      std::to_string(live) + " of " + std::to_string(total));
      }
    for (uint32_t v = 0; v < n; ++v)
      for (int c = 0; c < 2; ++c)
        if (f.covers(v) && f.filing[f.at(v)].bucket[c] != kUnfiled && !seen[2 * size_t(v) + c])
          return fail("node " + std::to_string(v) + " is filed in a bucket that does not hold it");
  }
  if (edges == EdgeCheck::corners) return true;
  std::sort(directed.begin(), directed.end());
  for (size_t k = 1; k < directed.size(); ++k)
    if (directed[k] == directed[k - 1])
      return fail("edge " + std::to_string(directed[k] >> 32) + "->" +
                  std::to_string(directed[k] & 0xffffffffu) +
                  " is used twice in one direction (orientation flip or non-manifold edge)");
  if (edges == EdgeCheck::closed) {
    for (uint64_t e : directed) {
      const uint64_t rev = (e << 32) | (e >> 32);
      if (!std::binary_search(directed.begin(), directed.end(), rev))
        return fail("edge " + std::to_string(e >> 32) + "-" + std::to_string(e & 0xffffffffu) +
                    " has one face on a closed mesh (crack or T-junction)");
    }
  }
  return true;
}

uint32_t front_stale_decisions(const VertexFront& f, const VertexTree& t, const FrontView& view,
                               const FrontParams& params, std::string* message) {
  const float hysteresis = std::max(1.f, params.hysteresis);
  auto retrying = [&](uint32_t v) { return f.filing[f.at(v)].bucket[0] == kBuckets; };
  uint32_t stale = 0;
  auto note = [&](std::string text) {
    if (stale++ == 0 && message) *message = std::move(text);
  };
  for (uint32_t k = 0; k < f.active_count; ++k) {
    const uint32_t v = f.active[k];
    if (t.is_leaf(v) || retrying(v)) continue;
    if (evaluate(t, v, view, f.threshold, kInf, 0.5).refine)
      note("active node " + std::to_string(v) + " wants to split");
  }
  for (uint32_t p = t.leaf_count; p < t.node_count(); ++p) {
    const uint32_t i = p - t.leaf_count;
    const uint32_t c1 = t.children[2 * i], c2 = t.children[2 * i + 1];
    if (!f.covers(p) || f.state[f.at(p)] != VertexFront::kSplit || f.state[f.at(c1)] != VertexFront::kActive ||
        f.state[f.at(c2)] != VertexFront::kActive || retrying(c1) || retrying(c2) || f.pending_until[f.inner_at(p)] >= 0)
      continue;
    bool deps = true;
    for (uint32_t k = t.dep_offsets[i]; k < t.dep_offsets[i + 1]; ++k)
      deps = deps && f.state[f.at(t.deps[k])] == VertexFront::kActive;
    if (deps && !evaluate(t, p, view, f.threshold / hysteresis, kInf, 0.5).refine)
      note("split node " + std::to_string(p) + " wants to merge");
  }
  return stale;
}

uint32_t front_compact_mesh(std::span<float> positions, std::span<uint32_t> indices, const VertexFront& f,
                            const VertexTree& t, std::span<const float> shown) {
  assert(positions.size() >= 3 * size_t(f.active_count) && indices.size() >= 3 * size_t(f.tri_count));
  const float* src = shown.empty() ? t.positions.data() : shown.data();
  for (uint32_t k = 0; k < f.active_count; ++k)
    std::copy_n(src + 3 * size_t(f.active[k]), 3, positions.data() + 3 * size_t(k));
  // active_pos maps a node id to its slot in the active list: the compact vertex index.
  for (size_t k = 0; k < 3 * size_t(f.tri_count); ++k) indices[k] = f.active_pos[f.at(f.tri_indices[k])];
  return f.tri_count;
}

uint32_t fronts_compact_mesh(std::span<float> positions, std::span<uint32_t> indices, std::span<uint32_t> node_index,
                             std::span<const VertexFront* const> fronts, const VertexTree& t,
                             std::span<const float> shown, uint32_t* vertex_count) {
  const float* src = shown.empty() ? t.positions.data() : shown.data();
  uint32_t nv = 0, nt = 0;
  for (size_t r = 0; r < fronts.size(); ++r) {
    const VertexFront& f = *fronts[r];
    for (uint32_t k = 0; k < f.active_count; ++k) {
      const uint32_t v = f.active[k];
      if (r > 0 && f.numbering && f.numbering->region[v] == kSharedRegion) continue;
      assert(positions.size() >= 3 * size_t(nv + 1));
      std::copy_n(src + 3 * size_t(v), 3, positions.data() + 3 * size_t(nv));
      node_index[v] = nv++;
    }
  }
  for (const VertexFront* f : fronts) {
    assert(indices.size() >= 3 * size_t(nt + f->tri_count));
    for (size_t k = 0; k < 3 * size_t(f->tri_count); ++k) indices[3 * size_t(nt) + k] = node_index[f->tri_indices[k]];
    nt += f->tri_count;
  }
  if (vertex_count) *vertex_count = nv;
  return nt;
}

uint32_t front_compact_uvs(std::span<float> uvs, const VertexFront& f, const VertexTree& t,
                           std::span<const float> shown_uvs) {
  assert(!t.uvs.empty() && uvs.size() >= 2 * size_t(f.active_count));
  const float* src = shown_uvs.empty() ? t.uvs.data() : shown_uvs.data();
  for (uint32_t k = 0; k < f.active_count; ++k) std::copy_n(src + 2 * size_t(f.active[k]), 2, uvs.data() + 2 * size_t(k));
  return f.active_count;
}

uint32_t fronts_compact_uvs(std::span<float> uvs, std::span<const VertexFront* const> fronts, const VertexTree& t,
                            std::span<const float> shown_uvs) {
  assert(!t.uvs.empty());
  const float* src = shown_uvs.empty() ? t.uvs.data() : shown_uvs.data();
  uint32_t nv = 0;
  // The vertex order of fronts_compact_mesh: fixed leaves once, from the first front.
  for (size_t r = 0; r < fronts.size(); ++r) {
    const VertexFront& f = *fronts[r];
    for (uint32_t k = 0; k < f.active_count; ++k) {
      const uint32_t v = f.active[k];
      if (r > 0 && f.numbering && f.numbering->region[v] == kSharedRegion) continue;
      assert(uvs.size() >= 2 * size_t(nv + 1));
      std::copy_n(src + 2 * size_t(v), 2, uvs.data() + 2 * size_t(nv++));
    }
  }
  return nv;
}

uint32_t front_compact_column(std::span<float> out, size_t width, const VertexFront& f,
                              std::span<const float> per_node) {
  assert(out.size() >= width * size_t(f.active_count));
  for (uint32_t k = 0; k < f.active_count; ++k) {
    assert(width * size_t(f.active[k]) + width <= per_node.size());
    std::copy_n(per_node.data() + width * size_t(f.active[k]), width, out.data() + width * size_t(k));
  }
  return f.active_count;
}

uint32_t fronts_compact_nodes(std::span<uint32_t> nodes, std::span<const VertexFront* const> fronts) {
  uint32_t nv = 0;
  for (size_t r = 0; r < fronts.size(); ++r) {
    const VertexFront& f = *fronts[r];
    for (uint32_t k = 0; k < f.active_count; ++k) {
      const uint32_t v = f.active[k];
      if (r > 0 && f.numbering && f.numbering->region[v] == kSharedRegion) continue;
      assert(nv < nodes.size());
      nodes[nv++] = v;
    }
  }
  return nv;
}

uint32_t fronts_compact_column(std::span<float> out, size_t width, std::span<const VertexFront* const> fronts,
                               std::span<const float> per_node) {
  uint32_t nv = 0;
  // The vertex order of fronts_compact_mesh: fixed leaves once, from the first front.
  for (size_t r = 0; r < fronts.size(); ++r) {
    const VertexFront& f = *fronts[r];
    for (uint32_t k = 0; k < f.active_count; ++k) {
      const uint32_t v = f.active[k];
      if (r > 0 && f.numbering && f.numbering->region[v] == kSharedRegion) continue;
      assert(out.size() >= width * size_t(nv + 1) && width * size_t(v) + width <= per_node.size());
      std::copy_n(per_node.data() + width * size_t(v), width, out.data() + width * size_t(nv++));
    }
  }
  return nv;
}

bool check_triangles(std::span<const uint32_t> indices, uint32_t vertex_count, EdgeCheck edges,
                     std::string* message) {
  auto fail = [&](std::string text) {
    if (message) *message = std::move(text);
    return false;
  };
  if (indices.size() % 3 != 0) return fail(std::to_string(indices.size()) + " indices, not a multiple of 3");
  std::vector<uint64_t> directed;
  directed.reserve(indices.size());
  for (size_t s = 0; s < indices.size() / 3; ++s) {
    const uint32_t* tri = &indices[3 * s];
    for (int j = 0; j < 3; ++j)
      if (tri[j] >= vertex_count)
        return fail("triangle " + std::to_string(s) + " references vertex " + std::to_string(tri[j]) +
                    " of " + std::to_string(vertex_count));
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
      return fail("triangle " + std::to_string(s) + " is degenerate");
    for (int j = 0; j < 3; ++j) directed.push_back(uint64_t(tri[j]) << 32 | tri[(j + 1) % 3]);
  }
  if (edges == EdgeCheck::corners) return true;
  std::sort(directed.begin(), directed.end());
  for (size_t k = 1; k < directed.size(); ++k)
    if (directed[k] == directed[k - 1])
      return fail("edge " + std::to_string(directed[k] >> 32) + "->" +
                  std::to_string(directed[k] & 0xffffffffu) +
                  " is used twice in one direction (orientation flip or non-manifold edge)");
  if (edges == EdgeCheck::closed)
    for (uint64_t e : directed)
      if (!std::binary_search(directed.begin(), directed.end(), (e << 32) | (e >> 32)))
        return fail("edge " + std::to_string(e >> 32) + "-" + std::to_string(e & 0xffffffffu) +
                    " has one face on a closed mesh (crack or T-junction)");
  return true;
}

bool triangles_closed(std::span<const uint32_t> indices) {
  std::vector<uint64_t> directed;
  directed.reserve(indices.size());
  for (size_t s = 0; s + 2 < indices.size(); s += 3)
    for (int j = 0; j < 3; ++j) directed.push_back(uint64_t(indices[s + j]) << 32 | indices[s + (j + 1) % 3]);
  std::sort(directed.begin(), directed.end());
  for (uint64_t e : directed)
    if (!std::binary_search(directed.begin(), directed.end(), (e << 32) | (e >> 32))) return false;
  return !directed.empty();
}

EdgeCheck edge_check_of(std::span<const uint32_t> indices) {
  std::vector<uint64_t> directed;
  directed.reserve(indices.size());
  for (size_t s = 0; s + 2 < indices.size(); s += 3)
    for (int j = 0; j < 3; ++j) directed.push_back(uint64_t(indices[s + j]) << 32 | indices[s + (j + 1) % 3]);
  std::sort(directed.begin(), directed.end());
  if (std::adjacent_find(directed.begin(), directed.end()) != directed.end()) return EdgeCheck::corners;
  for (uint64_t e : directed)
    if (!std::binary_search(directed.begin(), directed.end(), (e << 32) | (e >> 32)))
      return EdgeCheck::oriented;
  return directed.empty() ? EdgeCheck::oriented : EdgeCheck::closed;
}

}  // namespace lod
