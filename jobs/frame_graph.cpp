// FrameGraph: wiring of the per-frame stages into one tbb::flow::graph.
//
//   view -> visibility -> importance -> selection -> vdlod -> geomorph -> publish
//
// Each node is a continue_node that coordinates one stage; the data-parallel stages split
// the objects into fixed chunks of `grain` and run the runtime/ function per chunk inside a
// parallel_for. Chunk boundaries do not depend on the thread count and every per-chunk
// result lands in its own slot, merged in chunk order, so 1, 2 or N threads give
// bit-identical frames. Selection is global (one budget) and runs serially, on the visible
// objects that importance compacts in object order. vdlod updates the vertex front of every
// visible view-dependent object (a model with a vertex hierarchy), one task per object, its
// triangle target being the level selection gave it (its share of M); geomorph advances the
// morph factor of level changes and the per-vertex morphs of splits and collapses, and writes
// each view-dependent object's compact, geomorphed mesh into the frame.
#include "jobs/frame_graph.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/flow_graph.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <cassert>
#include <chrono>
#include <memory>
#include <optional>
#include <span>

#include "runtime/geomorph.h"
#include "runtime/importance.h"
#include "runtime/vertex_front.h"
#include "runtime/visibility.h"

namespace lod {
namespace {

using Clock = std::chrono::steady_clock;
using Node = tbb::flow::continue_node<tbb::flow::continue_msg, tbb::flow::lightweight>;

// ThreadSanitizer cannot see the synchronisation inside libtbb (a library not built with
// it), so it would report every hand-over between a spawning thread and a task. These mark
// the edges TBB guarantees: what precedes a spawn happens before the task runs, and what a
// task does happens before the wait that joins it. No-ops in other builds.
#if defined(__SANITIZE_THREAD__)
#define LOD_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define LOD_TSAN 1
#endif
#endif
// One address for every graph: a task must acquire before it reads its own captures.
#ifdef LOD_TSAN
extern "C" void __tsan_acquire(void* addr);
extern "C" void __tsan_release(void* addr);
char tbb_edge;
void before_spawn() { __tsan_release(&tbb_edge); }
void task_begins() { __tsan_acquire(&tbb_edge); }
void task_ends() { __tsan_release(&tbb_edge); }
void after_join() { __tsan_acquire(&tbb_edge); }
#else
inline void before_spawn() {}
inline void task_begins() {}
inline void task_ends() {}
inline void after_join() {}
#endif

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

// What publish sums per chunk before the chunks are merged in order.
struct ChunkTotals {
  uint64_t tris_in_view = 0;
  uint64_t tris_selected = 0;
  uint64_t level_cost = 0;
  std::array<uint32_t, kHistogramLevels> histogram{};
};

template <class T>
std::span<T> sub(std::vector<T>& v, size_t begin, size_t end) {
  return std::span<T>(v.data() + begin, end - begin);
}
template <class T>
std::span<const T> sub(const std::vector<T>& v, size_t begin, size_t end) {
  return std::span<const T>(v.data() + begin, end - begin);
}

struct StageEntry {
  const char* name;
  const char* does;
};
// The node/edge table: one node per stage, a chain of edges in this order.
constexpr StageEntry kStageTable[kStageCount] = {
    {"view", "frustum planes, focal length, budget"},
    {"visibility", "cull_spheres, parallel over chunks"},
    {"importance",
     "measure_objects + minima, importance_weights + choose_initial_levels, compaction, gather_selection, "
     "parallel"},
    {"selection", "lower_under_budget: heap over the visible set, serial (its gather pass runs in importance)"},
    {"vdlod", "front_update per visible view-dependent object, parallel over objects"},
    {"geomorph", "level morph factors; vertex morphs + compact meshes of vd objects, parallel"},
    {"publish", "totals, levels -> prev_level, parallel"},
};

}  // namespace

// Regions of one view-dependent object updated as separate tasks (more than threads, so work
// stealing evens out regions in and out of view).
constexpr uint32_t kMaxVdRegions = 8;

struct FrameGraph::Impl {
  const Scene& scene;
  FrameGraphOptions options;
  size_t count = 0;  // objects
  size_t grain = 1;
  size_t chunks = 0;

  ObjectState state;
  // Visible objects compacted in object order (slot k <-> Frame::objects[k]), so that the
  // serial selection streams over the visible set only, without a branch per object.
  std::vector<float> visible_weight;
  std::vector<uint32_t> visible_model;
  std::vector<uint8_t> all_ones;  // the `visible` column of the compacted set
  std::vector<HeapEntry> heap;           // selection: one entry per visible slot
  SelectionTables selection_tables;      // per level: SLC of the next step, lowerable
  std::vector<uint32_t> selection_counts;  // chunks x level_total: visible objects per level
  std::vector<uint32_t> selection_total;   // level_total: the chunks' counts summed
  std::vector<uint32_t> chunk_visible;  // visibility: visible objects per chunk
  std::vector<uint32_t> chunk_offset;   // first compacted slot of each chunk
  std::vector<ViewMinima> chunk_minima;
  std::vector<ChunkTotals> chunk_totals;
  // Publish counts objects per chain level (index into the ModelTable's per-level arrays),
  // in kCountLanes interleaved copies so that consecutive increments of one level do not
  // wait on each other; totals follow from the counts and these per-level tables.
  static constexpr size_t kCountLanes = 4;
  size_t level_total = 0;                // levels of all models
  std::vector<uint32_t> level_counts;    // chunks x kCountLanes x level_total
  std::vector<uint32_t> full_triangles;  // per level: triangles of its model's level 0
  uint32_t visible_total = 0;

  // View-dependent objects: one front and one morph state per object of a model with a
  // vertex hierarchy, in object order.
  struct VdObject {
    uint32_t object = 0;
    uint32_t model = 0;
    EdgeCheck edges = EdgeCheck::corners;  // what its full mesh passes, so every front must
    // One front per region of its model's hierarchy (vertex_tree_regions): regions update as
    // separate tasks and share one pixel threshold.
    std::vector<VertexFront> fronts;
    std::vector<FrontStats> region_stats;
    std::vector<uint32_t> node_index;  // fronts_compact_mesh scratch (several regions only)
    VertexMorph morph;
    std::vector<float> shown;  // geomorphed positions, xyz per hierarchy node
    FrontStats stats;          // summed over the regions
    uint32_t moving = 0;
    int32_t slot = -1;  // this frame: index in Frame::objects, -1 = not visible
  };
  std::vector<VdObject> vd;
  std::vector<uint32_t> vd_visible;  // this frame: indices into vd
  struct VdTask {
    uint32_t vd_index, region;
    uint32_t cap;  // max_triangles of this front this frame
  };
  std::vector<VdTask> vd_tasks;                   // this frame: one per (visible vd object, region)
  std::vector<std::vector<uint8_t>> vd_regions;   // per model: region per hierarchy node
  std::vector<uint32_t> vd_shared;                // per model: nodes active in every region
  std::vector<double> morph_start;   // per object: when its level last changed (seconds)
  std::vector<uint8_t> morph_from;   // per object: the level it morphs from
  std::vector<uint8_t> model_blends;  // per model: discrete levels with morph targets (not vd)
  struct MorphTotals {
    uint32_t morphing = 0;
    uint64_t extra_tris = 0;
  };
  std::vector<MorphTotals> chunk_morph;  // geomorph: per chunk
  uint64_t last_morph_extra = 0;         // last frame's Frame::tris_morph_extra
  uint64_t morph_reserve = 0;            // this frame: held back from M for blends

  // Per frame.
  View view;
  Frustum frustum{};
  float focal = 1;
  Frame* out = nullptr;
  ViewMinima minima{};
  SelectionResult selected;
  std::array<double, kStageCount> stage_ms{};
  uint64_t frame_index = 0;

  tbb::task_arena arena;
  std::optional<tbb::flow::graph> graph;
  std::vector<std::unique_ptr<Node>> nodes;  // kStageCount, in stage order; destroyed before the graph

  Impl(const Scene& s, const FrameGraphOptions& o)
      : scene(s),
        options(o),
        count(s.objects.size()),
        grain(std::max<uint32_t>(1, o.grain)),
        chunks((count + grain - 1) / grain),
        arena(o.threads == 0 ? tbb::task_arena::automatic : static_cast<int>(o.threads)) {
    state.resize(count);
    std::fill(state.prev_level.begin(), state.prev_level.end(), uint8_t{0});
    std::fill(state.was_visible.begin(), state.was_visible.end(), uint8_t{0});
    visible_weight.resize(count);
    visible_model.resize(count);
    all_ones.assign(count, 1);
    heap.resize(count);
    chunk_visible.resize(chunks);
    chunk_offset.resize(chunks);
    chunk_minima.resize(chunks);
    chunk_totals.resize(chunks);
    const ModelTable& models = scene.models;
    level_total = models.triangles.size();
    level_counts.resize(chunks * kCountLanes * level_total);
    selection_tables = build_selection_tables(models);
    selection_counts.resize(chunks * level_total);
    selection_total.resize(level_total);
    full_triangles.resize(level_total);
    for (size_t m = 0; m < models.model_count(); ++m)
      for (size_t k = 0; k < models.level_count[m]; ++k)
        full_triangles[models.first_level[m] + k] = models.triangles[models.first_level[m]];
    morph_start.assign(count, -1e300);
    morph_from.assign(count, 0);
    chunk_morph.resize(chunks);
    model_blends.resize(models.model_count());
    for (size_t m = 0; m < models.model_count(); ++m)
      model_blends[m] = scene.chains[m].hierarchy.empty() && can_morph_levels(scene.chains[m]);
    std::vector<EdgeCheck> edges(models.model_count(), EdgeCheck::corners);
    for (size_t m = 0; m < models.model_count(); ++m) {
      const LodChain& chain = scene.chains[m];
      if (chain.hierarchy.empty()) continue;
      const LodLevel& l0 = chain.levels[0];
      edges[m] = edge_check_of(std::span(chain.indices.data() + l0.first_index, l0.index_count));
    }
    vd_regions.resize(models.model_count());
    vd_shared.assign(models.model_count(), 0);
    for (size_t m = 0; m < models.model_count(); ++m) {
      const VertexTree& tree = scene.chains[m].hierarchy;
      if (tree.empty()) continue;
      // Regions only pay off when the hierarchy was built in parts: a one-part tree's extra
      // regions are tiny components, kept together in one front.
      if (vertex_tree_regions(vd_regions[m], tree, kMaxVdRegions) < 2) {
        vd_regions[m].clear();
        continue;
      }
      for (uint8_t r : vd_regions[m]) vd_shared[m] += r == kSharedRegion;
    }
    for (uint32_t id = 0; id < count; ++id) {
      const uint32_t m = scene.objects.model[id];
      const VertexTree& tree = scene.chains[m].hierarchy;
      if (tree.empty()) continue;
      VdObject& obj = vd.emplace_back();
      obj.object = id;
      obj.model = m;
      obj.edges = edges[m];
      const float tau = std::max(o_pixel_error(), 0.05f);
      if (vd_regions[m].empty()) {
        front_init(obj.fronts.emplace_back(), tree, tau);
      } else {
        uint32_t regions = 0;
        for (uint8_t r : vd_regions[m])
          if (r != kSharedRegion) regions = std::max<uint32_t>(regions, r + 1u);
        obj.fronts.resize(regions);
        for (uint32_t r = 0; r < regions; ++r) front_init(obj.fronts[r], tree, tau, vd_regions[m], uint8_t(r));
        obj.node_index.assign(tree.node_count(), 0);
      }
      obj.region_stats.resize(obj.fronts.size());
      vertex_morph_init(obj.morph, tree, options.geomorph_seconds);
      obj.shown = tree.positions;
    }
    vd_visible.reserve(vd.size());
    // Built inside the arena, the graph attaches to it: its tasks run on these threads.
    arena.execute([&] { build(); });
  }

  void build() {
    graph.emplace();
    nodes.reserve(kStageCount);
    for (size_t i = 0; i < kStageCount; ++i) {
      const Stage stage = static_cast<Stage>(i);
      nodes.push_back(std::make_unique<Node>(*graph, [this, stage](const tbb::flow::continue_msg&) {
        task_begins();
        const auto t0 = Clock::now();
        try {
          if (options.stage_hook) options.stage_hook(stage);
          run_stage(stage);
        } catch (...) {
          task_ends();
          throw;
        }
        stage_ms[static_cast<size_t>(stage)] = ms_between(t0, Clock::now());
        task_ends();
      }));
    }
    for (size_t i = 0; i + 1 < kStageCount; ++i) tbb::flow::make_edge(*nodes[i], *nodes[i + 1]);
  }

  void run_stage(Stage stage) {
    switch (stage) {
      case Stage::view:
        return stage_view();
      case Stage::visibility:
        return stage_visibility();
      case Stage::importance:
        return stage_importance();
      case Stage::selection:
        return stage_selection();
      case Stage::vdlod:
        return stage_vdlod();
      case Stage::geomorph:
        return stage_geomorph();
      case Stage::publish:
        return stage_publish();
      case Stage::count:
        break;
    }
    assert(false);
  }

  // Runs body(chunk, begin, end) for every chunk; one task per chunk.
  template <class Body>
  void for_chunks(const Body& body) {
    before_spawn();
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, chunks, 1),
        [&](const tbb::blocked_range<size_t>& r) {
          task_begins();
          for (size_t c = r.begin(); c != r.end(); ++c) body(c, c * grain, std::min(count, (c + 1) * grain));
          task_ends();
        },
        tbb::simple_partitioner());
    after_join();
  }

  void stage_view() {
    frustum = frustum_of(view);
    focal = focal_pixels(view);
  }

  void stage_visibility() {
    const ObjectSet& o = scene.objects;
    for_chunks([&](size_t c, size_t b, size_t e) {
      chunk_visible[c] =
          static_cast<uint32_t>(cull_spheres(sub(state.visible, b, e), sub(o.cx, b, e), sub(o.cy, b, e),
                                             sub(o.cz, b, e), sub(o.radius, b, e), frustum));
    });
    // Exclusive prefix sum over the chunks: where each chunk's visible objects go.
    visible_total = 0;
    for (size_t c = 0; c < chunks; ++c) {
      chunk_offset[c] = visible_total;
      visible_total += chunk_visible[c];
    }
  }

  void stage_importance() {
    const ObjectSet& o = scene.objects;
    for_chunks([&](size_t c, size_t b, size_t e) {
      chunk_minima[c] = measure_objects(sub(state.distance, b, e), sub(state.area, b, e),
                                        sub(state.visible, b, e), sub(o.cx, b, e), sub(o.cy, b, e),
                                        sub(o.cz, b, e), sub(o.radius, b, e), view.eye, focal);
    });
    // min() is order-free, but merging in chunk order keeps even that obvious.
    minima = empty_minima();
    for (const ViewMinima& m : chunk_minima) minima = merge_minima(minima, m);
    assert(minima.visible == visible_total);

    Frame& f = *out;
    f.objects.resize(visible_total);
    f.levels.resize(visible_total);
    if (visible_total == 0) return;
    const InitialLevelParams params{focal, options.pixel_error, options.hysteresis};
    for_chunks([&](size_t c, size_t b, size_t e) {
      importance_weights(sub(state.weight, b, e), sub(state.visible, b, e), sub(state.distance, b, e),
                         sub(state.area, b, e), minima);
      choose_initial_levels(sub(state.level, b, e), sub(state.visible, b, e), sub(state.prev_level, b, e),
                            sub(state.was_visible, b, e), sub(state.distance, b, e), sub(o.scale, b, e),
                            sub(o.model, b, e), scene.models, params);
      // Compact this chunk's visible objects into their slots. Branch-free (visibility is
      // random in object order): every object is written to the next free slot, which only
      // advances past visible ones. Stopping once the chunk's slots are full keeps the
      // writes inside them; every object left is then invisible.
      const uint32_t end_slot = chunk_offset[c] + chunk_visible[c];
      uint32_t slot = chunk_offset[c];
      uint32_t* __restrict ids = f.objects.data();
      uint8_t* __restrict levels = f.levels.data();
      for (size_t i = b; i < e && slot < end_slot; ++i) {
        ids[slot] = static_cast<uint32_t>(i);
        levels[slot] = state.level[i];
        visible_weight[slot] = state.weight[i];
        visible_model[slot] = o.model[i];
        slot += state.visible[i];
      }
      assert(slot == end_slot);
      // Selection's streaming pass on this chunk's slots (heap keys, visible per level), so
      // that only the heap work stays serial.
      const size_t b0 = chunk_offset[c], n0 = chunk_visible[c];
      const std::span<uint32_t> counts(selection_counts.data() + c * level_total, level_total);
      std::fill(counts.begin(), counts.end(), 0u);
      gather_selection(std::span<HeapEntry>(heap.data() + b0, n0), counts,
                       std::span<const uint8_t>(f.levels.data() + b0, n0),
                       std::span<const uint8_t>(all_ones.data() + b0, n0),
                       std::span<const float>(visible_weight.data() + b0, n0),
                       std::span<const uint32_t>(visible_model.data() + b0, n0), static_cast<uint32_t>(b0),
                       scene.models, selection_tables);
    });
  }

  // On the compacted visible set: the same result as on the whole range (selection breaks
  // ties by position, and compaction keeps object order), with less to stream through.
  void stage_selection() {
    const size_t v = visible_total;
    std::fill(selection_total.begin(), selection_total.end(), 0u);
    for (size_t c = 0; c < chunks; ++c) {
      const uint32_t* counts = selection_counts.data() + c * level_total;
      for (size_t k = 0; k < level_total; ++k) selection_total[k] += counts[k];
    }
    // Blending objects draw their finer level: what last frame's blends added is held back
    // from M (at most half of it, so blends never starve the selection), so that what is
    // drawn, not only what is selected, stays near M.
    SelectionParams so = options.selection;
    morph_reserve = 0;
    if (so.count == BudgetCount::triangles && so.reserve_blends) {
      morph_reserve = std::min(last_morph_extra, so.budget / 2);
      so.budget -= morph_reserve;
    }
    selected = lower_under_budget(
        std::span<uint8_t>(out->levels.data(), v), std::span<const uint8_t>(all_ones.data(), v),
        std::span<const float>(visible_weight.data(), v), std::span<const uint32_t>(visible_model.data(), v),
        scene.models, so, selection_total, std::span<HeapEntry>(heap.data(), v));
  }

  float o_pixel_error() const { return options.pixel_error; }
  double now() const { return double(frame_index) * options.frame_seconds; }

  // One task per visible view-dependent object; fronts are independent, so the result does
  // not depend on the thread count.
  void stage_vdlod() {
    const Frame& f = *out;
    vd_visible.clear();
    // Both lists are in object order: one merge finds each vd object's visible slot.
    size_t k = 0;
    for (uint32_t i = 0; i < vd.size(); ++i) {
      VdObject& o = vd[i];
      while (k < visible_total && f.objects[k] < o.object) ++k;
      o.slot = (k < visible_total && f.objects[k] == o.object) ? static_cast<int32_t>(k) : -1;
      if (o.slot >= 0) vd_visible.push_back(i);
    }
    const ObjectSet& objs = scene.objects;
    const ModelTable& models = scene.models;
    auto share_of = [&](const VdObject& o) {
      // Its share of the budget: the triangles of the level selection gave it.
      return std::max<uint32_t>(models.triangles[models.first_level[o.model] + f.levels[o.slot]], 1);
    };
    vd_tasks.clear();
    for (uint32_t j : vd_visible) {
      const VdObject& o = vd[j];
      const uint32_t share = share_of(o);
      const uint64_t cap = share + share / 10 + 16;
      // Regions share the cap: each keeps what it had and may grow by an equal part of the
      // room left, so their sum never passes it.
      uint64_t used = 0;
      for (const VertexFront& fr : o.fronts) used += fr.tri_count;
      const uint64_t room = used < cap ? (cap - used) / o.fronts.size() : 0;
      for (uint32_t r = 0; r < o.fronts.size(); ++r) {
        const uint64_t c = o.fronts.size() == 1 ? cap : std::max<uint64_t>(o.fronts[r].tri_count + room, 1);
        vd_tasks.push_back({j, r, static_cast<uint32_t>(std::min<uint64_t>(c, UINT32_MAX))});
      }
    }
    if (vd_tasks.empty()) return;
    before_spawn();
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, vd_tasks.size(), 1), [&](const tbb::blocked_range<size_t>& range) {
          task_begins();
          for (size_t j = range.begin(); j != range.end(); ++j) {
            VdObject& o = vd[vd_tasks[j].vd_index];
            const uint32_t r = vd_tasks[j].region;
            const float pos[3] = {objs.x[o.object], objs.y[o.object], objs.z[o.object]};
            const FrontView fv = front_view_of(view, pos, objs.scale[o.object], objs.yaw[o.object]);
            FrontParams p;
            p.time = now();
            p.collapse_delay = options.geomorph_seconds;
            p.hysteresis = options.vd_hysteresis;
            p.max_triangles = vd_tasks[j].cap;
            // One front: its own feedback; regions: feedback once per object after the join.
            if (o.fronts.size() == 1) p.target_triangles = share_of(o);
            const VertexTree& tree = scene.chains[o.model].hierarchy;
            o.region_stats[r] = front_update(o.fronts[r], tree, fv, p);
            vertex_morph_apply(o.morph, tree, o.fronts[r].frame_events(), p.time);
          }
          task_ends();
        });
    after_join();
    for (uint32_t j : vd_visible) {
      VdObject& o = vd[j];
      if (o.fronts.size() == 1) {
        o.stats = o.region_stats[0];
        continue;
      }
      FrontStats sum;
      for (const FrontStats& st : o.region_stats) {
        sum.splits += st.splits, sum.collapses += st.collapses, sum.visited += st.visited;
        sum.blocked += st.blocked, sum.active_tris += st.active_tris;
        sum.full_pass = sum.full_pass || st.full_pass;
      }
      FrontParams p;
      const float next = front_next_threshold(o.fronts[0].threshold, sum.active_tris, share_of(o), p);
      for (VertexFront& fr : o.fronts) front_set_threshold(fr, next);
      sum.threshold = next;
      o.stats = sum;
    }
  }

  // Level changes restart a per-object morph factor from the level last selected (newly
  // visible objects appear settled; a reversal mid-blend continues backwards); view-dependent
  // objects get their geomorphed vertices and compact mesh into the frame.
  void stage_geomorph() {
    Frame& f = *out;
    f.morph.resize(visible_total);
    f.from_levels.resize(visible_total);
    const double t = now();
    const ModelTable& models = scene.models;
    // Per object and independent: parallel over each chunk's visible slots.
    for_chunks([&](size_t c, size_t, size_t) {
      const uint32_t end_slot = chunk_offset[c] + chunk_visible[c];
      MorphTotals totals;
      for (uint32_t k = chunk_offset[c]; k < end_slot; ++k) {
        const uint32_t id = f.objects[k];
        const uint8_t level = f.levels[k];
        if (state.was_visible[id] && state.prev_level[id] != level) {
          // Going back to the level it was leaving, mid-blend, runs the same blend backwards
          // from where it is (no jump); any other change starts from the level last selected.
          const float m = morph_factor(t, morph_start[id], options.geomorph_seconds);
          const bool reverses = m < 1 && morph_from[id] == level;
          morph_start[id] = reverses ? t - double(1 - m) * options.geomorph_seconds : t;
          morph_from[id] = state.prev_level[id];
        }
        if (!state.was_visible[id]) morph_start[id] = -1e300;
        f.morph[k] = morph_factor(t, morph_start[id], options.geomorph_seconds);
        const uint32_t model = visible_model[k];
        const bool blends = f.morph[k] < 1 && model_blends[model] && morph_from[id] != level;
        f.from_levels[k] = blends ? morph_from[id] : level;
        if (blends) {
          const uint32_t first = models.first_level[model];
          ++totals.morphing;
          totals.extra_tris += models.triangles[first + std::min(level, morph_from[id])] - models.triangles[first + level];
        }
      }
      chunk_morph[c] = totals;
    });
    f.morphing = 0;
    f.tris_morph_extra = 0;
    for (const MorphTotals& m : chunk_morph) f.morphing += m.morphing, f.tris_morph_extra += m.extra_tris;
    last_morph_extra = f.tris_morph_extra;
    f.vd_objects.resize(vd_visible.size());
    uint32_t vertices = 0, indices = 0;
    f.vd_active_tris = f.vd_splits = f.vd_collapses = 0;
    for (size_t j = 0; j < vd_visible.size(); ++j) {
      const VdObject& o = vd[vd_visible[j]];
      VdObjectFrame& e = f.vd_objects[j];
      e.object = o.object;
      // Fixed seam vertices are active in every region but written once.
      uint32_t active = 0, tris = 0;
      for (const VertexFront& fr : o.fronts) active += fr.active_count, tris += fr.tri_count;
      e.first_vertex = vertices;
      e.vertex_count = active - uint32_t(o.fronts.size() - 1) * vd_shared[o.model];
      e.first_index = indices;
      e.index_count = 3 * tris;
      e.splits = o.stats.splits;
      e.collapses = o.stats.collapses;
      e.threshold = o.stats.threshold;
      e.closed = o.edges == EdgeCheck::closed;
      e.oriented = o.edges != EdgeCheck::corners;
      vertices += e.vertex_count;
      indices += e.index_count;
      f.vd_active_tris += tris;
      f.vd_splits += o.stats.splits;
      f.vd_collapses += o.stats.collapses;
    }
    f.vd_positions.resize(3 * size_t(vertices));
    f.vd_indices.resize(indices);
    if (vd_visible.empty()) return;
    before_spawn();
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, vd_visible.size(), 1), [&](const tbb::blocked_range<size_t>& r) {
          task_begins();
          for (size_t j = r.begin(); j != r.end(); ++j) {
            VdObject& o = vd[vd_visible[j]];
            VdObjectFrame& e = f.vd_objects[j];
            const VertexTree& tree = scene.chains[o.model].hierarchy;
            const std::span positions(f.vd_positions.data() + 3 * size_t(e.first_vertex), 3 * size_t(e.vertex_count));
            const std::span tris(f.vd_indices.data() + e.first_index, e.index_count);
            e.moving = 0;
            for (const VertexFront& fr : o.fronts)
              e.moving += static_cast<uint32_t>(vertex_morph_positions(o.shown, o.morph, fr.vertices(), t));
            if (o.fronts.size() == 1) {
              front_compact_mesh(positions, tris, o.fronts[0], tree, o.shown);
            } else {
              const VertexFront* fronts[kMaxVdRegions];
              for (size_t k = 0; k < o.fronts.size(); ++k) fronts[k] = &o.fronts[k];
              uint32_t written = 0;
              fronts_compact_mesh(positions, tris, o.node_index, std::span(fronts, o.fronts.size()), tree,
                                  o.shown, &written);
              assert(written == e.vertex_count);
            }
          }
          task_ends();
        });
    after_join();
  }

  void stage_publish() {
    Frame& f = *out;
    const ModelTable& models = scene.models;
    for_chunks([&](size_t c, size_t b, size_t e) {
      // Temporal state for the next frame: who was visible, at which level.
      std::copy(state.visible.begin() + b, state.visible.begin() + e, state.was_visible.begin() + b);
      uint32_t* counts = level_counts.data() + c * kCountLanes * level_total;
      std::fill(counts, counts + kCountLanes * level_total, 0u);
      const uint32_t first_slot = chunk_offset[c], end_slot = first_slot + chunk_visible[c];
      const uint32_t* first_level = models.first_level.data();
      for (uint32_t k = first_slot; k < end_slot; ++k) {
        const uint8_t level = f.levels[k];
        state.prev_level[f.objects[k]] = level;
        ++counts[(k % kCountLanes) * level_total + first_level[visible_model[k]] + level];
      }
      ChunkTotals t;
      for (size_t at = 0; at < level_total; ++at) {
        uint64_t n = 0;
        for (size_t lane = 0; lane < kCountLanes; ++lane) n += counts[lane * level_total + at];
        if (n == 0) continue;
        const int32_t l = models.level_l[at];
        t.tris_in_view += n * full_triangles[at];
        t.tris_selected += n * models.triangles[at];
        t.level_cost += n << std::clamp(l, 0, 63);
        t.histogram[static_cast<size_t>(std::clamp<int32_t>(l, 0, kHistogramLevels - 1))] +=
            static_cast<uint32_t>(n);
      }
      chunk_totals[c] = t;
    });

    f.object_count = static_cast<uint32_t>(count);
    f.visible = visible_total;
    f.tris_in_view = f.tris_selected = f.level_cost = 0;
    f.level_histogram.fill(0);
    for (const ChunkTotals& t : chunk_totals) {
      f.tris_in_view += t.tris_in_view;
      f.tris_selected += t.tris_selected;
      f.level_cost += t.level_cost;
      for (size_t l = 0; l < kHistogramLevels; ++l) f.level_histogram[l] += t.histogram[l];
    }
    f.budget = options.selection.budget;
    f.budget_morph_reserve = morph_reserve;
    f.coarsest_cost = selected.coarsest_cost;
    f.over_budget = selected.over_budget;
    f.lowered_steps = selected.lowered_steps;
  }

  // Forgets last frame's levels so that the next frame starts from scratch.
  void reset_temporal_state() {
    last_morph_extra = 0;
    std::fill(state.prev_level.begin(), state.prev_level.end(), uint8_t{0});
    std::fill(state.was_visible.begin(), state.was_visible.end(), uint8_t{0});
  }
};

FrameGraph::FrameGraph(const Scene& scene, const FrameGraphOptions& options)
    : impl_(std::make_unique<Impl>(scene, options)) {}

FrameGraph::~FrameGraph() = default;

void FrameGraph::run(const View& view, Frame& out) {
  Impl& m = *impl_;
  const auto t0 = Clock::now();
  m.view = view;
  m.out = &out;
  m.stage_ms.fill(0);
  out.index = ++m.frame_index;
  out.view = view;
  before_spawn();
  try {
    m.arena.execute([&] {  // may run on a worker when the arena has no free slot
      task_begins();
      m.nodes.front()->try_put(tbb::flow::continue_msg());
      m.graph->wait_for_all();
      task_ends();
    });
  } catch (...) {
    after_join();
    m.graph->reset();
    m.reset_temporal_state();
    m.out = nullptr;
    throw;
  }
  after_join();
  m.out = nullptr;
  out.stage_ms = m.stage_ms;
  out.total_ms = ms_between(t0, Clock::now());
}

void FrameGraph::set_budget(uint64_t budget) { impl_->options.selection.budget = budget; }

const FrameGraphOptions& FrameGraph::options() const { return impl_->options; }

std::string FrameGraph::dot() {
  std::string s = "digraph frame_graph {\n  rankdir=LR;\n  node [shape=box, fontname=\"Helvetica\"];\n";
  for (const StageEntry& e : kStageTable) {
    s += "  ";
    s += e.name;
    s += " [label=\"";
    s += e.name;
    s += "\\n";
    s += e.does;
    s += "\"];\n";
  }
  for (size_t i = 0; i + 1 < kStageCount; ++i) {
    s += "  ";
    s += kStageTable[i].name;
    s += " -> ";
    s += kStageTable[i + 1].name;
    s += ";\n";
  }
  s += "}\n";
  return s;
}

}  // namespace lod
