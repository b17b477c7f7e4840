// FrameGraph: the node table of the per-frame stages, wired into one tbb::flow::graph.
//
// Every node names the columns it reads and writes (kNodes); a node depends on an earlier one
// when one writes what the other reads or writes, the edges are those dependencies with the
// implied ones removed, and the DOT comes from the same table. Adding a stage is one row of
// the table and one member that runs it.
//
// The data-parallel nodes split the objects into fixed chunks of `grain` and run the runtime/
// function per chunk inside a parallel_for. Chunk boundaries do not depend on the thread count
// and every per-chunk result lands in its own slot, merged in chunk order, so 1, 2 or N threads
// give bit-identical frames. Selection is global (one budget) and runs serially, on the visible
// objects that importance compacts in object order.
#include "jobs/frame_graph.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/flow_graph.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <chrono>
#include <limits>
#include <memory>
#include <optional>
#include <span>

#include "jobs/tsan_annotations.h"
#include "jobs/hlod_read_failures.h"
#include "jobs/hlod_stream.h"
#include "runtime/geomorph.h"
#include "runtime/hlod_asset.h"
#include "runtime/importance.h"
#include "runtime/level_blend.h"
#include "runtime/budget_split.h"
#include "runtime/derived_columns.h"
#include "runtime/benefit_cost_selection.h"
#include "runtime/level_caps.h"
#include "runtime/selection_oracle.h"
#include "runtime/object_controls.h"
#include "runtime/occlusion.h"
#include "runtime/scene_hlod_cut.h"
#include "runtime/selection_quality.h"
#include "runtime/vd_share.h"
#include "runtime/vertex_front.h"
#include "runtime/vertex_normals.h"
#include "runtime/view_masks.h"
#include "runtime/visibility.h"
#include "runtime/world_bounds.h"

namespace lod {
namespace {

using Clock = std::chrono::steady_clock;
// Not lightweight: a lightweight node runs inside its predecessor's task, so two successors
// of one node would run one after the other.
using Node = tbb::flow::continue_node<tbb::flow::continue_msg>;

// ThreadSanitizer cannot see the synchronisation inside libtbb (a library not built with it),
// so the graph marks the hand-overs TBB guarantees, each on a byte of its own (SyncPoints): a
// node acquires what each of its predecessors released when it finished (a root, what the
// frame's caller released before starting the graph); a loop's chunks acquire what their node
// released before the loop, and the node what they released before the join. Data that
// crosses between two nodes without an edge of the table is therefore reported. No-ops in
// other builds.
using detail::tsan_acquire;
using detail::tsan_release;

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

// The clock ROAM's time limit reads ([[terrain]] max_ms).
double steady_now_ms(const void*) {
  return std::chrono::duration<double, std::milli>(Clock::now().time_since_epoch()).count();
}

// What publish sums per chunk before the chunks are merged in order.
struct ChunkTotals {
  uint64_t tris_in_view = 0;
  uint64_t tris_selected = 0;
  uint64_t level_cost = 0;
  uint32_t culled = 0;         // entries at a culled level (0 triangles)
  uint32_t level_changes = 0;  // entries visible last frame at another level
  SelectionQuality quality;
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

// Columns the nodes share (bits of NodeSpec::reads / writes).
enum Column : uint32_t {
  kObjects = 1u << 0,     // the store's objects and options (commit writes them)
  kBounds = 1u << 1,      // world spheres
  kControls = 1u << 2,    // per-object rows, min levels, error scales, priorities, never_cull
  kViews = 1u << 3,       // frusta and focal lengths
  kVisibility = 1u << 4,  // per-view visibility, view masks, per-chunk visible counts
  kEntries = 1u << 5,     // the frame's per-entry columns and the compacted selection inputs
  kLevels = 1u << 6,      // the frame's levels (initial, then selected)
  kBlend = 1u << 7,       // the store's blend state, the frame's morph factors and from-levels
  kFronts = 1u << 8,      // view-dependent fronts and vertex morphs
  kVdMesh = 1u << 9,      // the frame's view-dependent meshes
  kTotals = 1u << 10,     // the frame's totals
  kHistory = 1u << 11,    // the store's last-frame levels and visibility
  kPlacing = 1u << 12,    // the frame's handles, transforms and view masks per entry
  kHlod = 1u << 13,       // HLOD cuts and the pager, the frame's hlod columns
  kSceneHlod = 1u << 14,  // the scene HLOD cut, the frame's scene proxy columns
  kTerrain = 1u << 15,    // the terrain's ROAM state, the frame's terrain columns
};
constexpr const char* kColumnNames[] = {"objects", "bounds", "controls", "views",  "visibility", "entries", "levels",
                                        "blend",   "fronts", "vd_mesh",  "totals", "history",    "placing",
                                        "hlod",    "scene_hlod", "terrain"};

}  // namespace

// Regions of one view-dependent object updated as separate tasks (more than threads, so work
// stealing evens out regions in and out of view).
constexpr uint32_t kMaxVdRegions = 8;

struct FrameGraph::Impl {
  struct NodeSpec {
    Stage stage;
    const char* does;
    uint32_t reads, writes;
    void (Impl::*run)();
  };
  static const NodeSpec kNodes[];
  static constexpr size_t kNodeCount = kStageCount;

  FrameGraphOptions options;
  std::shared_ptr<const ModelSet> set;
  // Derived from the model set.
  LevelCaps caps;                        // selection rows: models, then capped prefixes
  SelectionTables selection_tables;      // per row level
  size_t level_total = 0;                // levels of all rows
  std::vector<uint32_t> full_triangles;  // per row level: triangles of its model's level 0
  std::vector<uint8_t> model_blends;     // per model: discrete levels with morph targets (not vd)
  struct VdModel {
    EdgeCheck edges = EdgeCheck::corners;  // what its full mesh passes, so every front must
    // Region-local numbering of the hierarchy (null: one front), shared by every object's fronts.
    std::shared_ptr<const RegionNumbering> regions;
    uint32_t region_count = 1;
    uint32_t shared = 0;                   // nodes active in every region (seams)
    // Per hierarchy face its material + 1 (0 = the default surface), when the chain has
    // materials; the vd mesh groups each object's triangles by it.
    std::vector<uint32_t> face_slot;
    uint32_t slots = 0;
  };
  std::vector<VdModel> vd_models;  // per model with a hierarchy (else default)
  std::vector<uint8_t> has_vd;      // per model: has a hierarchy
  std::vector<int16_t> occluder_level;  // per model: the level occluders draw, -1 = none
  std::vector<uint8_t> can_occlude;     // per model: occluder_level >= 0
  bool any_vd = false;

  // The fixed scene's objects (FrameGraph(scene)).
  ObjectStore own_store;
  double own_clock = 0;

  // Per frame.
  ObjectStore* store = nullptr;
  const FrameInput* input = nullptr;
  Frame* out = nullptr;
  size_t entries_high = 0;  // the most entries a frame has had (reserve_entries)
  uint32_t view_count = 1;
  std::array<View, kMaxViews> views{};
  std::array<Frustum, kMaxViews> frusta{};
  std::array<float, kMaxViews> focal{};
  double time = 0;
  uint64_t tick = 0;
  size_t count = 0, grain = 1, chunks = 0;

  // Per object (dense), per frame.
  std::vector<uint8_t> mask;
  bool models_changed = true;  // every object's derived columns need the new tables
  struct PerView {  // [0] holds the combined choice after importance
    std::vector<uint8_t> visible, level;
    std::vector<float> distance, area, weight;
  };
  std::array<PerView, kMaxViews> per_view;
  // Visible objects compacted in object order (slot k <-> Frame entry k).
  std::vector<float> visible_weight;
  std::vector<uint32_t> visible_row;
  std::vector<float> visible_benefit;      // benefit weights: benefit_cost and the optimum only
  std::vector<uint8_t> initial_levels;     // before selection, when the optimum is measured
  uint64_t selection_budget = 0;           // what selection was given (M less the blend reserve)
  std::vector<uint8_t> all_ones;
  std::vector<HeapEntry> heap;
  std::vector<uint32_t> selection_counts;  // chunks x level_total
  std::vector<uint32_t> selection_total;   // level_total
  std::vector<uint32_t> chunk_visible, chunk_offset;
  std::vector<ViewMinima> chunk_minima;    // chunks x kMaxViews
  std::array<ViewMinima, kMaxViews> minima{};
  std::vector<ChunkTotals> chunk_totals;
  static constexpr size_t kCountLanes = 4;  // interleaved per-level counters (no store chains)
  std::vector<uint32_t> level_counts;       // chunks x kCountLanes x level_total
  std::vector<BlendTotals> chunk_blend;
  std::vector<std::vector<OccluderCandidate>> chunk_occluders;
  std::vector<OccluderCandidate> occluders;
  std::vector<uint32_t> chunk_occluded;
  std::vector<uint32_t> chunk_far;         // view 0's frustum, beyond max_distance
  OcclusionBuffer occlusion_buffer;
  std::unique_ptr<OcclusionTracer> tracer;  // options.occlusion.make_tracer's; null: rasterise
  std::vector<OccluderMesh> occluder_meshes;
  OcclusionCamera occlusion_view{};
  uint32_t visible_total = 0;
  uint64_t last_morph_extra = 0;
  uint64_t morph_reserve = 0;
  SelectionResult selected;
  std::array<double, kStageCount> stage_ms{};
  // ThreadSanitizer's view of the graph's edges (see tsan_acquire); one byte per hand-over.
  struct SyncPoints {
    char start = 0, finish = 0;
    std::array<char, kNodeCount> done{};
    std::array<char, kStageCount> spawn{}, join{};
  } sync;
  uint64_t frame_index = 0;
  std::vector<uint32_t> freed_slots;

  // View-dependent objects, by handle slot (state follows the object, whatever moves).
  struct VdObject {
    ObjectHandle handle = 0;
    uint32_t model = 0;
    std::vector<VertexFront> fronts;  // one per region
    std::vector<FrontStats> region_stats;
    std::vector<uint32_t> region_tris, region_caps;
    std::vector<uint32_t> node_index;  // fronts_compact_mesh scratch (several regions only)
    VertexMorph morph;
    std::vector<float> shown;  // geomorphed positions, xyz per hierarchy node
    std::vector<float> shown_uv;  // geomorphed uvs, 2 per node (trees with uvs)
    std::vector<uint32_t> compact_nodes;       // several regions: the compact meshes' vertex order
    std::vector<uint32_t> sorted, slot_count;  // material grouping scratch
    std::vector<VdRunFrame> runs;              // this frame's runs (absolute first_index)
    FrontStats stats;          // summed over the regions
    uint32_t entry = 0;        // this frame's entry
  };
  std::vector<std::unique_ptr<VdObject>> vd_by_slot;
  std::vector<VdObject*> vd_visible;
  struct VdTask {
    VdObject* object;
    uint32_t region;
  };
  std::vector<VdTask> vd_tasks;

  // Scene HLOD (options.scene_hlod): per tree object, its dense index and whether it is as
  // built, refreshed after commits (dense indices only change there).
  SceneHlodCut scene_cut;
  std::vector<uint32_t> scene_dense;
  std::vector<uint8_t> scene_ok;
  std::vector<uint32_t> scene_bad_prefix;
  bool scene_refresh = true;

  // HLOD models (options.hlod): one stream for all of them; its loader threads are its own.
  std::unique_ptr<HlodStream> hlod_stream;
  std::vector<HlodModelInput> hlod_inputs;
  bool hlod_over_budget = false;
  uint64_t hlod_wanted_last = 0;  // last frame's cuts before their budget: the HLOD demand
  std::vector<HlodFailedFrame> hlod_failed;  // every failed node so far, messages made once

  // The terrain (options.terrain): ROAM state and share across frames, last frame's feedback.
  TerrainLod terrain;
  TerrainFeedback terrain_last;

  tbb::task_arena arena;
  std::optional<tbb::flow::graph> graph;
  std::optional<tbb::flow::broadcast_node<tbb::flow::continue_msg>> start;
  std::vector<std::unique_ptr<Node>> nodes;  // kNodeCount, destroyed before the graph

  Impl(std::shared_ptr<const ModelSet> models, const FrameGraphOptions& o)
      : options(o),
        grain(std::max<uint32_t>(1, o.grain)),
        arena(o.threads == 0 ? tbb::task_arena::automatic : static_cast<int>(o.threads)) {
    set_models(std::move(models));
    if (o.hlod && !o.hlod->empty()) make_hlod_stream(o.hlod);
    if (o.occlusion.enabled && o.occlusion.make_tracer) tracer = o.occlusion.make_tracer();
    if (o.terrain) terrain_lod_reset(terrain, *o.terrain, o.geomorph_seconds);
    // Built inside the arena, the graph attaches to it: its tasks run on these threads.
    arena.execute([&] { build(); });
  }

  // Reads run on the pager's threads, several at once: read_hlod_node opens the file per read.
  // A cache entry that fails a read is marked bad for the next bake.
  void make_hlod_stream(std::shared_ptr<const HlodModels> h) {
    const ModelNodeLoader load = marking_bad_entries(h, h->load);
    hlod_stream = std::make_unique<HlodStream>(h->trees, h->stream, load);
    hlod_inputs.resize(h->trees.size());
    for (size_t m = 0; m < hlod_inputs.size(); ++m) hlod_inputs[m].transform = h->transforms[m];
    // Set-up, not a frame: the roots are there before frame 1, so no frame has a hole.
    hlod_stream->load_roots(30.0);
  }

  // ---- the model set ----------------------------------------------------------------------

  void set_models(std::shared_ptr<const ModelSet> models) {
    set = std::move(models);
    const ModelTable& m = set->models;
    caps = build_level_caps(m);
    level_total = caps.rows.triangles.size();
    selection_tables = build_selection_tables(caps.rows);
    selection_total.assign(level_total, 0);
    full_triangles.resize(level_total);
    for (size_t r = 0; r < caps.rows.model_count(); ++r) {
      const uint32_t base = m.first_level[caps.model_of[r]];
      for (size_t k = 0; k < caps.rows.level_count[r]; ++k)
        full_triangles[caps.rows.first_level[r] + k] = m.triangles[base];
    }
    model_blends.resize(m.model_count());
    vd_models.assign(m.model_count(), VdModel{});
    has_vd.assign(m.model_count(), 0);
    any_vd = false;
    occluder_level.assign(m.model_count(), -1);
    can_occlude.assign(m.model_count(), 0);
    for (size_t i = 0; i < m.model_count(); ++i) {
      const LodChain& chain = *set->chains[i];
      for (size_t k = 0; k < chain.levels.size() && chain.positions.size() >= 9; ++k) {
        const uint32_t tris = chain.levels[k].triangles();
        if (tris > options.occlusion.occluder_triangles || tris == 0) continue;  // 0: the culled level
        occluder_level[i] = static_cast<int16_t>(k);
        can_occlude[i] = 1;
        break;
      }
    }
    for (size_t i = 0; i < m.model_count(); ++i) {
      const LodChain& chain = *set->chains[i];
      model_blends[i] = chain.hierarchy.empty() && can_morph_levels(chain);
      if (chain.hierarchy.empty()) continue;
      vd_models[i] = vd_model_of(chain);
      has_vd[i] = 1;
      any_vd = true;
    }
    models_changed = true;
    resize_chunks();
  }

  static VdModel vd_model_of(const LodChain& chain) {
    VdModel v;
    const LodLevel& l0 = chain.levels[0];
    v.edges = edge_check_of(std::span(chain.indices.data() + l0.first_index, l0.index_count));
    // The hierarchy's faces are level 0's triangles (cleaned levels have no degenerate ones the
    // build would drop); anything else is drawn as one surface.
    const VertexTree& t = chain.hierarchy;
    const auto runs = level_submeshes(chain, 0);
    if (!runs.empty() && t.face_count == l0.triangles() &&
        std::equal(t.face_leaves.begin(), t.face_leaves.end(), chain.indices.begin() + l0.first_index)) {
      v.face_slot.assign(t.face_count, 0);
      for (const LevelSubmesh& r : runs) {
        const uint32_t slot = uint32_t(r.material + 1);
        v.slots = std::max(v.slots, slot + 1);
        std::fill_n(v.face_slot.begin() + r.first_index / 3, r.index_count / 3, slot);  // level-local
      }
    }
    // Regions only pay off when the hierarchy was built in parts: a one-part tree's extra
    // regions are tiny components, kept together in one front.
    std::vector<uint8_t> region;
    v.region_count = vertex_tree_regions(region, chain.hierarchy, kMaxVdRegions);
    if (v.region_count < 2) {
      v.region_count = 1;
      return v;
    }
    auto numbering = std::make_shared<const RegionNumbering>(number_regions(chain.hierarchy, std::move(region), v.region_count));
    v.shared = numbering->shared;
    v.regions = std::move(numbering);
    return v;
  }

  // Per-object and per-chunk scratch for `count` objects; capacity is kept, so a steady
  // object count allocates nothing.
  void resize_chunks() {
    chunks = (count + grain - 1) / grain;
    visible_weight.resize(count);
    mask.resize(count);
    visible_row.resize(count);
    visible_benefit.resize(count);
    all_ones.resize(count, 1);  // only ever ones
    heap.resize(count);
    for (uint32_t v = 0; v < view_count; ++v) {
      PerView& p = per_view[v];
      p.visible.resize(count), p.level.resize(count);
      p.distance.resize(count), p.area.resize(count), p.weight.resize(count);
    }
    chunk_visible.resize(chunks);
    chunk_offset.resize(chunks);
    chunk_minima.resize(chunks * kMaxViews);
    chunk_totals.resize(chunks);
    chunk_blend.resize(chunks);
    chunk_occluders.resize(chunks);
    chunk_occluded.resize(chunks);
    chunk_far.resize(chunks);
    selection_counts.resize(chunks * level_total);
    level_counts.resize(chunks * kCountLanes * level_total);
  }

  // ---- the graph --------------------------------------------------------------------------

  // Node j depends on node i < j when one writes a column the other reads or writes.
  static bool conflicts(const NodeSpec& a, const NodeSpec& b) {
    return (a.writes & (b.reads | b.writes)) || (a.reads & b.writes);
  }
  // Edges i -> j without those implied by a longer path (pred[j] bit i).
  static std::array<uint32_t, kNodeCount> reduced_predecessors() {
    std::array<uint32_t, kNodeCount> pred{}, reach{};
    for (size_t j = 0; j < kNodeCount; ++j)
      for (size_t i = 0; i < j; ++i)
        if (conflicts(kNodes[i], kNodes[j])) pred[j] |= 1u << i;
    for (size_t j = 0; j < kNodeCount; ++j) {
      for (size_t i = 0; i < j; ++i)
        if (pred[j] >> i & 1) reach[j] |= reach[i] | (1u << i);
    }
    for (size_t j = 0; j < kNodeCount; ++j) {
      uint32_t implied = 0;
      for (size_t i = 0; i < j; ++i)
        if (pred[j] >> i & 1) implied |= reach[i];
      pred[j] &= ~implied;
    }
    return pred;
  }

  // What a node's body is given: the body is copied into the node by TBB (tsan_unseen_copy).
  struct NodeCapture {
    Impl* self;
    uint32_t index, preds;
  };

  void build() {
    graph.emplace();
    start.emplace(*graph);
    const auto pred = reduced_predecessors();
    nodes.reserve(kNodeCount);
    for (size_t i = 0; i < kNodeCount; ++i) {
      const NodeCapture cap{this, uint32_t(i), pred[i]};
      nodes.push_back(std::make_unique<Node>(*graph, [cap](const tbb::flow::continue_msg&) {
        const NodeCapture c = detail::tsan_unseen_copy(cap);
        c.self->run_node(c.index, c.preds);
      }));
    }
    for (size_t j = 0; j < kNodeCount; ++j) {
      if (pred[j] == 0) tbb::flow::make_edge(*start, *nodes[j]);
      for (uint32_t p = pred[j]; p; p &= p - 1) tbb::flow::make_edge(*nodes[std::countr_zero(p)], *nodes[j]);
    }
  }

  void run_node(uint32_t i, uint32_t preds) {
    if (preds == 0) tsan_acquire(sync.start);
    for (uint32_t p = preds; p; p &= p - 1) tsan_acquire(sync.done[std::countr_zero(p)]);
    const NodeSpec& spec = kNodes[i];
    const auto t0 = Clock::now();
    try {
      if (options.stage_hook) options.stage_hook(spec.stage);
      (this->*spec.run)();
    } catch (...) {
      tsan_release(sync.done[i]);
      throw;
    }
    stage_ms[static_cast<size_t>(spec.stage)] = ms_between(t0, Clock::now());
    tsan_release(sync.done[i]);
  }

  // A loop's hand-over: its chunks acquire `spawn`, released by the node before the loop, and
  // release `join`, acquired by the node after it. The chunks' copies of the loop's body and
  // range are TBB's (tsan_unseen_copy).
  template <class Body>
  struct Loop {
    char* spawn;
    char* join;
    const Body* body;
  };

  // Runs body(chunk, begin, end) for every chunk; one task per chunk.
  template <class Body>
  void for_chunks(Stage stage, const Body& body) {
    const auto each = [&](size_t c) { body(c, c * grain, std::min(count, (c + 1) * grain)); };
    run_loop(stage, chunks, each, tbb::simple_partitioner());
  }

  template <class Body>
  void for_items(Stage stage, size_t n, const Body& body) {
    if (n > 0) run_loop(stage, n, body, tbb::auto_partitioner());
  }

  template <class Body, class Partitioner>
  void run_loop(Stage stage, size_t n, const Body& body, const Partitioner& partitioner) {
    const Loop<Body> loop{&sync.spawn[static_cast<size_t>(stage)], &sync.join[static_cast<size_t>(stage)], &body};
    const auto task = [loop](const tbb::blocked_range<size_t>& range) {
      const Loop<Body> l = detail::tsan_unseen_copy(loop);
      const tbb::blocked_range<size_t> r = detail::tsan_unseen_copy(range);
      tsan_acquire(*l.spawn);
      for (size_t j = r.begin(); j != r.end(); ++j) (*l.body)(j);
      tsan_release(*l.join);
    };
    tsan_release(*loop.spawn);  // after everything the body reads is written
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1), task, partitioner);
    tsan_acquire(*loop.join);
  }

  // ---- nodes ------------------------------------------------------------------------------

  // Staged creates, destroys, moves and options, in commit order; then scratch for the count.
  void node_commit() {
    freed_slots.clear();
    for (const CommitBatchRef& batch : input->commits) {
      apply_commands(*store, batch.commands, static_cast<uint32_t>(set->models.model_count()), freed_slots);
      tick = batch.tick;
    }
    for (uint32_t slot : freed_slots)
      if (slot < vd_by_slot.size()) vd_by_slot[slot].reset();
    if (!input->commits.empty()) scene_refresh = true;
    count = store->size();
    resize_chunks();
  }

  // World spheres and controls of the objects that changed since they were last computed.
  void node_bounds() {
    ObjectStore& s = *store;
    if (models_changed) s.mark_all_dirty();
    models_changed = false;
    if (!s.any_dirty) return;
    for_chunks(Stage::bounds, [&](size_t, size_t b, size_t e) {
      refresh_derived_columns(s, b, e, caps, set->spheres);
    });
    s.any_dirty = false;
  }

  void node_view() {
    for (uint32_t v = 0; v < view_count; ++v) {
      frusta[v] = frustum_of(views[v]);
      focal[v] = focal_pixels(views[v]);
    }
    if (options.occlusion.enabled)
      occlusion_view = occlusion_camera(views[0], options.occlusion.width, options.occlusion.height);
  }

  void node_visibility() {
    const ObjectStore& s = *store;
    for_chunks(Stage::visibility, [&](size_t c, size_t b, size_t e) {
      std::array<std::span<uint8_t>, kMaxViews> vis;
      for (uint32_t v = 0; v < view_count; ++v) {
        vis[v] = sub(per_view[v].visible, b, e);
        cull_spheres(vis[v], sub(s.cx, b, e), sub(s.cy, b, e), sub(s.cz, b, e), sub(s.radius, b, e), frusta[v]);
        if (options.max_distance <= 0) continue;
        const size_t far = cull_beyond_distance(vis[v], sub(s.cx, b, e), sub(s.cy, b, e), sub(s.cz, b, e),
                                                sub(s.radius, b, e), views[v].eye, options.max_distance);
        if (v == 0) chunk_far[c] = static_cast<uint32_t>(far);
      }
      if (options.max_distance <= 0) chunk_far[c] = 0;
      chunk_visible[c] = static_cast<uint32_t>(
          combine_view_masks(sub(mask, b, e), std::span(vis.data(), view_count), sub(s.never_cull, b, e)));
      if (options.occlusion.enabled) {
        chunk_occluders[c].clear();
        gather_occluders(chunk_occluders[c], options.occlusion.occluders, vis[0], sub(s.cx, b, e), sub(s.cy, b, e),
                         sub(s.cz, b, e), sub(s.radius, b, e), sub(s.model, b, e), can_occlude, occlusion_view.eye,
                         static_cast<uint32_t>(b));
      }
    });
    out->occluded = out->occluders = 0;
    out->occluder_tris = 0;
    if (options.occlusion.enabled) cull_occluded();
    // Exclusive prefix sum over the chunks: where each chunk's visible objects go.
    visible_total = 0;
    for (size_t c = 0; c < chunks; ++c) {
      chunk_offset[c] = visible_total;
      visible_total += chunk_visible[c];
    }
  }

  // Occlusion for view 0: the best occluders of all chunks rasterised (serial, in a fixed
  // order), then every object view 0 sees tested against them, parallel over chunks.
  void cull_occluded() {
    const ObjectStore& s = *store;
    occluders.clear();
    for (size_t c = 0; c < chunks; ++c) occluders.insert(occluders.end(), chunk_occluders[c].begin(), chunk_occluders[c].end());
    keep_best_occluders(occluders, options.occlusion.occluders);
    occlusion_clear(occlusion_buffer, occlusion_view);
    occluder_meshes.clear();
    for (const OccluderCandidate& o : occluders) {
      const LodChain& chain = *set->chains[s.model[o.object]];
      const LodLevel& l = chain.levels[occluder_level[s.model[o.object]]];
      occluder_meshes.push_back(
          {std::span(chain.positions.data() + 3 * size_t(l.first_vertex), 3 * size_t(l.vertex_count)),
           std::span(chain.indices.data() + l.first_index, l.index_count), s.transform[o.object]});
    }
    if (tracer) {
      trace_occluders();
    } else {
      for (const OccluderMesh& m : occluder_meshes)
        rasterize_occluder(occlusion_buffer, occlusion_view, m.positions, m.indices, m.transform);
    }
    occlusion_finish(occlusion_buffer);
    for_chunks(Stage::visibility, [&](size_t c, size_t b, size_t e) {
      std::span<uint8_t> v0 = sub(per_view[0].visible, b, e);
      // never_cull objects are seen whatever hides them: test only the others.
      uint32_t culled = 0;
      for (size_t i = b; i < e; ++i) {
        if (!v0[i - b] || s.never_cull[i]) continue;
        const float center[3] = {s.cx[i], s.cy[i], s.cz[i]};
        if (!sphere_occluded(occlusion_buffer, occlusion_view, center, s.radius[i])) continue;
        v0[i - b] = 0;
        const uint8_t before = mask[i];
        mask[i] = static_cast<uint8_t>(before & ~1u);
        chunk_visible[c] -= mask[i] == 0;
        ++culled;
      }
      chunk_occluded[c] = culled;
    });
    for (size_t c = 0; c < chunks; ++c) out->occluded += chunk_occluded[c];
    out->occluders = static_cast<uint32_t>(occluders.size());
    out->occluder_tris = occlusion_buffer.triangles;
  }

  // Per tree object: live, same model, same sphere, not never_cull (a proxy stands only for
  // objects exactly as it was built from).
  void refresh_scene_validity(const SceneHlodTree& tree) {
    const ObjectStore& s = *store;
    const size_t n = tree.objects.size();
    scene_dense.resize(n);
    scene_ok.resize(n);
    scene_bad_prefix.resize(n + 1);
    for (size_t j = 0; j < n; ++j) {
      const SceneHlodObject& o = tree.objects[j];
      const uint32_t i = s.find(o.handle);
      scene_dense[j] = i;
      scene_ok[j] = i != kNoIndex && s.model[i] == o.model && !s.never_cull[i] && s.cx[i] == o.sphere.center[0] &&
                    s.cy[i] == o.sphere.center[1] && s.cz[i] == o.sphere.center[2] && s.radius[i] == o.sphere.radius;
    }
    scene_hlod_validity(scene_bad_prefix, scene_ok);
    scene_refresh = false;
  }

  // Objects a drawn proxy stands for leave view 0 (and the frame, unless another view sees them).
  void cover_by_proxies(const SceneHlodTree& tree) {
    for (uint32_t id : scene_cut.drawn) {
      const SceneHlodNode& n = tree.nodes[id];
      for (uint32_t j = n.first_object; j < n.first_object + n.object_count; ++j) {
        const uint32_t i = scene_dense[j];
        if (!(mask[i] & 1u)) continue;
        per_view[0].visible[i] = 0;
        mask[i] = static_cast<uint8_t>(mask[i] & ~1u);
        chunk_visible[i / grain] -= mask[i] == 0;
      }
    }
    visible_total = 0;
    for (size_t c = 0; c < chunks; ++c) {
      chunk_offset[c] = visible_total;
      visible_total += chunk_visible[c];
    }
  }

  void node_scene_hlod() {
    Frame& f = *out;
    f.scene_proxies.clear();
    f.scene_proxy_objects = 0;
    f.scene_proxy_tris = 0;
    const SceneHlodTree* tree = options.scene_hlod.get();
    if (!tree || tree->empty()) return;
    if (scene_refresh || models_changed) refresh_scene_validity(*tree);
    select_scene_hlod_cut(scene_cut, *tree, frusta[0], views[0].eye, focal[0], options.pixel_error, scene_bad_prefix);
    cover_by_proxies(*tree);
    f.scene_proxies.assign(scene_cut.drawn.begin(), scene_cut.drawn.end());
    f.scene_proxy_objects = scene_cut.objects;
    f.scene_proxy_tris = scene_cut.triangles;
  }

  // The tracer's depth buffer, rows in parallel (blocks of 8 rows).
  void trace_occluders() {
    occlusion_buffer.triangles = tracer->prepare(occluder_meshes);
    if (occluder_meshes.empty()) return;
    constexpr int kRows = 8;
    const int h = occlusion_buffer.height;
    for_items(Stage::visibility, size_t((h + kRows - 1) / kRows), [&](size_t j) {
      tracer->trace_rows(occlusion_buffer, occlusion_view, int(j) * kRows, std::min(h, int(j + 1) * kRows));
    });
  }

  void node_importance() {
    const ObjectStore& s = *store;
    for_chunks(Stage::importance, [&](size_t c, size_t b, size_t e) {
      for (uint32_t v = 0; v < view_count; ++v) {
        PerView& p = per_view[v];
        chunk_minima[c * kMaxViews + v] =
            measure_objects(sub(p.distance, b, e), sub(p.area, b, e), sub(p.visible, b, e), sub(s.cx, b, e),
                            sub(s.cy, b, e), sub(s.cz, b, e), sub(s.radius, b, e), views[v].eye, focal[v]);
      }
    });
    // min() is order-free, but merging in chunk order keeps even that obvious.
    for (uint32_t v = 0; v < view_count; ++v) {
      minima[v] = empty_minima();
      for (size_t c = 0; c < chunks; ++c) minima[v] = merge_minima(minima[v], chunk_minima[c * kMaxViews + v]);
    }
    Frame& f = *out;
    f.levels.resize(visible_total);
    f.objects.resize(visible_total);
    f.models.resize(visible_total);
    if (visible_total == 0) return;
    for_chunks(Stage::importance, [&](size_t c, size_t b, size_t e) {
      choose_chunk_levels(b, e);
      compact_chunk(c, b, e);
    });
  }

  // Each view's weights and initial levels, folded into view 0's columns, then the options.
  void choose_chunk_levels(size_t b, size_t e) {
    const ObjectStore& s = *store;
    for (uint32_t v = 0; v < view_count; ++v) {
      PerView& p = per_view[v];
      importance_weights(sub(p.weight, b, e), sub(p.visible, b, e), sub(p.distance, b, e), sub(p.area, b, e),
                         minima[v]);
      const InitialLevelParams params{focal[v], options.pixel_error, options.hysteresis};
      choose_initial_levels(sub(p.level, b, e), sub(p.visible, b, e), sub(s.prev_level, b, e),
                            sub(s.was_visible, b, e), sub(p.distance, b, e), sub(s.error_scale, b, e),
                            sub(s.row, b, e), caps.rows, params);
    }
    PerView& p0 = per_view[0];
    for (uint32_t v = 1; v < view_count; ++v) {
      const PerView& p = per_view[v];
      combine_view_choice(sub(p0.level, b, e), sub(p0.weight, b, e), sub(p0.visible, b, e), sub(p.level, b, e),
                          sub(p.weight, b, e), sub(p.visible, b, e));
    }
    apply_object_controls(sub(p0.level, b, e), sub(p0.weight, b, e), sub(p0.visible, b, e), sub(s.min_level, b, e),
                          sub(s.inv_priority, b, e));
  }

  // This chunk's visible objects into their slots, then selection's streaming pass on them.
  void compact_chunk(size_t c, size_t b, size_t e) {
    Frame& f = *out;
    const ObjectStore& s = *store;
    const PerView& p0 = per_view[0];
    // Branch-free (visibility is random in object order): every object is written to the
    // next free slot, which only advances past visible ones. Stopping once the chunk's slots
    // are full keeps the writes inside them; every object left is then invisible.
    const uint32_t end_slot = chunk_offset[c] + chunk_visible[c];
    uint32_t slot = chunk_offset[c];
    uint32_t* __restrict ids = f.objects.data();
    uint8_t* __restrict levels = f.levels.data();
    for (size_t i = b; i < e && slot < end_slot; ++i) {
      ids[slot] = static_cast<uint32_t>(i);
      levels[slot] = p0.level[i];
      visible_weight[slot] = p0.weight[i];
      visible_row[slot] = s.row[i];
      slot += p0.visible[i];
    }
    assert(slot == end_slot);
    for (uint32_t k = chunk_offset[c]; k < end_slot; ++k) f.models[k] = s.model[ids[k]];
    if (needs_benefit_weights())
      for (uint32_t k = chunk_offset[c]; k < end_slot; ++k)
        visible_benefit[k] = benefit_weight(p0.area[ids[k]], p0.distance[ids[k]], s.error_scale[ids[k]], focal[0]);
    const size_t b0 = chunk_offset[c], n0 = chunk_visible[c];
    const std::span<uint32_t> counts(selection_counts.data() + c * level_total, level_total);
    std::fill(counts.begin(), counts.end(), 0u);
    gather_selection(std::span<HeapEntry>(heap.data() + b0, n0), counts,
                     std::span<const uint8_t>(f.levels.data() + b0, n0),
                     std::span<const uint8_t>(all_ones.data() + b0, n0),
                     std::span<const float>(visible_weight.data() + b0, n0),
                     std::span<const uint32_t>(visible_row.data() + b0, n0), static_cast<uint32_t>(b0), caps.rows,
                     selection_tables);
  }

  // The frame's fraction of the optimum (Frame::benefit_optimum_fraction) is measured where the
  // oracle is cheap: at most kOptimumEntries entries, a DP of kOptimumCells cost cells (about
  // 300 x 4096 x levels steps, a few milliseconds, counted in publish).
  static constexpr size_t kOptimumEntries = 300;
  static constexpr size_t kOptimumCells = 4096;
  bool measures_optimum() const { return options.measure_quality && visible_total <= kOptimumEntries; }
  bool needs_benefit_weights() const {
    return options.selection.selector == Selector::benefit_cost || measures_optimum();
  }

  // On the compacted visible set: the same result as on the whole range (selection breaks
  // ties by position, and compaction keeps object order), with less to stream through.
  void node_selection() {
    const size_t v = visible_total;
    std::fill(selection_total.begin(), selection_total.end(), 0u);
    for (size_t c = 0; c < chunks; ++c) {
      // A chunk with nothing visible this frame was not compacted: its counts are an earlier
      // frame's and must not be summed.
      if (chunk_visible[c] == 0) continue;
      const uint32_t* counts = selection_counts.data() + c * level_total;
      for (size_t k = 0; k < level_total; ++k) selection_total[k] += counts[k];
    }
    // Blending objects draw their finer level: what last frame's blends added is held back
    // from M (at most half of it, so blends never starve the selection), so that what is
    // drawn, not only what is selected, stays near M.
    SelectionParams so = options.selection;
    so.budget -= terrain_taken();
    if (so.count == BudgetCount::triangles) {
      so.budget -= std::min(so.budget, out->scene_proxy_tris);  // one M
      if (hlod_stream) so.budget = first_share(so.budget, initial_triangles(), hlod_wanted_last);
    }
    morph_reserve = 0;
    if (so.count == BudgetCount::triangles && so.reserve_blends) {
      morph_reserve = std::min(last_morph_extra, so.budget / 2);
      so.budget -= morph_reserve;
    }
    selection_budget = so.budget;
    if (measures_optimum()) initial_levels.assign(out->levels.begin(), out->levels.begin() + long(v));
    const std::span<const float> benefit =
        so.selector == Selector::benefit_cost ? std::span<const float>(visible_benefit.data(), v) : std::span<const float>{};
    selected = lower_under_budget(
        std::span<uint8_t>(out->levels.data(), v), std::span<const uint8_t>(all_ones.data(), v),
        std::span<const float>(visible_weight.data(), v), std::span<const uint32_t>(visible_row.data(), v),
        caps.rows, so, selection_total, std::span<HeapEntry>(heap.data(), v), benefit);
  }

  // Triangles of the visible objects at their initial levels (the pixel threshold's demand).
  uint64_t initial_triangles() const {
    uint64_t t = 0;
    for (size_t k = 0; k < level_total; ++k) t += uint64_t(selection_total[k]) * caps.rows.triangles[k];
    return t;
  }

  // Each entry's handle, transform and view mask, gathered from its object; beside selection,
  // which is serial, so it takes the other cores.
  void node_entries() {
    Frame& f = *out;
    const ObjectStore& s = *store;
    f.handles.resize(visible_total);
    f.transforms.resize(visible_total);
    f.view_masks.resize(visible_total);
    for_chunks(Stage::entries, [&](size_t c, size_t, size_t) {
      const uint32_t b = chunk_offset[c], e = b + chunk_visible[c];
      for (uint32_t k = b; k < e; ++k) {
        const uint32_t i = f.objects[k];
        f.handles[k] = s.handle[i];
        f.transforms[k] = s.transform[i];
        f.view_masks[k] = mask[i];
      }
    });
  }

  // Level changes blend (runtime/level_blend.h), in parallel over each chunk's entries.
  void node_geomorph() {
    Frame& f = *out;
    f.morph.resize(visible_total);
    f.from_levels.resize(visible_total);
    ObjectStore& s = *store;
    const LevelBlendState state{s.morph_start, s.morph_from, s.prev_level, s.was_visible};
    for_chunks(Stage::geomorph, [&](size_t c, size_t, size_t) {
      const size_t b = chunk_offset[c], e = b + chunk_visible[c];
      chunk_blend[c] = advance_level_blends(sub(f.morph, b, e), sub(f.from_levels, b, e), sub(f.objects, b, e),
                                            sub(f.levels, b, e), sub(f.models, b, e), state, model_blends,
                                            set->models, time, options.geomorph_seconds);
    });
    f.morphing = 0;
    f.tris_morph_extra = 0;
    for (size_t c = 0; c < chunks; ++c) f.morphing += chunk_blend[c].morphing, f.tris_morph_extra += chunk_blend[c].extra_tris;
    const SelectionParams& so = options.selection;
    if (so.strict && so.count == BudgetCount::triangles && f.morphing > 0) {
      const uint64_t room = selected.over_budget || selected.triangles >= so.budget ? 0 : so.budget - selected.triangles;
      if (f.tris_morph_extra > room) {
        const BlendTotals kept = fit_blends_to_room(f.morph, f.from_levels, f.objects, f.levels, f.models, state,
                                                    set->models, room);
        f.morphing = kept.morphing;
        f.tris_morph_extra = kept.extra_tris;
      }
    }
    last_morph_extra = f.tris_morph_extra;
  }

  VdObject& vd_state(ObjectHandle h, uint32_t model) {
    const uint32_t slot = handle_slot(h);
    if (slot >= vd_by_slot.size()) vd_by_slot.resize(size_t{slot} + 1);
    std::unique_ptr<VdObject>& p = vd_by_slot[slot];
    if (p && p->handle == h && p->model == model) return *p;
    p = std::make_unique<VdObject>();
    p->handle = h;
    p->model = model;
    const VertexTree& tree = set->chains[model]->hierarchy;
    const VdModel& vm = vd_models[model];
    const float tau = std::max(options.pixel_error, 0.05f);
    if (!vm.regions) {
      front_init(p->fronts.emplace_back(), tree, tau);
    } else {
      p->fronts.resize(vm.region_count);
      for (uint32_t r = 0; r < vm.region_count; ++r) front_init(p->fronts[r], tree, tau, vm.regions, uint8_t(r));
      p->node_index.assign(tree.node_count(), 0);
    }
    p->region_stats.resize(p->fronts.size());
    p->region_tris.resize(p->fronts.size());
    p->region_caps.resize(p->fronts.size());
    vertex_morph_init(p->morph, tree, options.geomorph_seconds);
    p->shown = tree.positions;
    p->shown_uv = tree.uvs;
    return *p;
  }

  uint32_t share_of(const VdObject& o) const {
    const ModelTable& m = set->models;
    return std::max<uint32_t>(m.triangles[m.first_level[o.model] + out->levels[o.entry]], 1);
  }

  // One task per (visible view-dependent object, region); fronts are independent, so the
  // result does not depend on the thread count. View 0 drives the fronts.
  void node_vdlod() {
    const Frame& f = *out;
    vd_visible.clear();
    vd_tasks.clear();
    if (!any_vd) return;
    const ModelTable& m = set->models;
    for (uint32_t k = 0; k < visible_total; ++k) {
      if (!has_vd[f.models[k]]) continue;
      if (m.triangles[m.first_level[f.models[k]] + f.levels[k]] == 0) continue;  // culled: no front drawn
      VdObject& o = vd_state(f.handles[k], f.models[k]);
      o.entry = k;
      vd_visible.push_back(&o);
      for (size_t r = 0; r < o.fronts.size(); ++r) o.region_tris[r] = o.fronts[r].tri_count;
      share_region_caps(o.region_caps, o.region_tris, vd_cap_of_share(share_of(o)));
      for (uint32_t r = 0; r < o.fronts.size(); ++r) vd_tasks.push_back({&o, r});
    }
    for_items(Stage::vdlod, vd_tasks.size(), [&](size_t j) {
      VdObject& o = *vd_tasks[j].object;
      const uint32_t r = vd_tasks[j].region;
      const Transform& t = f.transforms[o.entry];
      const FrontView fv = front_view_of(views[0], t.position, t.scale, t.rotation);
      FrontParams p;
      p.time = time;
      p.collapse_delay = options.geomorph_seconds;
      p.hysteresis = options.vd_hysteresis;
      p.max_triangles = o.region_caps[r];
      // One front: its own feedback; regions: feedback once per object after the join.
      if (o.fronts.size() == 1) p.target_triangles = share_of(o);
      const VertexTree& tree = set->chains[o.model]->hierarchy;
      o.region_stats[r] = front_update(o.fronts[r], tree, fv, p);
      vertex_morph_apply(o.morph, tree, o.fronts[r].frame_events(), p.time);
    });
    for (VdObject* po : vd_visible) {
      VdObject& o = *po;
      o.stats = sum_region_stats(o.region_stats);
      if (o.fronts.size() == 1) continue;
      const float next = front_next_threshold(o.fronts[0].threshold, o.stats.active_tris, share_of(o), FrontParams{});
      for (VertexFront& fr : o.fronts) front_set_threshold(fr, next);
      o.stats.threshold = next;
    }
  }

  // View-dependent objects' geomorphed vertices and compact meshes into the frame.
  void node_vd_mesh() {
    Frame& f = *out;
    f.vd_objects.resize(vd_visible.size());
    uint32_t vertices = 0, indices = 0;
    bool any_uvs = false, any_uvs1 = false, any_colors = false;
    f.vd_active_tris = f.vd_splits = f.vd_collapses = 0;
    for (size_t j = 0; j < vd_visible.size(); ++j) {
      const VdObject& o = *vd_visible[j];
      const VdModel& vm = vd_models[o.model];
      VdObjectFrame& e = f.vd_objects[j];
      e.object = f.objects[o.entry];
      e.entry = o.entry;
      // Fixed seam vertices are active in every region but written once.
      uint32_t active = 0, tris = 0;
      for (const VertexFront& fr : o.fronts) active += fr.active_count, tris += fr.tri_count;
      e.first_vertex = vertices;
      e.vertex_count = active - uint32_t(o.fronts.size() - 1) * vm.shared;
      e.first_index = indices;
      e.index_count = 3 * tris;
      e.splits = o.stats.splits;
      e.collapses = o.stats.collapses;
      e.threshold = o.stats.threshold;
      e.closed = vm.edges == EdgeCheck::closed;
      e.oriented = vm.edges != EdgeCheck::corners;
      const VertexTree& tree = set->chains[o.model]->hierarchy;
      e.has_uvs = !tree.uvs.empty();
      e.has_uvs1 = !tree.uvs1.empty();
      e.has_colors = !tree.colors.empty();
      e.has_authored_normals = !tree.normals.empty();
      any_uvs |= e.has_uvs;
      any_uvs1 |= e.has_uvs1;
      any_colors |= e.has_colors;
      vertices += e.vertex_count;
      indices += e.index_count;
      f.vd_active_tris += tris;
      f.vd_splits += o.stats.splits;
      f.vd_collapses += o.stats.collapses;
    }
    f.vd_positions.resize(3 * size_t(vertices));
    f.vd_indices.resize(indices);
    f.vd_uvs.assign(any_uvs ? 2 * size_t(vertices) : 0, 0.f);
    f.vd_uvs1.assign(any_uvs1 ? 2 * size_t(vertices) : 0, 0.f);
    f.vd_colors.assign(any_colors ? 4 * size_t(vertices) : 0, 1.f);
    f.vd_normals.resize(3 * size_t(vertices));
    for_items(Stage::vd_mesh, vd_visible.size(), [&](size_t j) {
      VdObject& o = *vd_visible[j];
      VdObjectFrame& e = f.vd_objects[j];
      const VertexTree& tree = set->chains[o.model]->hierarchy;
      const std::span positions(f.vd_positions.data() + 3 * size_t(e.first_vertex), 3 * size_t(e.vertex_count));
      const std::span tris(f.vd_indices.data() + e.first_index, e.index_count);
      e.moving = 0;
      for (const VertexFront& fr : o.fronts) {
        e.moving += static_cast<uint32_t>(vertex_morph_positions(o.shown, o.morph, fr.vertices(), time));
        if (e.has_uvs) vertex_morph_uvs(o.shown_uv, o.morph, fr.vertices(), time);
      }
      const std::span uvs = e.has_uvs ? std::span(f.vd_uvs.data() + 2 * size_t(e.first_vertex), 2 * size_t(e.vertex_count))
                                      : std::span<float>();
      const VertexFront* fronts[kMaxVdRegions];
      for (size_t k = 0; k < o.fronts.size(); ++k) fronts[k] = &o.fronts[k];
      if (o.fronts.size() == 1) {
        front_compact_mesh(positions, tris, o.fronts[0], tree, o.shown);
        if (e.has_uvs) front_compact_uvs(uvs, o.fronts[0], tree, o.shown_uv);
      } else {
        uint32_t written = 0;
        fronts_compact_mesh(positions, tris, o.node_index, std::span(fronts, o.fronts.size()), tree, o.shown,
                            &written);
        assert(written == e.vertex_count);
        if (e.has_uvs) fronts_compact_uvs(uvs, std::span(fronts, o.fronts.size()), tree, o.shown_uv);
      }
      // Second uvs, colours and authored normals geomorphed straight into the frame, in the
      // compact meshes' vertex order (one pass, no per-node copy to compact afterwards).
      const std::span normals(f.vd_normals.data() + 3 * size_t(e.first_vertex), 3 * size_t(e.vertex_count));
      MorphOutput extra[3];
      size_t extras = 0;
      if (e.has_uvs1)
        extra[extras++] = {&o.morph.uv1, std::span(f.vd_uvs1.data() + 2 * size_t(e.first_vertex),
                                                   2 * size_t(e.vertex_count))};
      if (e.has_colors)
        extra[extras++] = {&o.morph.color, std::span(f.vd_colors.data() + 4 * size_t(e.first_vertex),
                                                     4 * size_t(e.vertex_count))};
      if (e.has_authored_normals) extra[extras++] = {&o.morph.normal, normals};
      if (extras) {
        std::span<const uint32_t> order = o.fronts[0].vertices();
        if (o.fronts.size() > 1) {
          o.compact_nodes.resize(e.vertex_count);
          fronts_compact_nodes(o.compact_nodes, std::span(fronts, o.fronts.size()));
          order = o.compact_nodes;
        }
        vertex_morph_compact(std::span(extra, extras), o.morph, order, time);
      }
      if (e.has_authored_normals)
        renormalise(normals);
      else
        area_weighted_normals(normals, positions, tris);
      group_by_material(o, tris, std::span(fronts, o.fronts.size()), vd_models[o.model], e.first_index);
    });
    // Runs into the frame, object by object.
    f.vd_runs.clear();
    for (size_t j = 0; j < vd_visible.size(); ++j) {
      VdObjectFrame& e = f.vd_objects[j];
      e.first_run = static_cast<uint32_t>(f.vd_runs.size());
      e.run_count = static_cast<uint32_t>(vd_visible[j]->runs.size());
      f.vd_runs.insert(f.vd_runs.end(), vd_visible[j]->runs.begin(), vd_visible[j]->runs.end());
    }
  }

  // Reorders an object's compact triangles by material (a stable counting sort over the
  // fronts' faces, in the order the compact mesh wrote them) and records its runs. Linear in
  // its triangles; no allocation once the scratch has grown.
  static void group_by_material(VdObject& o, std::span<uint32_t> tris, std::span<const VertexFront* const> fronts,
                                const VdModel& vm, uint32_t first_index) {
    o.runs.clear();
    if (vm.face_slot.empty()) return;
    const size_t count = tris.size() / 3;
    o.slot_count.assign(vm.slots + 1, 0);
    auto slot_of = [&](auto&& visit) {
      size_t k = 0;
      for (const VertexFront* fr : fronts)
        for (uint32_t s = 0; s < fr->tri_count; ++s) visit(k++, vm.face_slot[fr->tri_face[s]]);
    };
    slot_of([&](size_t, uint32_t slot) { ++o.slot_count[slot + 1]; });
    for (uint32_t m = 0; m < vm.slots; ++m) {
      const uint32_t n = o.slot_count[m + 1];
      if (n) o.runs.push_back({first_index + 3 * o.slot_count[m], 3 * n, int32_t(m) - 1});
      o.slot_count[m + 1] += o.slot_count[m];
    }
    o.sorted.resize(3 * count);
    slot_of([&](size_t k, uint32_t slot) { std::copy_n(&tris[3 * k], 3, &o.sorted[3 * size_t(o.slot_count[slot]++)]); });
    std::copy(o.sorted.begin(), o.sorted.end(), tris.begin());
  }

  // The triangles M leaves after the discrete selection, split evenly over the HLOD models.
  uint64_t hlod_share() const {
    const SelectionParams& sp = options.selection;
    if (sp.count != BudgetCount::triangles) return UINT64_MAX;
    const uint64_t objects = sp.budget - terrain_taken();
    const uint64_t used = selected.triangles + out->scene_proxy_tris;
    const uint64_t left = objects > used ? objects - used : 0;
    return left / std::max<size_t>(1, hlod_inputs.size());
  }

  // View 0's cut of every HLOD model, then the pager's update (no I/O here).
  void node_hlod() {
    Frame& f = *out;
    f.hlod_drawn.clear();
    f.hlod_opened.clear();
    hlod_over_budget = false;
    f.hlod_nodes_drawn = 0;
    f.hlod_tris = f.resident_bytes = f.stream_requests = f.stream_loads = f.stream_evictions = f.stream_failures = f.stream_budget = 0;
    f.holes = 0;
    f.stream_failed.clear();
    if (!hlod_stream) return;
    const uint64_t share = hlod_share();
    for (HlodModelInput& in : hlod_inputs) {
      in.params.pixel_error = options.pixel_error;
      in.params.triangle_budget = share;
      in.params.culled = options.hlod->culled;
    }
    hlod_stream->frame(frame_index, hlod_view_of(views[0]), hlod_inputs);
    uint64_t wanted = 0;
    for (uint32_t m = 0; m < hlod_stream->model_count(); ++m) {
      const HlodCut& cut = hlod_stream->cut(m);
      for (const HlodDraw& d : cut.drawn) f.hlod_drawn.push_back({m, d.node, d.layer});
      for (const uint32_t n : cut.opened) f.hlod_opened.push_back({m, n});
      hlod_over_budget |= cut.over_budget;
      wanted += cut.wanted_triangles;
    }
    hlod_wanted_last = wanted;
    const HlodStreamFigures fig = hlod_stream->figures();
    f.hlod_nodes_drawn = fig.hlod_nodes_drawn;
    f.hlod_tris = fig.hlod_triangles;
    f.resident_bytes = fig.resident_bytes;
    f.stream_budget = options.hlod->stream.budget_bytes;
    f.stream_requests = fig.stream_requests;
    f.stream_loads = fig.stream_loads;
    f.stream_evictions = fig.stream_evictions;
    f.stream_failures = fig.stream_failures;
    const std::span<const HlodStreamFailure> failed = hlod_stream->failures();
    for (size_t k = hlod_failed.size(); k < failed.size(); ++k)
      hlod_failed.push_back({failed[k].model, failed[k].node,
                             hlod_failure_message(*options.hlod, failed[k].model, failed[k].node, failed[k].why)});
    f.stream_failed = hlod_failed;
    f.holes = fig.holes;
  }

  // What the terrain takes from M this frame (triangle budgets only); selection keeps >= 1.
  uint64_t terrain_taken() const {
    const SelectionParams& sp = options.selection;
    if (!options.terrain || sp.count != BudgetCount::triangles) return 0;
    return std::min(terrain.share, sp.budget - std::min<uint64_t>(sp.budget, 1));
  }

  // Before the graph fires: the share from the last frame's feedback (the first frame's from
  // the model), so selection and the terrain node both know it from the start.
  void plan_terrain_share() {
    if (!options.terrain) return;
    const SelectionParams& sp = options.selection;
    const uint64_t m = sp.count == BudgetCount::triangles ? sp.budget : 0;
    terrain_last.budget = m;
    terrain.share = terrain.started ? next_terrain_share(terrain_last, *options.terrain)
                                    : first_terrain_share(m, *options.terrain);
    terrain.started = 1;
  }

  // ROAM for view 0 under the share, then the mesh into the frame.
  void node_terrain() {
    Frame& f = *out;
    f.terrain_tris = f.terrain_splits = f.terrain_merges = f.terrain_share = 0;
    f.terrain_grid = 0;
    f.terrain_morphing = 0;
    f.terrain_pixel_error = 0;
    f.terrain_time_bound = 0;
    if (!options.terrain) {
      f.terrain_positions.clear(), f.terrain_indices.clear(), f.terrain_samples.clear();
      return;
    }
    const TerrainModel& model = *options.terrain;
    terrain.morph.duration = options.geomorph_seconds;  // set_geomorph_seconds applies from the next change
    const RoamFrameStats st =
        terrain_lod_update(terrain, model, views[0], terrain.share, time, RoamClock{&steady_now_ms, nullptr});
    f.terrain_tris = terrain_compact_mesh(f.terrain_positions, f.terrain_indices, f.terrain_samples, terrain, model.roam);
    f.terrain_grid = model.roam.size;
    f.terrain_splits = st.splits;
    f.terrain_merges = st.merges;
    f.terrain_share = terrain.share;
    f.terrain_morphing = terrain.last_morph.morphing;
    f.terrain_pixel_error = terrain_error_left(terrain.roam);
    f.terrain_time_bound = st.time_bound;
    terrain_last.share = terrain.share;
    terrain_last.terrain_tris = f.terrain_tris;
    terrain_last.terrain_bound = st.budget_bound && !st.time_bound;  // a larger share would not help the clock
    terrain_last.terrain_error = f.terrain_pixel_error;
  }

  void node_publish() {
    Frame& f = *out;
    ObjectStore& s = *store;
    const ModelTable& rows = caps.rows;
    const PerView& p0 = per_view[0];
    for_chunks(Stage::publish, [&](size_t c, size_t b, size_t e) {
      uint32_t* counts = level_counts.data() + c * kCountLanes * level_total;
      std::fill(counts, counts + kCountLanes * level_total, 0u);
      const uint32_t first_slot = chunk_offset[c], end_slot = first_slot + chunk_visible[c];
      const uint32_t* first_level = rows.first_level.data();
      const size_t n = end_slot - first_slot;
      // Measured before the history is overwritten (the entries of chunk c are its objects).
      const SelectionQuality quality =
          options.measure_quality
              ? measure_selection_quality(std::span(f.objects.data() + first_slot, n),
                                          std::span(f.levels.data() + first_slot, n),
                                          std::span(f.models.data() + first_slot, n), mask, uint8_t{1},
                                          p0.distance, p0.area, s.error_scale, set->models, focal[0])
              : SelectionQuality{};
      uint32_t changes = 0;
      for (uint32_t k = first_slot; k < end_slot; ++k) {
        const uint8_t level = f.levels[k];
        const uint32_t id = f.objects[k];
        changes += s.was_visible[id] && s.prev_level[id] != level;
        s.prev_level[id] = level;
        ++counts[(k % kCountLanes) * level_total + first_level[visible_row[k]] + level];
      }
      // Temporal state for the next frame: who was visible, at which level.
      std::copy(p0.visible.begin() + b, p0.visible.begin() + e, s.was_visible.begin() + b);
      chunk_totals[c] = sum_counts(counts);
      chunk_totals[c].level_changes = changes;
      chunk_totals[c].quality = quality;
    });
    f.object_count = static_cast<uint32_t>(count);
    f.visible = visible_total;
    f.tris_in_view = f.tris_selected = f.level_cost = 0;
    f.level_histogram.fill(0);
    f.culled = f.level_changes = 0;
    SelectionQuality quality;
    for (size_t c = 0; c < chunks; ++c) {
      const ChunkTotals& t = chunk_totals[c];
      f.culled += t.culled + chunk_far[c];
      f.level_changes += t.level_changes;
      quality = merge_quality(quality, t.quality);
      f.tris_in_view += t.tris_in_view;
      f.tris_selected += t.tris_selected;
      f.level_cost += t.level_cost;
      for (size_t l = 0; l < kHistogramLevels; ++l) f.level_histogram[l] += t.histogram[l];
    }
    f.tris_selected += f.hlod_tris + f.scene_proxy_tris;  // HLOD cuts and proxies draw within the same M
    terrain_last.objects_tris = f.tris_selected;
    terrain_last.objects_lowered = selected.levels_lowered > 0 || selected.over_budget;
    terrain_last.objects_coarsest = selected.coarsest_cost + f.hlod_tris;
    // Objects whose coarsest levels do not fit count as infinitely short: the share gives way.
    terrain_last.objects_error = selected.over_budget ? std::numeric_limits<float>::max() : quality.pixel_error_max;
    f.tris_selected += f.terrain_tris;  // and so does the terrain
    f.budget = options.selection.budget;
    f.budget_morph_reserve = morph_reserve;
    f.coarsest_cost = selected.coarsest_cost;
    // The terrain never draws under 2 triangles: a budget of 1 or 2 cannot hold it.
    const bool terrain_over = options.selection.count == BudgetCount::triangles && f.terrain_tris > terrain_taken();
    f.over_budget = selected.over_budget || hlod_over_budget || terrain_over;
    f.lowered_steps = selected.lowered_steps;
    f.levels_lowered = selected.levels_lowered;
    f.benefit = quality.benefit;
    f.pixel_error_max = quality.pixel_error_max;
    f.pixel_error_mean = quality.measured ? float(quality.pixel_error_sum / quality.measured) : 0.f;
    measure_optimum_fraction(f);
  }

  // The selected levels' benefit over the optimum of the same problem (initial levels, weights,
  // the budget selection had); -1 where not measured or the coarsest levels do not fit.
  void measure_optimum_fraction(Frame& f) const {
    f.benefit_optimum_fraction = -1;
    f.benefit_optimum_exact = false;
    if (!measures_optimum()) return;
    const size_t v = visible_total;
    const std::span<const float> w(visible_benefit.data(), v);
    const std::span<const uint32_t> rows(visible_row.data(), v);
    SelectionOptimum o;
    if (!selection_optimum(initial_levels, w, rows, caps.rows, options.selection.count == BudgetCount::triangles,
                           selection_budget, kOptimumCells, o))
      return;
    const double b = selection_benefit(std::span<const uint8_t>(f.levels.data(), v), w, rows, caps.rows);
    f.benefit_optimum_fraction = o.benefit > 0 ? std::min(1.0, b / o.benefit) : 1.0;
    f.benefit_optimum_exact = o.exact;
  }

  ChunkTotals sum_counts(const uint32_t* counts) const {
    const ModelTable& rows = caps.rows;
    ChunkTotals t;
    for (size_t at = 0; at < level_total; ++at) {
      uint64_t n = 0;
      for (size_t lane = 0; lane < kCountLanes; ++lane) n += counts[lane * level_total + at];
      if (n == 0) continue;
      const int32_t l = rows.level_l[at];
      t.tris_in_view += n * full_triangles[at];
      t.tris_selected += n * rows.triangles[at];
      t.culled += rows.triangles[at] == 0 ? static_cast<uint32_t>(n) : 0u;
      t.level_cost += n << std::clamp(l, 0, 63);
      t.histogram[static_cast<size_t>(std::clamp<int32_t>(l, 0, kHistogramLevels - 1))] += static_cast<uint32_t>(n);
    }
    return t;
  }

  // Forgets last frame's levels so that the next frame starts from scratch.
  void reset_temporal_state() {
    last_morph_extra = 0;
    store->reset_temporal_state();
    if (options.terrain) terrain_lod_reset(terrain, *options.terrain, options.geomorph_seconds);
  }

  struct FrameBody {
    Impl* self;
    char& sync_byte() const { return *reinterpret_cast<char*>(const_cast<FrameBody*>(this)); }
    void operator()() const {
      tsan_acquire(sync_byte());
      self->fire_graph();
    }
  };
  // Starts the roots and waits for every node; then hands the nodes' writes to the caller.
  void fire_graph() {
    const auto join_nodes = [this] {
      for (char& d : sync.done) tsan_acquire(d);
      tsan_release(sync.finish);
    };
    start->try_put(tbb::flow::continue_msg());
    try {
      graph->wait_for_all();
    } catch (...) {
      join_nodes();
      throw;
    }
    join_nodes();
  }

  // Room in each per-entry array for the most entries any frame has had: every pool slot takes
  // that size the next time it is written, not whenever it first happens to hold a frame that
  // large (a late step of a whole frame, ~4.4 MB at 100,000 objects, that the soak test saw).
  // An eighth more, so that a peak creeping up by a few objects does not copy every slot again.
  static void reserve_entries(Frame& f, size_t entries) {
    auto room = [entries](auto& v) {
      if (v.capacity() < entries) v.reserve(entries + entries / 8);
    };
    room(f.handles), room(f.models), room(f.transforms), room(f.view_masks);
    room(f.objects), room(f.levels), room(f.morph), room(f.from_levels);
  }

  void run(const FrameInput& in, ObjectStore& objects, Frame& f) {
    const auto t0 = Clock::now();
    assert(!in.views.empty() && in.views.size() <= kMaxViews);
    input = &in;
    store = &objects;
    out = &f;
    reserve_entries(f, entries_high);
    time = in.time;
    const uint32_t vc = static_cast<uint32_t>(std::clamp<size_t>(in.views.size(), 1, kMaxViews));
    if (vc != view_count) {
      view_count = vc;
      resize_chunks();
    }
    for (uint32_t v = 0; v < view_count; ++v) views[v] = in.views[std::min<size_t>(v, in.views.size() - 1)];
    stage_ms.fill(0);
    plan_terrain_share();
    f.index = ++frame_index;
    f.time_s = time;
    // The body may run on a worker when the arena has no free slot: it acquires on its own
    // address, before it reads a member, what this thread released there.
    FrameBody body{this};
    tsan_release(sync.start);
    tsan_release(body.sync_byte());
    try {
      arena.execute(body);
    } catch (...) {
      tsan_acquire(sync.finish);
      graph->reset();
      reset_temporal_state();
      out = nullptr;
      f.tick = tick;
      throw;
    }
    tsan_acquire(sync.finish);
    out = nullptr;
    input = nullptr;
    f.tick = tick;
    f.view_count = view_count;
    for (uint32_t v = 0; v < kMaxViews; ++v) f.views[v] = v < view_count ? camera_of(views[v]) : Camera{};
    f.stage_ms = stage_ms;
    f.total_ms = ms_between(t0, Clock::now());
    entries_high = std::max(entries_high, f.objects.size());
  }
};

// The node table. Reads/writes are what each node's runtime stages touch; edges follow.
const FrameGraph::Impl::NodeSpec FrameGraph::Impl::kNodes[] = {
    {Stage::commit, "apply_commands: staged creates, destroys, moves, options", 0, kObjects,
     &Impl::node_commit},
    {Stage::bounds, "world_spheres + object_controls, parallel", kObjects, kBounds | kControls, &Impl::node_bounds},
    {Stage::view, "frustum planes, focal length per view", 0, kViews, &Impl::node_view},
    {Stage::visibility, "cull_spheres (+ cull_beyond_distance) per view + combine_view_masks; occlusion: gather_occluders, rasterize_occluder, sphere_occluded; parallel", kBounds | kControls | kViews,
     kVisibility, &Impl::node_visibility},
    {Stage::scene_hlod, "select_scene_hlod_cut (view 0) + the objects drawn proxies stand for leave the visible set, serial",
     kObjects | kBounds | kControls | kViews | kVisibility, kVisibility | kSceneHlod, &Impl::node_scene_hlod},
    {Stage::importance,
     "measure_objects + minima, importance_weights + choose_initial_levels per view, combine_view_choice, "
     "apply_object_controls, compaction, gather_selection, parallel",
     kObjects | kBounds | kControls | kViews | kVisibility | kHistory, kEntries | kLevels, &Impl::node_importance},
    {Stage::selection, "lower_under_budget (greedy, greedy_multi or benefit_cost): heap over the visible set, serial", kEntries | kLevels | kSceneHlod, kLevels,
     &Impl::node_selection},
    {Stage::entries, "handles, transforms, view masks of the entries, parallel", kEntries | kObjects | kVisibility,
     kPlacing, &Impl::node_entries},
    {Stage::geomorph, "advance_level_blends, parallel; strict budgets: fit_blends_to_room, serial", kEntries | kLevels | kHistory, kBlend, &Impl::node_geomorph},
    {Stage::vdlod, "front_update per visible view-dependent object (view 0), parallel",
     kEntries | kPlacing | kLevels | kViews, kFronts, &Impl::node_vdlod},
    {Stage::vd_mesh, "vertex_morph_positions + compact meshes of vd objects, parallel", kEntries | kFronts, kVdMesh,
     &Impl::node_vd_mesh},
    {Stage::hlod, "select_hlod_cut per HLOD model (view 0, M minus the discrete selection) + pager update, serial",
     kLevels | kViews | kSceneHlod, kHlod, &Impl::node_hlod},
    {Stage::terrain, "terrain_lod_update (ROAM, view 0, its share of M; geomorphs) + terrain_compact_mesh, serial", kViews, kTerrain,
     &Impl::node_terrain},
    {Stage::publish, "totals, measure_selection_quality, levels -> history, parallel", kEntries | kLevels | kVisibility | kBlend | kHlod | kSceneHlod | kTerrain,
     kTotals | kHistory, &Impl::node_publish},
};

std::shared_ptr<const ModelSet> make_model_set(std::vector<std::shared_ptr<const LodChain>> chains) {
  auto s = std::make_shared<ModelSet>();
  s->chains = std::move(chains);
  ModelTable& t = s->models;
  for (const auto& c : s->chains) {
    assert(!c->levels.empty() && c->levels.size() <= kMaxLevels);
    t.first_level.push_back(static_cast<uint32_t>(t.triangles.size()));
    t.level_count.push_back(static_cast<uint8_t>(c->levels.size()));
    t.radius.push_back(c->levels.front().bounds.radius);
    for (const LodLevel& lv : c->levels) {
      t.triangles.push_back(lv.triangles());
      t.level_l.push_back(lv.level);
      t.error.push_back(lv.error);
    }
    s->spheres.push_back(chain_sphere(*c));
  }
  return s;
}

namespace {

std::shared_ptr<const ModelSet> model_set_of(const Scene& scene) {
  std::vector<std::shared_ptr<const LodChain>> chains;
  for (const LodChain& c : scene.chains) chains.push_back(std::make_shared<const LodChain>(c));
  return make_model_set(std::move(chains));
}

}  // namespace

FrameGraph::FrameGraph(std::shared_ptr<const ModelSet> models, const FrameGraphOptions& options)
    : impl_(std::make_unique<Impl>(std::move(models), options)) {}

FrameGraph::FrameGraph(const Scene& scene, const FrameGraphOptions& options)
    : impl_(std::make_unique<Impl>(model_set_of(scene), options)) {
  ObjectStore& s = impl_->own_store;
  const ObjectSet& o = scene.objects;
  for (uint32_t i = 0; i < o.size(); ++i) s.insert(make_handle(i, 1), o.model[i], transform_of(o, i), ObjectOptions{});
}

FrameGraph::~FrameGraph() = default;

void FrameGraph::run(const FrameInput& input, ObjectStore& objects, Frame& out) { impl_->run(input, objects, out); }

void FrameGraph::run(const View& view, Frame& out) {
  Impl& m = *impl_;
  m.own_clock = double(m.frame_index + 1) * m.options.frame_seconds;
  FrameInput in;
  in.views = std::span(&view, 1);
  in.time = m.own_clock;
  m.run(in, m.own_store, out);
}

void FrameGraph::set_models(std::shared_ptr<const ModelSet> models) { impl_->set_models(std::move(models)); }
void FrameGraph::set_budget(uint64_t budget) { impl_->options.selection.budget = budget; }
void FrameGraph::set_pixel_error(float pixels) { impl_->options.pixel_error = pixels; }
void FrameGraph::set_hysteresis(float band) { impl_->options.hysteresis = band; }
void FrameGraph::set_geomorph_seconds(float seconds) { impl_->options.geomorph_seconds = seconds; }
void FrameGraph::set_scene_hlod(std::shared_ptr<const SceneHlodTree> tree) {
  impl_->options.scene_hlod = std::move(tree);
  impl_->scene_refresh = true;
}
const FrameGraphOptions& FrameGraph::options() const { return impl_->options; }
ObjectStore& FrameGraph::scene_objects() { return impl_->own_store; }

std::string FrameGraph::dot() {
  using Impl = FrameGraph::Impl;
  static_assert(std::size(Impl::kNodes) == kStageCount, "one node per Stage");
  const auto pred = Impl::reduced_predecessors();
  std::string s = "digraph frame_graph {\n  rankdir=LR;\n  node [shape=box, fontname=\"Helvetica\"];\n";
  auto columns = [](uint32_t bits) {
    std::string c;
    for (uint32_t b = bits; b; b &= b - 1) {
      if (!c.empty()) c += ", ";
      c += kColumnNames[std::countr_zero(b)];
    }
    return c.empty() ? std::string("-") : c;
  };
  for (const Impl::NodeSpec& n : Impl::kNodes) {
    const char* name = kStageNames[static_cast<size_t>(n.stage)];
    s += "  " + std::string(name) + " [label=\"" + name + "\\n" + n.does + "\\nreads: " + columns(n.reads) +
         "\\nwrites: " + columns(n.writes) + "\"];\n";
  }
  for (size_t j = 0; j < Impl::kNodeCount; ++j)
    for (uint32_t p = pred[j]; p; p &= p - 1)
      s += "  " + std::string(kStageNames[static_cast<size_t>(Impl::kNodes[std::countr_zero(p)].stage)]) + " -> " +
           kStageNames[static_cast<size_t>(Impl::kNodes[j].stage)] + ";\n";
  s += "}\n";
  return s;
}

}  // namespace lod
