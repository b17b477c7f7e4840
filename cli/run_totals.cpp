#include "cli/run_totals.h"

#include <algorithm>
#include <utility>

namespace lod::cli {
namespace {

template <size_t... I>
std::array<QuantileSketch, sizeof...(I)> sketches(size_t exact, std::index_sequence<I...>) {
  return {((void)I, QuantileSketch(exact))...};
}

}  // namespace

RunTotals::RunTotals(size_t exact_percentiles)
    : total_ms_(exact_percentiles), stage_ms_(sketches(exact_percentiles, std::make_index_sequence<kStageCount>())) {}

void RunTotals::add(const FrameRecord& r) {
  ++frames_;
  over_budget_ += r.over_budget;
  binding_ += (r.lowered_steps > 0 || r.over_budget);
  total_ms_.add(r.total_ms);
  sum_ms_ += r.total_ms;
  for (size_t i = 0; i < kStageCount; ++i) stage_ms_[i].add(r.stage_ms[i]);
  vis_ += r.visible;
  in_view_ += double(r.tris_in_view);
  selected_ += double(r.tris_selected);
  const double d = double(r.tris_selected + r.tris_morph_extra);
  drawn_ += d;
  if (r.budget > 0) max_drawn_over_budget_ = std::max(max_drawn_over_budget_, d / double(r.budget));
  drawn_over_budget_ += d > double(r.budget);
  occluded_ += r.occluded;
  culled_ += r.culled;
  benefit_ += r.benefit;
  if (r.benefit_optimum_fraction >= 0) {  // measured on this frame
    min_optimum_fraction_ = optimum_frames_ == 0 ? r.benefit_optimum_fraction
                                                 : std::min(min_optimum_fraction_, r.benefit_optimum_fraction);
    sum_optimum_fraction_ += r.benefit_optimum_fraction;
    ++optimum_frames_;
  }
  changes_ += r.level_changes;
  px_mean_ += r.pixel_error_mean;
  max_pixel_error_ = std::max(max_pixel_error_, double(r.pixel_error_max));
  max_resident_ = std::max(max_resident_, r.resident_bytes);
  holes_ += r.holes;
  hlod_nodes_ += r.hlod_nodes_drawn;
  proxies_ += r.scene_proxies;
  proxy_objects_ += r.proxy_objects;
  draws_ += double(r.draws());
  terrain_tris_ += double(r.terrain_tris);
  stream_loads_ = std::max(stream_loads_, r.stream_loads);  // counters: the last frame's
  stream_evictions_ = std::max(stream_evictions_, r.stream_evictions);
  stream_failures_ = std::max(stream_failures_, r.stream_failures);
}

void RunTotals::fill(RunSummary& s) const {
  const double n = std::max<double>(1, double(frames_));
  s.frames = frames_;
  s.over_budget_frames = over_budget_;
  s.binding_frames = binding_;
  s.median_ms = total_ms_.percentile(0.5);
  s.p99_ms = total_ms_.percentile(0.99);
  s.max_ms = frames_ ? total_ms_.max() : 0;
  s.mean_ms = sum_ms_ / n;
  bool exact = total_ms_.exact();
  for (size_t i = 0; i < kStageCount; ++i) {
    s.median_stage_ms[i] = stage_ms_[i].percentile(0.5);
    exact = exact && stage_ms_[i].exact();
  }
  s.percentile_relative_error = exact ? 0 : QuantileSketch::kRelativeError;
  s.mean_visible = vis_ / n;
  s.mean_tris_in_view = in_view_ / n;
  s.mean_tris_selected = selected_ / n;
  s.mean_tris_drawn = drawn_ / n;
  s.max_drawn_over_budget = max_drawn_over_budget_;
  s.frames_drawn_over_budget = drawn_over_budget_;
  s.mean_occluded = occluded_ / n;
  s.mean_culled = culled_ / n;
  s.mean_benefit = benefit_ / n;
  s.optimum_frames = optimum_frames_;
  s.min_benefit_optimum_fraction = optimum_frames_ ? min_optimum_fraction_ : 0;
  s.mean_benefit_optimum_fraction = optimum_frames_ ? sum_optimum_fraction_ / double(optimum_frames_) : 0;
  s.mean_level_changes = changes_ / n;
  s.mean_pixel_error = px_mean_ / n;
  s.max_pixel_error = max_pixel_error_;
  s.max_resident_bytes = max_resident_;
  s.total_holes = holes_;
  s.stream_loads = stream_loads_;
  s.stream_evictions = stream_evictions_;
  s.stream_failures = stream_failures_;
  s.mean_hlod_nodes_drawn = hlod_nodes_ / n;
  s.mean_scene_proxies = proxies_ / n;
  s.mean_proxy_objects = proxy_objects_ / n;
  s.mean_draws = draws_ / n;
  s.mean_terrain_tris = terrain_tris_ / n;
}

}  // namespace lod::cli
