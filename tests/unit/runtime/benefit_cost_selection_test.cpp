// Selector::benefit_cost (Funkhouser-Sequin with the best-single-object check): >= 1/2 of the
// exact optimum on random and adversarial problems, the single object winning where the ratio
// greedy alone fails, the budget held, never finer than the initial levels, and the frame
// oracle (selection_optimum) agreeing with the DP.
#include "runtime/benefit_cost_selection.h"

#include <gtest/gtest.h>

#include <random>

#include "runtime/selection_oracle.h"
#include "unit/runtime/random_knapsack.h"
#include "unit/runtime/runtime_fixtures.h"

namespace lod {
namespace {

struct Problem {
  ModelTable models;
  std::vector<uint32_t> model;
  std::vector<float> w;  // benefit weights
  uint64_t budget = 0;

  // benefit_cost from `initial` levels (default: all finest); its result and levels.
  SelectionResult select(std::vector<uint8_t>& levels, BudgetCount count = BudgetCount::triangles) const {
    std::vector<uint8_t> visible(model.size(), 1);
    std::vector<float> importance(model.size(), 1.f);
    std::vector<HeapEntry> heap(model.size());
    SelectionParams p;
    p.budget = budget;
    p.count = count;
    p.selector = Selector::benefit_cost;
    return select_under_budget(levels, visible, importance, model, models, p, heap, w);
  }
  KnapsackProblem knapsack() const {
    KnapsackProblem k;
    k.capacity = budget;
    k.first.push_back(0);
    for (size_t i = 0; i < model.size(); ++i) {
      const uint32_t base = models.first_level[model[i]], n = models.level_count[model[i]];
      for (uint32_t l = 0; l < n; ++l) {
        k.cost.push_back(models.triangles[base + l]);
        k.benefit.push_back(double(w[i]) *
                            std::max(0.0, double(models.error[base + n - 1]) - models.error[base + l]));
      }
      k.first.push_back(static_cast<uint32_t>(k.cost.size()));
    }
    return k;
  }
};

// One object per chain, weight 1.
Problem one_object_each(const std::vector<std::vector<test::LevelSpec>>& chains, uint64_t budget) {
  Problem p;
  p.models = test::table_of(chains);
  for (uint32_t m = 0; m < chains.size(); ++m) p.model.push_back(m), p.w.push_back(1.f);
  p.budget = budget;
  return p;
}

TEST(BenefitCostSelector, BestSingleObjectBeatsTheRatioGreedy) {
  // Room 100 above the coarsest (1 + 1): A gains 2 for 1 triangle (ratio 2), B gains 100 for 100
  // (ratio 1). The ratio greedy takes A and then B no longer fits: 2 of 100. B alone: 100.
  const Problem p = one_object_each({{{2, 0.f}, {1, 2.f}}, {{101, 0.f}, {1, 100.f}}}, 102);
  std::vector<uint8_t> levels(2, 0);
  const SelectionResult r = p.select(levels);
  EXPECT_EQ(levels, (std::vector<uint8_t>{1, 0})) << "B alone";
  EXPECT_EQ(r.triangles, 102u);
}

TEST(BenefitCostSelector, AtLeastHalfTheOptimumOnAdversarialProblems) {
  // Chains with costs and errors out of proportion, weights over four orders of magnitude and
  // budgets from just above the coarsest levels: where ratio-greedy choices go wrong.
  std::mt19937 rng(5);
  double worst = 1;
  for (int trial = 0; trial < 400; ++trial) {
    std::vector<std::vector<test::LevelSpec>> chains;
    for (int m = 0; m < 4; ++m) {
      std::vector<test::LevelSpec> levels;
      uint32_t tris = 1 + rng() % 200;
      float error = 0;
      for (int k = 0; k < 1 + int(rng() % 4); ++k) {
        levels.push_back({tris, error});
        tris = std::max<uint32_t>(1, tris - 1 - rng() % std::max<uint32_t>(1, tris));
        error += float(rng() % 1000) / 10.f;
      }
      chains.push_back(levels);
    }
    Problem p;
    p.models = test::table_of(chains);
    const size_t n = 2 + rng() % 7;
    uint64_t coarsest = 0, finest = 0;
    for (size_t i = 0; i < n; ++i) {
      const uint32_t m = rng() % 4;
      p.model.push_back(m);
      p.w.push_back(std::pow(10.f, float(rng() % 4000) / 1000.f));
      coarsest += p.models.triangles[p.models.first_level[m] + p.models.level_count[m] - 1];
      finest += p.models.triangles[p.models.first_level[m]];
    }
    p.budget = coarsest + (finest - coarsest) * (rng() % 100) / 100;
    std::vector<uint8_t> levels(n, 0), opt(n);
    const SelectionResult r = p.select(levels);
    const KnapsackProblem k = p.knapsack();
    ASSERT_TRUE(optimal_choice(k, 1, opt));
    uint64_t cost = 0;
    const double b = benefit_of(k, levels, &cost), o = benefit_of(k, opt);
    EXPECT_LE(cost, p.budget) << "trial " << trial;
    EXPECT_EQ(r.triangles, cost);
    EXPECT_LE(b, o * (1 + 1e-9));
    EXPECT_GE(b, 0.5 * o * (1 - 1e-9)) << "trial " << trial;
    if (o > 0) worst = std::min(worst, b / o);
  }
  std::printf("benefit_cost: worst fraction of the optimum on adversarial problems %.4f\n", worst);
}

TEST(BenefitCostSelector, RandomScenesAgainstTheOptimum) {
  double worst = 1;
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    for (double share : {0.1, 0.3, 0.6}) {
      test::RandomScene s(120, seed, share);
      Problem p{s.models, s.model, {}, s.problem.capacity};
      for (size_t i = 0; i < s.model.size(); ++i)
        p.w.push_back(benefit_weight(s.area[i], s.distance[i], s.scale[i], 1000.f));
      std::vector<uint8_t> levels(120, 0), opt(120);
      const SelectionResult r = p.select(levels);
      ASSERT_TRUE(optimal_choice(s.problem, 10, opt));
      uint64_t cost = 0;
      const double b = benefit_of(s.problem, levels, &cost), o = benefit_of(s.problem, opt);
      EXPECT_LE(cost, s.problem.capacity);
      EXPECT_EQ(r.cost, cost);
      EXPECT_FALSE(r.over_budget);
      EXPECT_LE(b, o * (1 + 1e-6));
      EXPECT_GE(b, 0.5 * o);
      worst = std::min(worst, b / o);
    }
  }
  EXPECT_GE(worst, 0.95) << "on smooth chains the hull greedy is near the optimum";
  std::printf("benefit_cost: worst fraction of the optimum on random scenes %.4f\n", worst);
}

TEST(BenefitCostSelector, NeverFinerThanTheInitialLevelsAndKeepsThemWhenTheyFit) {
  test::RandomScene s(60, 9, 0.3);
  Problem p{s.models, s.model, {}, s.problem.capacity};
  for (size_t i = 0; i < s.model.size(); ++i)
    p.w.push_back(benefit_weight(s.area[i], s.distance[i], 1.f, 1000.f));
  std::vector<uint8_t> initial(60);
  for (size_t i = 0; i < 60; ++i) initial[i] = static_cast<uint8_t>(i % s.models.level_count[s.model[i]]);
  std::vector<uint8_t> levels = initial;
  const SelectionResult r = p.select(levels);
  EXPECT_LE(r.cost, p.budget);
  for (size_t i = 0; i < 60; ++i) EXPECT_GE(levels[i], initial[i]) << "object " << i;
  EXPECT_EQ(r.levels_lowered, [&] {
    uint32_t below = 0;
    for (size_t i = 0; i < 60; ++i) below += levels[i] - initial[i];
    return below;
  }());
  // A budget the initial levels fit: they are kept, nothing popped.
  p.budget = 1u << 30;
  levels = initial;
  const SelectionResult loose = p.select(levels);
  EXPECT_EQ(levels, initial);
  EXPECT_EQ(loose.lowered_steps, 0u);
}

TEST(BenefitCostSelector, LevelBudgetsAndTheOverBudgetCase) {
  test::RandomScene s(80, 4, 0.3);
  Problem p{s.models, s.model, {}, 0};
  for (size_t i = 0; i < s.model.size(); ++i)
    p.w.push_back(benefit_weight(s.area[i], s.distance[i], 1.f, 1000.f));
  uint64_t coarsest = 0, finest = 0;
  for (uint32_t m : s.model) {
    coarsest += uint64_t{1} << s.models.level_l[s.models.first_level[m] + s.models.level_count[m] - 1];
    finest += uint64_t{1} << s.models.level_l[s.models.first_level[m]];
  }
  p.budget = (coarsest + finest) / 2;
  std::vector<uint8_t> levels(80, 0);
  const SelectionResult r = p.select(levels, BudgetCount::levels);
  EXPECT_LE(r.level_cost, p.budget);
  EXPECT_EQ(r.cost, r.level_cost);
  EXPECT_GT(r.level_cost, coarsest) << "it raises some objects";
  p.budget = coarsest - 1;
  std::fill(levels.begin(), levels.end(), 0);
  EXPECT_TRUE(p.select(levels, BudgetCount::levels).over_budget);
}

TEST(SelectionOptimum, MatchesTheDynamicProgrammeAndBoundsItWhenRounded) {
  for (uint32_t seed = 1; seed <= 10; ++seed) {
    test::RandomScene s(60, seed, 0.3);
    std::vector<float> w;
    for (size_t i = 0; i < 60; ++i) w.push_back(benefit_weight(s.area[i], s.distance[i], 1.f, 1000.f));
    std::vector<uint8_t> initial(60, 0), opt(60);
    ASSERT_TRUE(optimal_choice(s.problem, 10, opt));
    const double o = benefit_of(s.problem, opt);
    SelectionOptimum exact, rounded;
    ASSERT_TRUE(selection_optimum(initial, w, s.model, s.models, true, s.problem.capacity, 1u << 20, exact));
    EXPECT_TRUE(exact.exact);
    EXPECT_NEAR(exact.benefit, o, 1e-4 * o) << "seed " << seed;
    ASSERT_TRUE(selection_optimum(initial, w, s.model, s.models, true, s.problem.capacity, 256, rounded));
    EXPECT_FALSE(rounded.exact);
    EXPECT_GE(rounded.benefit, o * (1 - 1e-6)) << "an upper bound";
    EXPECT_NEAR(selection_benefit(opt, w, s.model, s.models), o, 1e-4 * o);
  }
}

}  // namespace
}  // namespace lod
