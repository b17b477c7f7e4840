// FrameGraph: the per-frame tbb::flow::graph, built once from a table of nodes and fired every
// frame. Each node runs runtime/ stages over the columns it names; edges follow from what the
// nodes read and write (FrameGraph::dot() draws the same table), so nodes with no data
// dependency run at the same time:
//
//   commit -> bounds --+
//   view --------------+-> visibility -> scene_hlod -> importance -> selection -+-> geomorph -> publish
//                                                                                +-> vdlod -> vd_mesh
//                                                                                +-> hlod ------------+
//   view -> terrain ------------------------------------------------------------------------------+
//
// scene_hlod (after visibility): view 0's cut of the scene HLOD (runtime/scene_hlod_cut); the
// static objects a drawn proxy stands for leave view 0's visible set, and the proxies'
// triangles come off M before selection.
// hlod (HLOD models, jobs/hlod_stream): view 0's cut of every model from what is resident, then
// the pager's update (never waits on I/O; loader threads read the .hlod files). One M: when the
// discrete objects' initial levels and last frame's wanted cuts do not fit together, selection
// gets M in proportion to its demand (runtime/budget_split.h); the cuts get what it leaves,
// split evenly over the models, each undoing its least visible refinements first (levels
// budgets: no cap).
// terrain ([[terrain]], runtime/terrain_lod): ROAM for view 0 under the terrain's share of M,
// set before the frame from the last frame's feedback; selection and hlod get M minus it, so
// the node needs nothing the others write and runs beside visibility, importance and selection.
// The flow-graph headers stay in frame_graph.cpp.
#pragma once
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "jobs/hlod_models.h"
#include "jobs/scene.h"
#include "runtime/frame.h"
#include "runtime/initial_levels.h"
#include "runtime/object_commands.h"
#include "runtime/object_store.h"
#include "runtime/occlusion.h"
#include "runtime/scene_hlod_tree.h"
#include "runtime/slc_selection.h"
#include "runtime/terrain_lod.h"
#include "runtime/view.h"

namespace lod {

struct FrameGraphOptions {
  uint32_t threads = 0;            // task_arena concurrency; 0 = all cores
  SelectionParams selection;
  float pixel_error = 1.0f;
  float hysteresis = 0.25f;
  float max_distance = 0;          // objects whose sphere lies farther are not drawn; 0 = no limit
  // Frame::benefit and pixel_error_* (runtime/selection_quality.h): one more pass over the
  // entries in publish (measured: +0.1 ms at 25,000 visible on 2 threads), so only when asked;
  // services made from a config (lod run) ask.
  bool measure_quality = false;
  uint32_t grain = 2048;           // objects per parallel chunk
  // View-dependent objects and geomorphing: a level change, split or collapse blends over
  // geomorph_seconds (0 = none). run(view, out) steps the clock by frame_seconds.
  float geomorph_seconds = 0.25f;
  float frame_seconds = 1.0f / 60;
  float vd_hysteresis = 1.5f;      // FrontParams::hysteresis
  // Occlusion culling for view 0 (runtime/occlusion.h): the `occluders` objects of largest
  // angular size are rasterised at their finest level of at most `occluder_triangles`.
  struct Occlusion {
    bool enabled = false;
    int width = 320, height = 180;     // depth buffer pixels
    uint32_t occluders = 48;
    uint32_t occluder_triangles = 256;
    // Empty: occluders are rasterised. Set ([visibility] occlusion_method = "embree"): a tracer
    // made once per frame graph fills the buffer by ray casting instead (runtime/occlusion.h).
    std::function<std::unique_ptr<OcclusionTracer>()> make_tracer;
  } occlusion;
  // Called at the start of every stage, on the thread running it (tracing; tests inject
  // failures by throwing from it). Empty = no call.
  std::function<void(Stage)> stage_hook;
  // Streamed HLOD models drawn by the hlod node (none: the node does nothing).
  std::shared_ptr<const HlodModels> hlod;
  // Scene HLOD over static objects (handles bound), cut by the scene_hlod node; none: nothing.
  std::shared_ptr<const SceneHlodTree> scene_hlod;
  // The terrain drawn by the terrain node (none: the node does nothing).
  std::shared_ptr<const TerrainModel> terrain;
};

// The models a graph draws from: chains shared (adding a model copies none), plus the tables
// the stages read. Immutable once made.
struct ModelSet {
  std::vector<std::shared_ptr<const LodChain>> chains;
  ModelTable models;
  std::vector<Sphere> spheres;  // per model: chain_sphere
};
std::shared_ptr<const ModelSet> make_model_set(std::vector<std::shared_ptr<const LodChain>> chains);

// What one frame runs on besides the objects.
struct FrameInput {
  std::span<const View> views;               // 1..kMaxViews; view 0 drives view-dependent fronts
  double time = 0;                           // seconds on the blend clock, non-decreasing
  std::span<const CommitBatchRef> commits;   // applied in order by the commit node
};

class FrameGraph {
 public:
  FrameGraph(std::shared_ptr<const ModelSet> models, const FrameGraphOptions& options);
  // A fixed scene: its objects go into a store the graph owns (run(view, out) uses it).
  FrameGraph(const Scene& scene, const FrameGraphOptions& options);
  ~FrameGraph();
  FrameGraph(const FrameGraph&) = delete;
  FrameGraph& operator=(const FrameGraph&) = delete;

  // Runs one frame over `objects` and fills `out` (reusing its capacity). Not re-entrant.
  // Frame indices start at 1 and increase by one per call; out.tick is the tick of the last
  // commit applied so far. If a stage throws, the graph and the temporal state are reset,
  // `out` is left partly written, and the exception propagates (commits already applied stay).
  void run(const FrameInput& input, ObjectStore& objects, Frame& out);
  // The fixed scene's store, the clock advanced by frame_seconds per call.
  void run(const View& view, Frame& out);

  // Between frames (the LOD thread's own calls).
  void set_models(std::shared_ptr<const ModelSet> models);
  void set_budget(uint64_t budget);
  void set_pixel_error(float pixels);
  void set_hysteresis(float band);
  void set_geomorph_seconds(float seconds);
  void set_scene_hlod(std::shared_ptr<const SceneHlodTree> tree);
  const FrameGraphOptions& options() const;
  ObjectStore& scene_objects();  // the fixed scene's store

  // The node table as Graphviz DOT (nodes with what they do, edges from their columns).
  static std::string dot();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lod
