// RunReport: the per-frame figures of `lod run` and how each is written: the terminal table,
// a frame's JSON object and CSV row, the summary's JSON and text. cli/run_outputs.h streams
// them to the files; cli/run_totals.h sums the frames into the summary.
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "runtime/frame.h"
#include "runtime/model_table.h"
#include "runtime/status.h"

namespace lod::cli {

struct FrameRecord {
  uint64_t frame = 0;
  uint32_t objects = 0, visible = 0;
  uint64_t tris_in_view = 0, tris_selected = 0, level_cost = 0, budget = 0, coarsest_cost = 0;
  bool over_budget = false;
  uint32_t lowered_steps = 0;
  std::array<uint32_t, kHistogramLevels> levels{};
  std::array<double, kStageCount> stage_ms{};
  double total_ms = 0;
  uint64_t vd_active_tris = 0, vd_splits = 0, vd_collapses = 0;  // view-dependent objects
  uint32_t morphing = 0;             // objects blending two levels (drawn at the finer one)
  uint64_t tris_morph_extra = 0;     // what that adds to tris_selected
  uint64_t budget_morph_reserve = 0; // held back from M for last frame's blends
  uint64_t tick = 0;                 // the commit the frame was computed from
  uint32_t occluded = 0;             // frustum-visible objects occlusion culled
  uint32_t levels_lowered = 0;       // levels selection lowered (lowered_steps counts heap pops)
  uint32_t culled = 0;               // at a culled level, or beyond lod.max_distance
  uint32_t level_changes = 0;        // entries at another level than last frame
  double benefit = 0;                // the oracle's benefit of the selected levels (view 0)
  double benefit_optimum_fraction = -1;  // over the optimum of the same problem; -1: not measured
  bool benefit_optimum_exact = false;    // against the exact optimum (else an upper bound of it)
  float pixel_error_max = 0, pixel_error_mean = 0;  // screen-space error left (view 0)
  std::array<uint32_t, kMaxLevels> chain_levels{};  // objects per chain level index
  // HLOD models (the hlod node): nodes drawn, pager bytes and counters, holes (must be 0).
  uint32_t hlod_nodes_drawn = 0, holes = 0;
  uint64_t hlod_tris = 0, resident_bytes = 0, stream_requests = 0, stream_loads = 0, stream_evictions = 0,
           stream_failures = 0;
  uint64_t terrain_tris = 0, terrain_splits = 0, terrain_merges = 0;  // [[terrain]] (ROAM)
  uint32_t terrain_morphing = 0;  // its vertices geomorphing
  uint32_t terrain_time_bound = 0;  // 1: [[terrain]] max_ms stopped ROAM's update

  // Scene HLOD: proxies drawn, the static objects they stand for, their triangles.
  uint32_t scene_proxies = 0, proxy_objects = 0;
  uint64_t proxy_tris = 0;

  uint64_t drawn() const { return tris_selected + tris_morph_extra; }  // with blends
  // Draw calls a renderer makes without instancing: entries, proxies, HLOD nodes.
  uint64_t draws() const { return uint64_t(visible) + scene_proxies + hlod_nodes_drawn; }
};

FrameRecord record_of(const Frame& frame);

// Why a run ended before its frames were all run (or did not).
enum class RunStop { frames, max_seconds, signal };
const char* run_stop_name(RunStop stop);  // "frames", "max_seconds", "signal"

struct RunSummary {
  std::string config;
  size_t frames = 0, over_budget_frames = 0, binding_frames = 0;
  size_t frames_requested = 0;  // --frames or the config's
  RunStop stop = RunStop::frames;
  double max_seconds = 0;       // --max-seconds (0: none)
  int stop_signal = 0;          // RunStop::signal: SIGINT or SIGTERM
  size_t objects = 0, models = 0;
  uint32_t threads = 0;
  uint64_t budget = 0;
  std::string budget_count;
  double median_ms = 0, p99_ms = 0, mean_ms = 0, max_ms = 0;
  std::array<double, kStageCount> median_stage_ms{};
  // The percentiles (median, p99, medians per stage) are exact up to QuantileSketch's exact
  // capacity; past it they come from its histogram, within this relative error (0: exact).
  double percentile_relative_error = 0;
  uint64_t plot_frames_per_bucket = 1;  // the plots' min/max buckets (1: every frame drawn)
  double mean_visible = 0, mean_tris_in_view = 0, mean_tris_selected = 0;
  // Drawn = selected + what blends add (triangle budgets): the mean and the worst frame vs M.
  double mean_tris_drawn = 0, max_drawn_over_budget = 0;
  size_t frames_drawn_over_budget = 0;  // drawn (blends included) > M
  double mean_occluded = 0;             // objects occlusion culled per frame
  double mean_culled = 0;               // culled level or beyond lod.max_distance, per frame
  double mean_benefit = 0, mean_level_changes = 0;
  // Frames whose fraction of the optimum was measured (<= 300 entries), its min and mean there.
  size_t optimum_frames = 0;
  double min_benefit_optimum_fraction = 0, mean_benefit_optimum_fraction = 0;
  double mean_pixel_error = 0, max_pixel_error = 0;
  // HLOD models: the most bytes resident on any frame against [stream] budget_mb, holes summed.
  size_t hlod_models = 0;
  uint64_t stream_budget = 0, max_resident_bytes = 0, total_holes = 0, stream_loads = 0, stream_evictions = 0,
           stream_failures = 0;
  std::vector<std::string> stream_failed;  // each failed node read: file, node and why
  double mean_hlod_nodes_drawn = 0;
  double mean_scene_proxies = 0, mean_proxy_objects = 0, mean_draws = 0;
  size_t scene_hlod_nodes = 0;  // proxies in the scene HLOD (0: off)
  // [[terrain]]: mean triangles, and frames --validate found with a crack or T-junction.
  double mean_terrain_tris = 0;
  size_t terrain_failures = 0;
  double bake_ms = 0;
  size_t baked_models = 0, cached_models = 0;
  double wall_s = 0;
};

// What the per-frame table's columns mean (printed under its header).
std::string table_legend();
std::string table_header();
std::string table_row(const FrameRecord& r);
std::string summary_text(const RunSummary& s);

// One frame's object in the --json file's "frames" array, and the "summary" object (also
// the report's summary.json).
nlohmann::json frame_json(const FrameRecord& r);
nlohmann::json summary_json(const RunSummary& s);
// frames.csv: its header line and one frame's line, each ending in a newline.
std::string csv_header();
std::string csv_row(const FrameRecord& r);

}  // namespace lod::cli
