#include "cli/run_report.h"

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli/svg_plot.h"
#include "runtime/file_write.h"

namespace lod::cli {
namespace {

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const double pos = p * double(v.size() - 1);
  const size_t i = size_t(pos);
  const double t = pos - double(i);
  return i + 1 < v.size() ? v[i] * (1 - t) + v[i + 1] * t : v[i];
}

Status write_file(const std::filesystem::path& file, const std::string& text) {
  return write_file_atomic(file, text);
}

nlohmann::json or_null(bool measured, double value) { return measured ? nlohmann::json(value) : nlohmann::json(); }

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

}  // namespace

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

// Min and sum (summarize divides) of the fraction of the optimum over the frames measured.
void summarize_optimum_fraction(const FrameRecord& r, RunSummary& s) {
  if (r.benefit_optimum_fraction < 0) return;
  s.min_benefit_optimum_fraction =
      s.optimum_frames == 0 ? r.benefit_optimum_fraction : std::min(s.min_benefit_optimum_fraction, r.benefit_optimum_fraction);
  s.mean_benefit_optimum_fraction += r.benefit_optimum_fraction;
  ++s.optimum_frames;
}

void summarize(const std::vector<FrameRecord>& records, RunSummary& s) {
  s.frames = records.size();
  s.optimum_frames = 0;
  s.min_benefit_optimum_fraction = s.mean_benefit_optimum_fraction = 0;
  s.over_budget_frames = 0;
  s.binding_frames = 0;
  std::vector<double> total;
  std::array<std::vector<double>, kStageCount> stage;
  double vis = 0, inview = 0, sel = 0, drawn = 0, occluded = 0, culled = 0, benefit = 0, changes = 0, px = 0;
  s.max_pixel_error = 0;
  s.max_resident_bytes = s.total_holes = 0;
  double hlod_nodes = 0, proxies = 0, proxy_objects = 0, draws = 0, terrain_tris = 0;
  s.max_drawn_over_budget = 0;
  s.frames_drawn_over_budget = 0;
  for (const auto& r : records) {
    s.over_budget_frames += r.over_budget;
    s.binding_frames += (r.lowered_steps > 0 || r.over_budget);
    total.push_back(r.total_ms);
    for (size_t i = 0; i < kStageCount; ++i) stage[i].push_back(r.stage_ms[i]);
    vis += r.visible;
    inview += double(r.tris_in_view);
    sel += double(r.tris_selected);
    const double d = double(r.tris_selected + r.tris_morph_extra);
    drawn += d;
    if (r.budget > 0) s.max_drawn_over_budget = std::max(s.max_drawn_over_budget, d / double(r.budget));
    s.frames_drawn_over_budget += d > double(r.budget);
    occluded += r.occluded;
    culled += r.culled;
    benefit += r.benefit;
    summarize_optimum_fraction(r, s);
    changes += r.level_changes;
    px += r.pixel_error_mean;
    s.max_pixel_error = std::max(s.max_pixel_error, double(r.pixel_error_max));
    s.max_resident_bytes = std::max(s.max_resident_bytes, r.resident_bytes);
    s.total_holes += r.holes;
    hlod_nodes += r.hlod_nodes_drawn;
    proxies += r.scene_proxies;
    proxy_objects += r.proxy_objects;
    draws += double(r.draws());
    terrain_tris += double(r.terrain_tris);
    s.stream_loads = std::max(s.stream_loads, r.stream_loads);  // counters: the last frame's
    s.stream_evictions = std::max(s.stream_evictions, r.stream_evictions);
    s.stream_failures = std::max(s.stream_failures, r.stream_failures);
  }
  s.mean_hlod_nodes_drawn = hlod_nodes / std::max<double>(1, double(records.size()));
  const double n = std::max<double>(1, double(records.size()));
  s.median_ms = percentile(total, 0.5);
  s.p99_ms = percentile(total, 0.99);
  s.max_ms = total.empty() ? 0 : *std::max_element(total.begin(), total.end());
  double sum = 0;
  for (double t : total) sum += t;
  s.mean_ms = sum / n;
  for (size_t i = 0; i < kStageCount; ++i) s.median_stage_ms[i] = percentile(stage[i], 0.5);
  s.mean_visible = vis / n;
  s.mean_tris_in_view = inview / n;
  s.mean_tris_selected = sel / n;
  s.mean_tris_drawn = drawn / n;
  s.mean_occluded = occluded / n;
  s.mean_culled = culled / n;
  s.mean_benefit = benefit / n;
  if (s.optimum_frames > 0) s.mean_benefit_optimum_fraction /= double(s.optimum_frames);
  s.mean_level_changes = changes / n;
  s.mean_pixel_error = px / n;
  s.mean_scene_proxies = proxies / n;
  s.mean_proxy_objects = proxy_objects / n;
  s.mean_draws = draws / n;
  s.mean_terrain_tris = terrain_tris / n;
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
  std::snprintf(buf, sizeof buf,
                "summary: %zu frames, %zu objects of %zu models, %u threads, budget M = %llu (%s)\n"
                "  frame graph: median %.3f ms, p99 %.3f ms, mean %.3f ms, max %.3f ms\n",
                s.frames, s.objects, s.models, s.threads, (unsigned long long)s.budget, s.budget_count.c_str(),
                s.median_ms, s.p99_ms, s.mean_ms, s.max_ms);
  o << buf << "  median per stage:";
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

Status write_json(const std::filesystem::path& file, const std::vector<FrameRecord>& records, const RunSummary& s) {
  nlohmann::json j;
  j["frames"] = nlohmann::json::array();
  for (const auto& r : records) j["frames"].push_back(frame_json(r));
  j["summary"] = summary_json(s);
  if (file.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(file.parent_path(), ec);
  }
  return write_file(file, j.dump(1) + "\n");
}

namespace {

// The plots of what selection did: drawn vs M (linear), objects per level, level changes and
// the pixel error left.
Status write_selection_plots(const std::filesystem::path& dir, const std::vector<FrameRecord>& records,
                             const RunSummary& s) {
  PlotSeries drawn{"drawn (selected + blends)", "#d62728", {}}, selected{"selected", "#1f77b4", {}},
      budget{"budget M", "#2ca02c", {}, true};
  PlotSeries changes{"level changes", "#9467bd", {}}, culled{"culled", "#7f7f7f", {}, true};
  PlotSeries px_max{"worst", "#d62728", {}}, px_mean{"mean", "#1f77b4", {}};
  size_t levels_used = 1;
  for (const auto& r : records) {
    drawn.values.push_back(double(r.drawn()));
    selected.values.push_back(double(r.tris_selected));
    budget.values.push_back(double(r.budget));
    changes.values.push_back(r.level_changes);
    culled.values.push_back(r.culled);
    px_max.values.push_back(r.pixel_error_max);
    px_mean.values.push_back(r.pixel_error_mean);
    for (size_t l = 0; l < kMaxLevels; ++l)
      if (r.chain_levels[l]) levels_used = std::max(levels_used, l + 1);
  }
  PlotOptions o;
  o.title = "Drawn triangles (with level blends) vs the budget (" + s.config + ")";
  o.y_label = "triangles";
  if (auto st = write_file(dir / "drawn.svg", svg_line_plot({drawn, selected, budget}, o)); !st) return st;

  static const char* colors[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b",
                                 "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};
  std::vector<PlotSeries> per_level;
  for (size_t l = 0; l < levels_used; ++l) {
    PlotSeries ps{"level " + std::to_string(l), colors[l % 10], {}};
    for (const auto& r : records) ps.values.push_back(r.chain_levels[l]);
    per_level.push_back(std::move(ps));
  }
  per_level.push_back(culled);
  o.title = "Objects per chain level (0 = full detail; culled: not drawn)";
  o.y_label = "objects";
  if (auto st = write_file(dir / "levels.svg", svg_line_plot(per_level, o)); !st) return st;
  o.title = "Level changes per frame (objects visible last frame at another level)";
  o.y_label = "objects";
  if (auto st = write_file(dir / "level_changes.svg", svg_line_plot({changes}, o)); !st) return st;
  o.title = "Screen-space error left by the selected levels (view 0)";
  o.y_label = "pixels";
  return write_file(dir / "pixel_error.svg", svg_line_plot({px_max, px_mean}, o));
}

}  // namespace

Status write_report(const std::filesystem::path& dir, const std::vector<FrameRecord>& records, const RunSummary& s,
                    const std::string& graph_dot) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return Status::error(dir.string() + ": cannot create report directory: " + ec.message());

  std::ostringstream csv;
  csv << "frame,objects,visible,tris_in_view,tris_selected,tris_drawn,tris_blend_extra,level_cost,budget,coarsest_cost,"
         "over_budget,lowered_steps,levels_lowered,culled,level_changes,benefit,pixel_error_max,pixel_error_mean";
  for (size_t i = 0; i < kStageCount; ++i) csv << "," << kStageNames[i] << "_ms";
  csv << ",total_ms\n";
  for (const auto& r : records) {
    csv << r.frame << "," << r.objects << "," << r.visible << "," << r.tris_in_view << "," << r.tris_selected << ","
        << r.drawn() << "," << r.tris_morph_extra << "," << r.level_cost << "," << r.budget << "," << r.coarsest_cost
        << "," << (r.over_budget ? 1 : 0) << "," << r.lowered_steps << "," << r.levels_lowered << "," << r.culled << ","
        << r.level_changes << "," << r.benefit << "," << r.pixel_error_max << "," << r.pixel_error_mean;
    for (size_t i = 0; i < kStageCount; ++i) csv << "," << r.stage_ms[i];
    csv << "," << r.total_ms << "\n";
  }
  if (auto st = write_file(dir / "frames.csv", csv.str()); !st) return st;
  if (auto st = write_file(dir / "summary.json", summary_json(s).dump(1) + "\n"); !st) return st;
  if (auto st = write_file(dir / "graph.dot", graph_dot); !st) return st;

  PlotSeries in_view{"in view (full detail)", "#d62728", {}}, selected{"selected", "#1f77b4", {}},
      budget{"budget M", "#2ca02c", {}, true};
  for (const auto& r : records) {
    in_view.values.push_back(double(r.tris_in_view));
    selected.values.push_back(double(r.tris_selected));
    budget.values.push_back(double(r.budget));
  }
  PlotOptions tri_opt;
  tri_opt.title = "Triangles per frame: in view, selected, budget (" + s.config + ")";
  tri_opt.y_label = "triangles (log)";
  tri_opt.log_y = true;
  if (auto st = write_file(dir / "triangles.svg", svg_line_plot({in_view, selected, budget}, tri_opt)); !st) return st;
  if (auto st = write_selection_plots(dir, records, s); !st) return st;

  static const char* colors[] = {"#7f7f7f", "#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2"};
  std::vector<PlotSeries> stages;
  for (size_t i = 0; i < kStageCount; ++i) {
    PlotSeries ps{kStageNames[i], colors[i % 7], {}};
    for (const auto& r : records) ps.values.push_back(r.stage_ms[i]);
    stages.push_back(std::move(ps));
  }
  PlotSeries total{"total", "#000000", {}};
  for (const auto& r : records) total.values.push_back(r.total_ms);
  stages.push_back(std::move(total));
  PlotOptions ms_opt;
  ms_opt.title = "Frame graph milliseconds per stage (" + std::to_string(s.threads) + " threads)";
  ms_opt.y_label = "ms";
  return write_file(dir / "stage_ms.svg", svg_line_plot(stages, ms_opt));
}

}  // namespace lod::cli
