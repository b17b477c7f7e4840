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
  return r;
}

void summarize(const std::vector<FrameRecord>& records, RunSummary& s) {
  s.frames = records.size();
  s.over_budget_frames = 0;
  s.binding_frames = 0;
  std::vector<double> total;
  std::array<std::vector<double>, kStageCount> stage;
  double vis = 0, inview = 0, sel = 0, drawn = 0, occluded = 0;
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
  }
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

Status write_report(const std::filesystem::path& dir, const std::vector<FrameRecord>& records, const RunSummary& s,
                    const std::string& graph_dot) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return Status::error(dir.string() + ": cannot create report directory: " + ec.message());

  std::ostringstream csv;
  csv << "frame,objects,visible,tris_in_view,tris_selected,level_cost,budget,coarsest_cost,over_budget,lowered_steps";
  for (size_t i = 0; i < kStageCount; ++i) csv << "," << kStageNames[i] << "_ms";
  csv << ",total_ms\n";
  for (const auto& r : records) {
    csv << r.frame << "," << r.objects << "," << r.visible << "," << r.tris_in_view << "," << r.tris_selected << ","
        << r.level_cost << "," << r.budget << "," << r.coarsest_cost << "," << (r.over_budget ? 1 : 0) << ","
        << r.lowered_steps;
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
