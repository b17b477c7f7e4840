#include "cli/run_report.h"

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>


namespace lod::cli {
namespace {

nlohmann::json or_null(bool measured, double value) { return measured ? nlohmann::json(value) : nlohmann::json(); }

}  // namespace

nlohmann::json frame_json(const FrameRecord& r) {
  nlohmann::json levels = nlohmann::json::object();
  for (size_t l = 0; l < r.levels.size(); ++l)
    if (r.levels[l]) levels[std::to_string(l)] = r.levels[l];
  nlohmann::json ms = nlohmann::json::object();
  for (size_t s = 0; s < kStageCount; ++s) ms[kStageNames[s]] = r.stage_ms[s];
  ms["total"] = r.total_ms;
  return {{"frame", r.frame},
          {"objects", r.objects},
          {"visible", r.visible},
          {"tris_in_view", r.tris_in_view},
          {"tris_selected", r.tris_selected},
          {"level_cost", r.level_cost},
          {"budget", r.budget},
          {"coarsest_cost", r.coarsest_cost},
          {"over_budget", r.over_budget},
          {"lowered_steps", r.lowered_steps},
          {"levels", levels},
          {"vd_active_tris", r.vd_active_tris},
          {"vd_splits", r.vd_splits},
          {"vd_collapses", r.vd_collapses},
          {"morphing", r.morphing},
          {"tris_morph_extra", r.tris_morph_extra},
          {"budget_morph_reserve", r.budget_morph_reserve},
          {"tick", r.tick},
          {"occluded", r.occluded},
          {"levels_lowered", r.levels_lowered},
          {"culled", r.culled},
          {"level_changes", r.level_changes},
          {"benefit", r.benefit},
          {"benefit_optimum_fraction", or_null(r.benefit_optimum_fraction >= 0, r.benefit_optimum_fraction)},
          {"benefit_optimum_exact", r.benefit_optimum_exact},
          {"pixel_error_max", r.pixel_error_max},
          {"pixel_error_mean", r.pixel_error_mean},
          {"tris_drawn", r.drawn()},
          {"hlod_nodes_drawn", r.hlod_nodes_drawn},
          {"resident_bytes", r.resident_bytes},
          {"stream_requests", r.stream_requests},
          {"stream_loads", r.stream_loads},
          {"holes", r.holes},
          {"scene_proxies", r.scene_proxies},
          {"proxy_objects", r.proxy_objects},
          {"proxy_tris", r.proxy_tris},
          {"draws", r.draws()},
          {"terrain_tris", r.terrain_tris},
          {"terrain_splits", r.terrain_splits},
          {"terrain_merges", r.terrain_merges},
          {"terrain_morphing", r.terrain_morphing},
          {"terrain_time_bound", r.terrain_time_bound},
          {"ms", ms}};
}

nlohmann::json summary_json(const RunSummary& s) {
  nlohmann::json stages = nlohmann::json::object();
  for (size_t i = 0; i < kStageCount; ++i) stages[kStageNames[i]] = s.median_stage_ms[i];
  return {{"config", s.config},
          {"frames", s.frames},
          {"frames_requested", s.frames_requested},
          {"stopped_by", run_stop_name(s.stop)},
          {"max_seconds", or_null(s.max_seconds > 0, s.max_seconds)},
          {"stop_signal", s.stop_signal},
          {"percentile_relative_error", s.percentile_relative_error},
          {"plot_frames_per_bucket", s.plot_frames_per_bucket},
          {"over_budget_frames", s.over_budget_frames},
          {"binding_frames", s.binding_frames},
          {"objects", s.objects},
          {"models", s.models},
          {"threads", s.threads},
          {"budget", s.budget},
          {"budget_count", s.budget_count},
          {"median_ms", s.median_ms},
          {"p99_ms", s.p99_ms},
          {"mean_ms", s.mean_ms},
          {"max_ms", s.max_ms},
          {"median_stage_ms", stages},
          {"mean_visible", s.mean_visible},
          {"mean_tris_in_view", s.mean_tris_in_view},
          {"mean_tris_selected", s.mean_tris_selected},
          {"mean_tris_drawn", s.mean_tris_drawn},
          {"max_drawn_over_budget", s.max_drawn_over_budget},
          {"frames_drawn_over_budget", s.frames_drawn_over_budget},
          {"mean_occluded", s.mean_occluded},
          {"mean_culled", s.mean_culled},
          {"mean_benefit", s.mean_benefit},
          {"optimum_frames", s.optimum_frames},
          {"min_benefit_optimum_fraction", or_null(s.optimum_frames > 0, s.min_benefit_optimum_fraction)},
          {"mean_benefit_optimum_fraction", or_null(s.optimum_frames > 0, s.mean_benefit_optimum_fraction)},
          {"mean_level_changes", s.mean_level_changes},
          {"mean_pixel_error", s.mean_pixel_error},
          {"max_pixel_error", s.max_pixel_error},
          {"hlod_models", s.hlod_models},
          {"stream_budget", s.stream_budget},
          {"max_resident_bytes", s.max_resident_bytes},
          {"total_holes", s.total_holes},
          {"stream_loads", s.stream_loads},
          {"stream_evictions", s.stream_evictions},
          {"stream_failures", s.stream_failures},
          {"stream_failed", s.stream_failed},
          {"mean_hlod_nodes_drawn", s.mean_hlod_nodes_drawn},
          {"scene_hlod_nodes", s.scene_hlod_nodes},
          {"mean_scene_proxies", s.mean_scene_proxies},
          {"mean_proxy_objects", s.mean_proxy_objects},
          {"mean_draws", s.mean_draws},
          {"mean_terrain_tris", s.mean_terrain_tris},
          {"terrain_failures", s.terrain_failures},
          {"bake_ms", s.bake_ms},
          {"baked_models", s.baked_models},
          {"cached_models", s.cached_models},
          {"wall_s", s.wall_s}};
}

const char* run_stop_name(RunStop stop) {
  switch (stop) {
    case RunStop::max_seconds: return "max_seconds";
    case RunStop::signal: return "signal";
    case RunStop::frames: break;
  }
  return "frames";
}

FrameRecord record_of(const Frame& f) {
  FrameRecord r;
  r.frame = f.index;
  r.objects = f.object_count;
  r.visible = f.visible;
  r.tris_in_view = f.tris_in_view;
  r.tris_selected = f.tris_selected;
  r.level_cost = f.level_cost;
  r.budget = f.budget;
  r.coarsest_cost = f.coarsest_cost;
  r.over_budget = f.over_budget;
  r.lowered_steps = f.lowered_steps;
  r.levels = f.level_histogram;
  r.stage_ms = f.stage_ms;
  r.total_ms = f.total_ms;
  r.vd_active_tris = f.vd_active_tris;
  r.vd_splits = f.vd_splits;
  r.vd_collapses = f.vd_collapses;
  r.morphing = f.morphing;
  r.tris_morph_extra = f.tris_morph_extra;
  r.budget_morph_reserve = f.budget_morph_reserve;
  r.tick = f.tick;
  r.occluded = f.occluded;
  r.levels_lowered = f.levels_lowered;
  r.culled = f.culled;
  r.level_changes = f.level_changes;
  r.benefit = f.benefit;
  r.benefit_optimum_fraction = f.benefit_optimum_fraction;
  r.benefit_optimum_exact = f.benefit_optimum_exact;
  r.pixel_error_max = f.pixel_error_max;
  r.pixel_error_mean = f.pixel_error_mean;
  for (uint8_t l : f.levels) ++r.chain_levels[std::min<size_t>(l, kMaxLevels - 1)];
  r.hlod_nodes_drawn = f.hlod_nodes_drawn;
  r.holes = f.holes;
  r.hlod_tris = f.hlod_tris;
  r.resident_bytes = f.resident_bytes;
  r.stream_requests = f.stream_requests;
  r.stream_loads = f.stream_loads;
  r.stream_evictions = f.stream_evictions;
  r.stream_failures = f.stream_failures;
  r.scene_proxies = uint32_t(f.scene_proxies.size());
  r.proxy_objects = f.scene_proxy_objects;
  r.proxy_tris = f.scene_proxy_tris;
  r.terrain_tris = f.terrain_tris;
  r.terrain_splits = f.terrain_splits;
  r.terrain_merges = f.terrain_merges;
  r.terrain_morphing = f.terrain_morphing;
  r.terrain_time_bound = f.terrain_time_bound;
  return r;
}

std::string table_legend() {
  return "  (tris_in_view: the visible objects at full detail; selected: triangles of the chosen levels; budget: M;\n"
         "   over: YES when even the coarsest levels exceed M; lowered: heap pops of selection; *_ms: visibility,\n"
         "   importance and selection stages and the whole frame graph, in milliseconds)";
}

std::string table_header() {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%6s %7s %7s %12s %11s %11s %5s %7s %8s %8s %8s %8s", "frame", "objects", "visible",
                "tris_in_view", "selected", "budget", "over", "lowered", "cull_ms", "imp_ms", "sel_ms", "total_ms");
  return buf;
}

std::string table_row(const FrameRecord& r) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%6llu %7u %7u %12llu %11llu %11llu %5s %7u %8.3f %8.3f %8.3f %8.3f",
                (unsigned long long)r.frame, r.objects, r.visible, (unsigned long long)r.tris_in_view,
                (unsigned long long)r.tris_selected, (unsigned long long)r.budget, r.over_budget ? "YES" : "-",
                r.lowered_steps, r.stage_ms[size_t(Stage::visibility)], r.stage_ms[size_t(Stage::importance)],
                r.stage_ms[size_t(Stage::selection)], r.total_ms);
  return buf;
}

std::string summary_text(const RunSummary& s) {
  std::ostringstream o;
  char buf[512];
  std::snprintf(buf, sizeof buf, "summary: %zu frames, %zu objects of %zu models, %u threads, budget M = %llu (%s)\n",
                s.frames, s.objects, s.models, s.threads, (unsigned long long)s.budget, s.budget_count.c_str());
  o << buf;
  if (s.stop == RunStop::max_seconds) {
    std::snprintf(buf, sizeof buf, "  stopped by --max-seconds %g after %zu of %zu frames\n", s.max_seconds, s.frames,
                  s.frames_requested);
    o << buf;
  } else if (s.stop == RunStop::signal) {
    std::snprintf(buf, sizeof buf, "  stopped by %s after %zu of %zu frames\n",
                  s.stop_signal == SIGINT ? "SIGINT" : s.stop_signal == SIGTERM ? "SIGTERM" : "a signal", s.frames,
                  s.frames_requested);
    o << buf;
  }
  std::snprintf(buf, sizeof buf, "  frame graph: median %.3f ms, p99 %.3f ms, mean %.3f ms, max %.3f ms\n", s.median_ms,
                s.p99_ms, s.mean_ms, s.max_ms);
  o << buf;
  if (s.percentile_relative_error > 0) {
    std::snprintf(buf, sizeof buf,
                  "  (median, p99 and the medians per stage below are approximate: from a histogram, within %.1f %%)\n",
                  100 * s.percentile_relative_error);
    o << buf;
  }
  o << "  median per stage:";
  for (size_t i = 0; i < kStageCount; ++i) {
    std::snprintf(buf, sizeof buf, " %s %.3f", kStageNames[i], s.median_stage_ms[i]);
    o << buf;
  }
  std::snprintf(buf, sizeof buf,
                " ms\n  budget bound on %zu of %zu frames; over budget (coarsest levels exceed M) on %zu frames\n"
                "  mean visible %.0f, mean triangles in view %.0f at full detail, %.0f selected (%.1fx fewer)\n"
                "  drawn with level blends: mean %.0f, worst frame %.3f x M, %zu frames drawn over M\n"
                "  bake: %.0f ms, %zu models baked, %zu from cache; wall %.1f s\n",
                s.binding_frames, s.frames, s.over_budget_frames, s.mean_visible, s.mean_tris_in_view,
                s.mean_tris_selected, s.mean_tris_selected > 0 ? s.mean_tris_in_view / s.mean_tris_selected : 0.0,
                s.mean_tris_drawn, s.max_drawn_over_budget, s.frames_drawn_over_budget, s.bake_ms, s.baked_models,
                s.cached_models, s.wall_s);
  o << buf;
  std::snprintf(buf, sizeof buf,
                "  selection: mean benefit %.4g, %.1f level changes per frame; screen-space error left: mean %.2f px, "
                "worst %.2f px\n",
                s.mean_benefit, s.mean_level_changes, s.mean_pixel_error, s.max_pixel_error);
  o << buf;
  if (s.optimum_frames > 0) {
    std::snprintf(buf, sizeof buf, "  benefit over the optimum (%zu frames of <= 300 entries): min %.4f, mean %.4f\n",
                  s.optimum_frames, s.min_benefit_optimum_fraction, s.mean_benefit_optimum_fraction);
    o << buf;
  }
  if (s.mean_culled > 0) {
    std::snprintf(buf, sizeof buf, "  culled (culled level or beyond lod.max_distance): mean %.0f objects per frame\n",
                  s.mean_culled);
    o << buf;
  }
  if (s.hlod_models > 0) {
    std::snprintf(buf, sizeof buf,
                  "  hlod: %zu models, mean %.1f nodes drawn; resident max %.2f MB of the %.2f MB stream budget; "
                  "%llu loads, %llu evictions, %llu failed reads; %llu holes\n",
                  s.hlod_models, s.mean_hlod_nodes_drawn, double(s.max_resident_bytes) / (1 << 20),
                  double(s.stream_budget) / (1 << 20), (unsigned long long)s.stream_loads,
                  (unsigned long long)s.stream_evictions, (unsigned long long)s.stream_failures,
                  (unsigned long long)s.total_holes);
    o << buf;
    // Which, by file, node and reason (the first few; the JSON summary lists them all).
    constexpr size_t kNamed = 10;
    for (size_t k = 0; k < std::min(kNamed, s.stream_failed.size()); ++k) o << "    failed: " << s.stream_failed[k] << "\n";
    if (s.stream_failed.size() > kNamed) o << "    ... and " << s.stream_failed.size() - kNamed << " more failed reads\n";
  }
  if (s.scene_hlod_nodes > 0) {
    std::snprintf(buf, sizeof buf,
                  "  scene hlod: %zu proxies; mean %.1f drawn per frame standing for %.0f objects; mean %.0f draws "
                  "(entries + proxies + hlod nodes)\n",
                  s.scene_hlod_nodes, s.mean_scene_proxies, s.mean_proxy_objects, s.mean_draws);
    o << buf;
  }
  if (s.mean_terrain_tris > 0) {
    std::snprintf(buf, sizeof buf, "  terrain: mean %.0f triangles (in the budget); %zu frames failed the crack check\n",
                  s.mean_terrain_tris, s.terrain_failures);
    o << buf;
  }
  if (s.mean_occluded > 0) {
    std::snprintf(buf, sizeof buf, "  occlusion: mean %.0f objects in the frustum culled as hidden per frame\n",
                  s.mean_occluded);
    o << buf;
  }
  return o.str();
}

std::string csv_header() {
  std::string h =
      "frame,objects,visible,tris_in_view,tris_selected,tris_drawn,tris_blend_extra,level_cost,budget,coarsest_cost,"
      "over_budget,lowered_steps,levels_lowered,culled,level_changes,benefit,pixel_error_max,pixel_error_mean";
  for (size_t i = 0; i < kStageCount; ++i) h += std::string(",") + kStageNames[i] + "_ms";
  return h + ",total_ms\n";
}

std::string csv_row(const FrameRecord& r) {
  std::ostringstream csv;  // default stream formatting: 6 significant digits, as the file always had
  csv << r.frame << "," << r.objects << "," << r.visible << "," << r.tris_in_view << "," << r.tris_selected << ","
      << r.drawn() << "," << r.tris_morph_extra << "," << r.level_cost << "," << r.budget << "," << r.coarsest_cost
      << "," << (r.over_budget ? 1 : 0) << "," << r.lowered_steps << "," << r.levels_lowered << "," << r.culled << ","
      << r.level_changes << "," << r.benefit << "," << r.pixel_error_max << "," << r.pixel_error_mean;
  for (size_t i = 0; i < kStageCount; ++i) csv << "," << r.stage_ms[i];
  csv << "," << r.total_ms << "\n";
  return csv.str();
}

}  // namespace lod::cli
