// RunTotals: the summary of a run's frames, added up one frame at a time in memory that does
// not grow with the run: sums for the means, the largest values, counts, and a QuantileSketch
// per timing for the percentiles (exact for the first QuantileSketch exact_capacity frames,
// approximate past them: the summary then says so in percentile_relative_error).
#pragma once
#include <array>
#include <cstddef>

#include "cli/quantile_sketch.h"
#include "cli/run_report.h"

namespace lod::cli {

class RunTotals {
 public:
  explicit RunTotals(size_t exact_percentiles = 16384);

  void add(const FrameRecord& r);
  // Fills the frame counts, timings, means and maxima of `s` (the rest of it is left as it is).
  void fill(RunSummary& s) const;

 private:
  QuantileSketch total_ms_;
  std::array<QuantileSketch, kStageCount> stage_ms_;
  size_t frames_ = 0, over_budget_ = 0, binding_ = 0, drawn_over_budget_ = 0, optimum_frames_ = 0;
  double sum_ms_ = 0, vis_ = 0, in_view_ = 0, selected_ = 0, drawn_ = 0, occluded_ = 0, culled_ = 0, benefit_ = 0,
         changes_ = 0, px_mean_ = 0, hlod_nodes_ = 0, proxies_ = 0, proxy_objects_ = 0, draws_ = 0,
         terrain_tris_ = 0;
  double max_drawn_over_budget_ = 0, max_pixel_error_ = 0;
  double min_optimum_fraction_ = 0, sum_optimum_fraction_ = 0;
  uint64_t max_resident_ = 0, holes_ = 0, stream_loads_ = 0, stream_evictions_ = 0, stream_failures_ = 0;
};

}  // namespace lod::cli
