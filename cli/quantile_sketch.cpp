#include "cli/quantile_sketch.h"

#include <algorithm>
#include <cmath>

namespace lod::cli {
namespace {

const double kLogRatio = std::log(QuantileSketch::kBinRatio);
const double kLogLowest = std::log(QuantileSketch::kLowest);

}  // namespace

const size_t QuantileSketch::kBins =
    2 + size_t(std::ceil(std::log(QuantileSketch::kHighest / QuantileSketch::kLowest) / std::log(QuantileSketch::kBinRatio)));

QuantileSketch::QuantileSketch(size_t exact_capacity) : exact_capacity_(exact_capacity) {
  exact_.reserve(std::min<size_t>(exact_capacity_, 1024));
}

size_t QuantileSketch::bin_of(double v) const {
  if (!(v >= kLowest)) return 0;  // zero, negative, tiny (and NaN)
  const double b = std::floor((std::log(v) - kLogLowest) / kLogRatio);
  return std::min(kBins - 1, size_t(1 + std::max(0.0, b)));
}

double QuantileSketch::value_of(size_t bin) const {
  if (bin == 0) return 0;
  // Bin b >= 1 holds [lowest * r^(b-1), lowest * r^b): its geometric middle.
  return std::exp(kLogLowest + (double(bin) - 0.5) * kLogRatio);
}

void QuantileSketch::move_to_bins() {
  binned_.assign(kBins, 0);
  for (double v : exact_) ++binned_[bin_of(v)];
  exact_.clear();
  exact_.shrink_to_fit();
}

void QuantileSketch::add(double v) {
  min_ = count_ == 0 ? v : std::min(min_, v);
  max_ = count_ == 0 ? v : std::max(max_, v);
  ++count_;
  if (binned_.empty() && exact_.size() < exact_capacity_) {
    exact_.push_back(v);
    return;
  }
  if (binned_.empty()) move_to_bins();
  ++binned_[bin_of(v)];
}

double QuantileSketch::percentile(double p) const {
  if (count_ == 0) return 0;
  p = std::clamp(p, 0.0, 1.0);
  if (binned_.empty()) {  // as over the sorted values
    std::vector<double> v = exact_;
    std::sort(v.begin(), v.end());
    const double pos = p * double(v.size() - 1);
    const size_t i = size_t(pos);
    const double t = pos - double(i);
    return i + 1 < v.size() ? v[i] * (1 - t) + v[i + 1] * t : v[i];
  }
  const uint64_t rank = uint64_t(p * double(count_ - 1));  // the value of this rank (0-based) is in bin b
  if (rank == 0) return min_;
  if (rank + 1 == count_) return max_;
  uint64_t below = 0;
  for (size_t b = 0; b < binned_.size(); ++b) {
    below += binned_[b];
    if (below > rank) return std::clamp(value_of(b), min_, max_);
  }
  return max_;
}

}  // namespace lod::cli
