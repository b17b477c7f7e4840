// The selection oracle: the DP optimum is exact (brute force on tiny problems), the greedy
// keeps its half-of-optimum guarantee, and the SLC heap never beats the optimum, on random scenes.
#include "runtime/selection_oracle.h"

#include <gtest/gtest.h>

#include <random>

#include "unit/runtime/random_knapsack.h"

namespace lod {
namespace {

using test::RandomScene;

TEST(SelectionOracle, DynamicProgrammingMatchesBruteForce) {
  for (uint32_t seed = 1; seed <= 30; ++seed) {
    RandomScene s(5, seed, 0.4);
    std::vector<uint8_t> opt(5);
    ASSERT_TRUE(optimal_choice(s.problem, 10, opt));
    uint64_t opt_cost = 0;
    const double opt_benefit = benefit_of(s.problem, opt, &opt_cost);
    EXPECT_LE(opt_cost, s.problem.capacity);
    // Every combination.
    double best = -1;
    std::vector<uint8_t> pick(5, 0);
    for (;;) {
      uint64_t cost = 0;
      const double b = benefit_of(s.problem, pick, &cost);
      if (cost <= s.problem.capacity) best = std::max(best, b);
      size_t i = 0;
      while (i < 5 && ++pick[i] == s.problem.first[i + 1] - s.problem.first[i]) pick[i++] = 0;
      if (i == 5) break;
    }
    EXPECT_NEAR(opt_benefit, best, 1e-9 * std::max(1.0, best)) << "seed " << seed;
  }
}

TEST(SelectionOracle, GreedyAndHeapAgainstTheOptimum) {
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    for (double share : {0.1, 0.3, 0.6}) {
      RandomScene s(120, seed, share);
      std::vector<uint8_t> opt(120), greedy(120);
      ASSERT_TRUE(optimal_choice(s.problem, 10, opt));
      ASSERT_TRUE(greedy_choice(s.problem, greedy));
      const std::vector<uint8_t> heap = s.heap_choice();
      uint64_t gc = 0, hc = 0;
      const double o = benefit_of(s.problem, opt), g = benefit_of(s.problem, greedy, &gc),
                   h = benefit_of(s.problem, heap, &hc);
      EXPECT_LE(gc, s.problem.capacity);
      EXPECT_LE(hc, s.problem.capacity);
      EXPECT_LE(g, o * (1 + 1e-9));
      EXPECT_LE(h, o * (1 + 1e-9));
      EXPECT_GE(g, 0.5 * o) << "Funkhouser-Sequin's guarantee, seed " << seed;
    }
  }
}

TEST(SelectionOracle, RefusesWhatItCannotSolve) {
  RandomScene s(10, 3, 0.5);
  std::vector<uint8_t> levels(10);
  EXPECT_FALSE(optimal_choice(s.problem, 7, levels)) << "costs not multiples of the unit";
  KnapsackProblem tight = s.problem;
  tight.capacity = 0;
  EXPECT_FALSE(optimal_choice(tight, 10, levels));
  EXPECT_FALSE(greedy_choice(tight, levels));
}

}  // namespace
}  // namespace lod
