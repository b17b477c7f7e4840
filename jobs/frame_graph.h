// FrameGraph: the per-frame tbb::flow::graph, built once and fired every frame.
//
//   view -> visibility -> importance -> selection -> vdlod -> geomorph -> publish
//
// Nodes only coordinate; the work is the pure stages of runtime/, run data-parallel
// (parallel_for over object chunks) inside visibility and importance. The flow-graph
// headers stay in frame_graph.cpp.
#pragma once
#include <functional>
#include <memory>
#include <string>

#include "jobs/scene.h"
#include "runtime/frame.h"
#include "runtime/initial_levels.h"
#include "runtime/slc_selection.h"

namespace lod {

struct FrameGraphOptions {
  uint32_t threads = 0;            // task_arena concurrency; 0 = all cores
  SelectionParams selection;
  float pixel_error = 1.0f;
  float hysteresis = 0.25f;
  uint32_t grain = 2048;           // objects per parallel chunk
  // View-dependent objects and geomorphing: a level change, split or collapse blends over
  // geomorph_seconds (0 = none); frames are frame_seconds apart on the geomorph clock.
  float geomorph_seconds = 0.25f;
  float frame_seconds = 1.0f / 60;
  float vd_hysteresis = 1.5f;      // FrontParams::hysteresis
  // Called at the start of every stage, on the thread running it (tracing; tests inject
  // failures by throwing from it). Empty = no call.
  std::function<void(Stage)> stage_hook;
};

class FrameGraph {
 public:
  FrameGraph(const Scene& scene, const FrameGraphOptions& options);
  ~FrameGraph();
  FrameGraph(const FrameGraph&) = delete;
  FrameGraph& operator=(const FrameGraph&) = delete;

  // Runs one frame for `view` and fills `out` (reusing its capacity). Not re-entrant.
  // Frame indices start at 1 and increase by one per call. If a stage throws, the graph
  // and the temporal state (last frame's levels) are reset, `out` is left partly written,
  // and the exception propagates.
  void run(const View& view, Frame& out);

  void set_budget(uint64_t budget);
  const FrameGraphOptions& options() const;
  // The node/edge table as Graphviz DOT, for `lod run --report`.
  static std::string dot();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lod
