// RunPlots: the report's SVG plots of a run, kept as DecimatedSeries while it goes, so their
// memory is fixed however many frames it runs: every frame drawn up to `buckets` frames; past
// that each bucket of frames is drawn at its minimum and maximum (at the frames they came
// from), and the x axis says how many frames a bucket spans.
#pragma once
#include <array>
#include <cstddef>
#include <filesystem>

#include "cli/decimated_series.h"
#include "cli/run_report.h"

namespace lod::cli {

class RunPlots {
 public:
  explicit RunPlots(size_t buckets = 1024);

  void add(const FrameRecord& r);
  uint64_t frames_per_bucket() const { return total_ms_.frames_per_bucket(); }
  // triangles.svg (Yu, Liang and Chen's Fig. 4: in view, selected, budget; log scale), drawn.svg (drawn with
  // blends vs M, linear), levels.svg (objects per chain level), level_changes.svg,
  // pixel_error.svg (worst and mean error left) and stage_ms.svg (per-stage milliseconds).
  Status write(const std::filesystem::path& dir, const RunSummary& s) const;

 private:
  DecimatedSeries in_view_, selected_, budget_, drawn_, changes_, culled_, px_max_, px_mean_, total_ms_;
  std::array<DecimatedSeries, kMaxLevels> levels_;
  std::array<DecimatedSeries, kStageCount> stage_ms_;
  size_t levels_used_ = 1;
};

}  // namespace lod::cli
