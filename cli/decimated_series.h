// DecimatedSeries: a per-frame series for a plot, in at most `buckets` buckets whatever the
// run's length. While a run has no more frames than buckets every frame is its own bucket
// and the plot is exact. Past that, neighbouring buckets merge in pairs (each then spans twice
// as many frames), and a bucket keeps its smallest and largest value and the frames they came
// from: a spike of one frame stays in the plot at its own frame, at its own height.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

namespace lod::cli {

class DecimatedSeries {
 public:
  explicit DecimatedSeries(size_t buckets = 1024);  // rounded up to an even count of at least 2

  void add(double value);  // the next frame's value (frame = how many came before)
  uint64_t count() const { return count_; }
  uint64_t frames_per_bucket() const { return width_; }
  // What to draw, in frame order: each bucket's minimum and maximum at the frames they came from
  // (one point when they are the same frame), so at most 2 x buckets points.
  void points(std::vector<double>& x, std::vector<double>& values) const;

 private:
  struct Bucket {
    double min, max;
    uint64_t min_at, max_at;
  };
  void merge_pairs();

  size_t capacity_;
  std::vector<Bucket> buckets_;
  uint64_t count_ = 0, width_ = 1;
};

}  // namespace lod::cli
