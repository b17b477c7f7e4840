#include "cli/decimated_series.h"

#include <algorithm>
#include <cmath>

namespace lod::cli {

DecimatedSeries::DecimatedSeries(size_t buckets) : capacity_(std::max<size_t>(2, buckets + (buckets & 1))) {
  buckets_.reserve(capacity_);
}

void DecimatedSeries::merge_pairs() {
  for (size_t i = 0; i < buckets_.size() / 2; ++i) {
    const Bucket &a = buckets_[2 * i], &b = buckets_[2 * i + 1];
    Bucket m = a;
    if (b.min < a.min || std::isnan(a.min)) m.min = b.min, m.min_at = b.min_at;
    if (b.max > a.max || std::isnan(a.max)) m.max = b.max, m.max_at = b.max_at;
    buckets_[i] = m;
  }
  buckets_.resize(buckets_.size() / 2);
  width_ *= 2;
}

void DecimatedSeries::add(double v) {
  const uint64_t at = count_++;
  if (at % width_ == 0) {
    // Full: the buckets so far cover capacity x width frames, an even multiple of the new width.
    if (buckets_.size() == capacity_) merge_pairs();
    buckets_.push_back({v, v, at, at});
    return;
  }
  Bucket& b = buckets_.back();
  if (v < b.min || std::isnan(b.min)) b.min = v, b.min_at = at;
  if (v > b.max || std::isnan(b.max)) b.max = v, b.max_at = at;
}

void DecimatedSeries::points(std::vector<double>& x, std::vector<double>& values) const {
  x.clear();
  values.clear();
  for (const Bucket& b : buckets_) {
    if (b.min_at == b.max_at) {
      x.push_back(double(b.min_at));
      values.push_back(b.min);
    } else if (b.min_at < b.max_at) {
      x.insert(x.end(), {double(b.min_at), double(b.max_at)});
      values.insert(values.end(), {b.min, b.max});
    } else {
      x.insert(x.end(), {double(b.max_at), double(b.min_at)});
      values.insert(values.end(), {b.max, b.min});
    }
  }
}

}  // namespace lod::cli
