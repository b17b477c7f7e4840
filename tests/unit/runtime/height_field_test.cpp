// fill_missing_heights: holes fill from their rim inwards, in one pass per ring.
#include "runtime/height_field.h"

#include <gtest/gtest.h>

namespace lod {
namespace {

HeightField flat(uint32_t w, uint32_t h, float v) {
  HeightField f;
  f.width = w, f.height = h;
  f.heights.assign(f.sample_count(), v);
  return f;
}

TEST(HeightFieldFill, AHoleTakesItsRimInRings) {
  HeightField f = flat(5, 1, 0);
  f.heights = {2, 0, 0, 0, 10};
  const std::vector<uint8_t> missing = {0, 1, 1, 1, 0};
  EXPECT_EQ(fill_missing_heights(f, missing), 3u);
  EXPECT_FLOAT_EQ(f.heights[1], 2.f);  // ring 1: its one valid neighbour
  EXPECT_FLOAT_EQ(f.heights[3], 10.f);
  EXPECT_FLOAT_EQ(f.heights[2], 6.f);  // ring 2: the mean of ring 1
}

TEST(HeightFieldFill, EverythingMissingChangesNothing) {
  HeightField f = flat(3, 3, 7);
  EXPECT_EQ(fill_missing_heights(f, std::vector<uint8_t>(9, 1)), 0u);
  for (float h : f.heights) EXPECT_EQ(h, 7.f);
}

// Fuzzer finding (a GDAL XYZ grid of 99,993 x 2 with three samples): one sweep of the whole
// grid per ring took rings x samples. Rings now visit each sample once, so a 2,000 x 1,000
// field with one valid sample (3,000 rings) fills in one pass over it.
TEST(HeightFieldFill, ASingleValidSampleFillsAHugeHole) {
  HeightField f = flat(2000, 1000, 0);
  std::vector<uint8_t> missing(f.sample_count(), 1);
  missing[0] = 0;
  f.heights[0] = 42;
  EXPECT_EQ(fill_missing_heights(f, missing), f.sample_count() - 1);
  for (float h : f.heights) ASSERT_EQ(h, 42.f);
}

}  // namespace
}  // namespace lod
