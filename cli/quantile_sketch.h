// QuantileSketch: percentiles of a stream of values in bounded memory, for `lod run`'s
// frame times over runs of any length.
//
// The first `exact_capacity` values are kept as they are, and a percentile over them is exact:
// linear interpolation between neighbouring order statistics, as over the sorted values. Past
// that the sketch forgets the values and counts them in a fixed histogram of geometric bins,
// each 1 % wider than the last, from 1e-6 to 1e6 (values below 1e-6, zero and negative ones
// included, share a bin reported as 0; values above 1e6 share the last bin). A percentile p
// is then the geometric middle of the bin holding the value of rank floor(p (n - 1)), clamped
// to the exact minimum and maximum: within kRelativeError (0.5 %) of that value, or within
// 1e-6 of it below 1e-6. The exact figure lies between that value and the next one, so over
// the many values a sketch holds by then the two differ by little more than the bin width.
// Memory: exact_capacity doubles plus kBins counters, whatever the count.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

namespace lod::cli {

class QuantileSketch {
 public:
  static constexpr double kLowest = 1e-6, kHighest = 1e6, kBinRatio = 1.01;
  static constexpr double kRelativeError = 0.005;  // >= sqrt(kBinRatio) - 1
  static const size_t kBins;                       // the zero bin, then the geometric bins

  explicit QuantileSketch(size_t exact_capacity = 16384);

  void add(double value);
  uint64_t count() const { return count_; }
  // Every percentile so far is exact (no more values than exact_capacity).
  bool exact() const { return binned_.empty(); }
  // p in [0, 1]; 0 for an empty sketch.
  double percentile(double p) const;
  double min() const { return min_; }
  double max() const { return max_; }

 private:
  size_t bin_of(double value) const;
  double value_of(size_t bin) const;
  void move_to_bins();

  size_t exact_capacity_;
  std::vector<double> exact_;
  std::vector<uint64_t> binned_;  // empty until the exact values overflow
  uint64_t count_ = 0;
  double min_ = 0, max_ = 0;
};

}  // namespace lod::cli
