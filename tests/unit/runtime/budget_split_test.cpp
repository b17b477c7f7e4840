#include <gtest/gtest.h>

#include "runtime/budget_split.h"

namespace lod {
namespace {

TEST(BudgetSplit, FittingDemandsTakeWhatTheyAskAndTheRestIsSplitByDemand) {
  EXPECT_EQ(first_share(1000, 300, 500), 1000u) << "both fit: the first pass is not capped";
  EXPECT_EQ(first_share(1000, 900, 0), 1000u) << "nothing else asks";
  EXPECT_EQ(first_share(1000, 1500, 500), 750u);
  EXPECT_EQ(first_share(1000, 0, 5000), 0u);
  EXPECT_EQ(first_share(UINT64_MAX, UINT64_MAX, UINT64_MAX), UINT64_MAX / 2) << "no overflow";
}

}  // namespace
}  // namespace lod
