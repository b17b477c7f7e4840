// FrameLog: one row per viewer frame (what was drawn, from which LOD frame, how long it took),
// written as CSV with --stats and summarised at exit (viewer frame-time percentiles).
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "runtime/status.h"

namespace lod::viewer {

struct FrameRow {
  uint64_t viewer_frame = 0;
  uint64_t lod_frame = 0;        // Frame::index drawn
  uint32_t visible = 0;
  // Frame::tris_selected with view-dependent objects counted at their active mesh (what is
  // drawn for them) instead of their discrete level: selected_as_drawn().
  uint64_t tris_selected = 0;
  // Objects blending two levels are drawn at the finer one: Frame::tris_morph_extra says what
  // that adds, so drawn == tris_selected + morph_extra (== tris_selected when none morphs).
  uint32_t morphing = 0;         // Frame::morphing
  uint64_t morph_extra = 0;      // Frame::tris_morph_extra
  uint32_t morph_draws = 0;      // blended batches drawn
  uint64_t drawn = 0;            // triangles submitted
  uint32_t vd_objects = 0;       // view-dependent objects drawn from their active mesh
  uint64_t vd_drawn = 0;         // their triangles (part of `drawn`)
  int64_t gpu_primitives = -1;   // GL_PRIMITIVES_GENERATED, -1 when not queried
  uint32_t hlod_nodes = 0;       // Frame::hlod_nodes_drawn
  uint32_t hlod_draws = 0;       // node layers and boundary patches drawn
  uint64_t hlod_drawn = 0;       // their triangles (part of `drawn`; Frame::hlod_tris when none is missing)
  uint32_t hlod_missing = 0;     // cut entries not drawn: node unreadable, or not in the trees
  uint64_t resident_bytes = 0;   // Frame::resident_bytes (the LOD thread's pager)
  uint64_t gpu_node_bytes = 0;   // the viewer's GPU copies of HLOD nodes
  uint32_t proxies = 0;          // scene HLOD proxies drawn
  uint64_t proxy_drawn = 0;      // their triangles (part of `drawn`)
  uint32_t proxy_objects = 0;    // Frame::scene_proxy_objects
  uint32_t draws = 0;
  uint32_t levels_drawn = 0;     // distinct chain levels among the draws
  uint32_t rejected = 0;         // frame entries the draw list refused
  int whole = 1;                 // frame_is_whole()
  double viewer_ms = 0;          // this viewer frame, CPU wall time
  double lod_ms = 0;             // Frame::total_ms
  double service_ms = 0;         // time in lod::Service calls this viewer frame (driven: includes step)
};

struct FrameTimeSummary {
  size_t frames = 0;
  double mean_ms = 0, p50_ms = 0, p95_ms = 0, p99_ms = 0, max_ms = 0;
  double service_max_ms = 0;     // longest time one viewer frame spent in lod::Service calls
  uint64_t lod_frames_seen = 0;  // distinct LOD frames drawn
};

class FrameLog {
 public:
  void add(const FrameRow& row) { rows_.push_back(row); }
  const std::vector<FrameRow>& rows() const { return rows_; }
  // `skip` first frames (start-up) are left out of the percentiles.
  FrameTimeSummary summary(size_t skip) const;
  Status write_csv(const std::filesystem::path& path) const;

 private:
  std::vector<FrameRow> rows_;
};

}  // namespace lod::viewer
