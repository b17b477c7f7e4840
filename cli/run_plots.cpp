#include "cli/run_plots.h"

#include <utility>

#include "cli/svg_plot.h"
#include "runtime/file_write.h"

namespace lod::cli {
namespace {

template <size_t N, size_t... I>
std::array<DecimatedSeries, N> series_array(size_t buckets, std::index_sequence<I...>) {
  return {((void)I, DecimatedSeries(buckets))...};
}

PlotSeries plotted(const DecimatedSeries& d, std::string name, std::string color, bool dashed = false) {
  PlotSeries p{std::move(name), std::move(color), {}, dashed, {}};
  d.points(p.x, p.values);
  return p;
}

}  // namespace

RunPlots::RunPlots(size_t buckets)
    : in_view_(buckets),
      selected_(buckets),
      budget_(buckets),
      drawn_(buckets),
      changes_(buckets),
      culled_(buckets),
      px_max_(buckets),
      px_mean_(buckets),
      total_ms_(buckets),
      levels_(series_array<kMaxLevels>(buckets, std::make_index_sequence<kMaxLevels>())),
      stage_ms_(series_array<kStageCount>(buckets, std::make_index_sequence<kStageCount>())) {}

void RunPlots::add(const FrameRecord& r) {
  in_view_.add(double(r.tris_in_view));
  selected_.add(double(r.tris_selected));
  budget_.add(double(r.budget));
  drawn_.add(double(r.drawn()));
  changes_.add(r.level_changes);
  culled_.add(r.culled);
  px_max_.add(r.pixel_error_max);
  px_mean_.add(r.pixel_error_mean);
  total_ms_.add(r.total_ms);
  for (size_t l = 0; l < kMaxLevels; ++l) {
    levels_[l].add(r.chain_levels[l]);
    if (r.chain_levels[l]) levels_used_ = std::max(levels_used_, l + 1);
  }
  for (size_t i = 0; i < kStageCount; ++i) stage_ms_[i].add(r.stage_ms[i]);
}

Status RunPlots::write(const std::filesystem::path& dir, const RunSummary& s) const {
  PlotOptions o;
  if (frames_per_bucket() > 1)
    o.x_label = "frame (each bucket of " + std::to_string(frames_per_bucket()) +
                " frames drawn at its minimum and maximum)";

  PlotOptions tri = o;
  tri.title = "Triangles per frame: in view, selected, budget (" + s.config + ")";
  tri.y_label = "triangles (log)";
  tri.log_y = true;
  const PlotSeries selected = plotted(selected_, "selected", "#1f77b4"),
                   budget = plotted(budget_, "budget M", "#2ca02c", true);
  if (auto st = write_file_atomic(
          dir / "triangles.svg",
          svg_line_plot({plotted(in_view_, "in view (full detail)", "#d62728"), selected, budget}, tri));
      !st)
    return st;

  o.title = "Drawn triangles (with level blends) vs the budget (" + s.config + ")";
  o.y_label = "triangles";
  if (auto st = write_file_atomic(
          dir / "drawn.svg", svg_line_plot({plotted(drawn_, "drawn (selected + blends)", "#d62728"), selected, budget}, o));
      !st)
    return st;

  static const char* level_colors[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b",
                                       "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};
  std::vector<PlotSeries> per_level;
  for (size_t l = 0; l < levels_used_; ++l)
    per_level.push_back(plotted(levels_[l], "level " + std::to_string(l), level_colors[l % 10]));
  per_level.push_back(plotted(culled_, "culled", "#7f7f7f", true));
  o.title = "Objects per chain level (0 = full detail; culled: not drawn)";
  o.y_label = "objects";
  if (auto st = write_file_atomic(dir / "levels.svg", svg_line_plot(per_level, o)); !st) return st;
  o.title = "Level changes per frame (objects visible last frame at another level)";
  if (auto st = write_file_atomic(dir / "level_changes.svg",
                                  svg_line_plot({plotted(changes_, "level changes", "#9467bd")}, o));
      !st)
    return st;
  o.title = "Screen-space error left by the selected levels (view 0)";
  o.y_label = "pixels";
  if (auto st = write_file_atomic(
          dir / "pixel_error.svg",
          svg_line_plot({plotted(px_max_, "worst", "#d62728"), plotted(px_mean_, "mean", "#1f77b4")}, o));
      !st)
    return st;

  static const char* stage_colors[] = {"#7f7f7f", "#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2"};
  std::vector<PlotSeries> stages;
  for (size_t i = 0; i < kStageCount; ++i) stages.push_back(plotted(stage_ms_[i], kStageNames[i], stage_colors[i % 7]));
  stages.push_back(plotted(total_ms_, "total", "#000000"));
  o.title = "Frame graph milliseconds per stage (" + std::to_string(s.threads) + " threads)";
  o.y_label = "ms";
  return write_file_atomic(dir / "stage_ms.svg", svg_line_plot(stages, o));
}

}  // namespace lod::cli
