// QuantileSketch: exact over its first values, within its stated error past them, in fixed memory.
#include "cli/quantile_sketch.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace {

using lod::cli::QuantileSketch;

// Spread over six decades, in an order that is not sorted (a fixed LCG).
std::vector<double> spread_values(size_t n) {
  std::vector<double> v;
  uint64_t s = 12345;
  for (size_t i = 0; i < n; ++i) {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    v.push_back(1e-3 * std::pow(10.0, 6.0 * double(s >> 11) / double(1ull << 53)));
  }
  return v;
}

double interpolated(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const double pos = p * double(v.size() - 1);
  const size_t i = size_t(pos);
  return i + 1 < v.size() ? v[i] + (v[i + 1] - v[i]) * (pos - double(i)) : v[i];
}

TEST(QuantileSketch, IsExactUpToItsCapacity) {
  QuantileSketch q(1000);
  const auto v = spread_values(1000);
  for (double x : v) q.add(x);
  ASSERT_TRUE(q.exact());
  for (double p : {0.0, 0.25, 0.5, 0.9, 0.99, 1.0}) EXPECT_DOUBLE_EQ(q.percentile(p), interpolated(v, p)) << p;
  EXPECT_EQ(q.count(), 1000u);
  EXPECT_EQ(q.min(), *std::min_element(v.begin(), v.end()));
  EXPECT_EQ(q.max(), *std::max_element(v.begin(), v.end()));
}

TEST(QuantileSketch, PastItsCapacityStaysWithinTheStatedError) {
  QuantileSketch q(256);
  auto v = spread_values(50000);
  for (double x : v) q.add(x);
  ASSERT_FALSE(q.exact());
  std::sort(v.begin(), v.end());
  for (double p : {0.01, 0.1, 0.5, 0.9, 0.99, 0.999}) {
    const double want = v[size_t(p * double(v.size() - 1))];
    EXPECT_LE(std::fabs(q.percentile(p) - want), QuantileSketch::kRelativeError * want) << p;
  }
  EXPECT_EQ(q.percentile(0), v.front()) << "clamped to the exact minimum";
  EXPECT_EQ(q.percentile(1), v.back()) << "and maximum";
  EXPECT_EQ(q.count(), 50000u);
}

TEST(QuantileSketch, CountsZeroAndTinyValuesAsZero) {
  QuantileSketch q(4);
  for (int i = 0; i < 100; ++i) q.add(i < 60 ? 0.0 : 2.0);
  ASSERT_FALSE(q.exact());
  EXPECT_EQ(q.percentile(0.5), 0.0);
  EXPECT_NEAR(q.percentile(0.9), 2.0, 2.0 * QuantileSketch::kRelativeError);
  QuantileSketch empty;
  EXPECT_EQ(empty.percentile(0.5), 0.0);
}

TEST(QuantileSketch, TheStatedErrorCoversHalfABin) {
  EXPECT_GE(QuantileSketch::kRelativeError, std::sqrt(QuantileSketch::kBinRatio) - 1);
}

}  // namespace
