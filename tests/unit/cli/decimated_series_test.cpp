// DecimatedSeries: every frame while they fit, then a fixed number of buckets that keep spikes.
#include "cli/decimated_series.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace {

using lod::cli::DecimatedSeries;

TEST(DecimatedSeries, KeepsEveryFrameWhileTheyFit) {
  DecimatedSeries d(64);
  for (int i = 0; i < 64; ++i) d.add(std::sin(i * 0.3));
  std::vector<double> x, v;
  d.points(x, v);
  ASSERT_EQ(x.size(), 64u);
  EXPECT_EQ(d.frames_per_bucket(), 1u);
  for (int i = 0; i < 64; ++i) {
    EXPECT_EQ(x[i], i);
    EXPECT_EQ(v[i], std::sin(i * 0.3));
  }
}

TEST(DecimatedSeries, KeepsAFixedNumberOfPointsAndTheSpikes) {
  DecimatedSeries d(64);
  const uint64_t n = 1000003, spike = 777777, dip = 123457;
  for (uint64_t i = 0; i < n; ++i) d.add(i == spike ? 1000.0 : i == dip ? -5.0 : double(i % 7));
  std::vector<double> x, v;
  d.points(x, v);
  EXPECT_EQ(d.count(), n);
  EXPECT_LE(x.size(), 128u);
  EXPECT_GE(d.frames_per_bucket() * 64, n) << "the buckets cover every frame";
  EXPECT_EQ(d.frames_per_bucket() & (d.frames_per_bucket() - 1), 0u) << "a power of two";
  bool saw_spike = false, saw_dip = false;
  for (size_t i = 0; i < x.size(); ++i) {
    if (i > 0) {
      EXPECT_LT(x[i - 1], x[i]) << "in frame order";
    }
    saw_spike = saw_spike || (x[i] == double(spike) && v[i] == 1000.0);
    saw_dip = saw_dip || (x[i] == double(dip) && v[i] == -5.0);
    EXPECT_TRUE(v[i] == 1000.0 || v[i] == -5.0 || v[i] == 0.0 || v[i] == 6.0) << "each bucket's min or max";
  }
  EXPECT_TRUE(saw_spike) << "a one-frame spike stays at its frame";
  EXPECT_TRUE(saw_dip);
}

TEST(DecimatedSeries, AConstantSeriesIsOnePointPerBucket) {
  DecimatedSeries d(8);
  for (int i = 0; i < 100; ++i) d.add(3.0);
  std::vector<double> x, v;
  d.points(x, v);
  EXPECT_LE(x.size(), 8u);
  for (double y : v) EXPECT_EQ(y, 3.0);
}

}  // namespace
