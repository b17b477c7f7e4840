#include <gtest/gtest.h>

#include <queue>
#include <random>

#include "runtime/importance.h"
#include "runtime/slc_selection.h"
#include "unit/runtime/runtime_fixtures.h"

namespace lod {
namespace {

// Yu, Liang and Chen's models: cow 100/50/25/12/6 %, armadillo and buddha 25 % .. 0.18 %.
ModelTable paper_table() {
  auto chain = [](double full, std::vector<double> ratios) {
    std::vector<test::LevelSpec> levels;
    float error = 0;
    for (double r : ratios) {
      levels.push_back({static_cast<uint32_t>(full * r), error});
      error = error * 2 + 0.01f;
    }
    return levels;
  };
  const std::vector<double> big = {0.25, 0.12, 0.06, 0.03, 0.015, 0.0075, 0.0037, 0.0018};
  return test::table_of({chain(5804, {1.0, 0.5, 0.25, 0.12, 0.06}), chain(345944, big), chain(1087716, big)});
}

struct Scene {
  std::vector<uint8_t> level, visible;
  std::vector<float> weight;
  std::vector<uint32_t> model;
  std::vector<HeapEntry> heap;
};

Scene random_scene(const ModelTable& t, size_t n, std::mt19937& rng) {
  Scene s;
  s.level.resize(n);
  s.visible.resize(n);
  s.weight.resize(n);
  s.model.resize(n);
  s.heap.resize(n);
  std::uniform_real_distribution<float> w(0.001f, 1.f);
  for (size_t i = 0; i < n; ++i) {
    s.model[i] = static_cast<uint32_t>(rng() % t.model_count());
    s.visible[i] = rng() % 4 != 0;
    s.level[i] = static_cast<uint8_t>(rng() % t.level_count[s.model[i]]);
    // Few distinct weights, so equal keys and the id tie-break really occur.
    s.weight[i] = rng() % 3 == 0 ? 0.5f : w(rng);
  }
  return s;
}

uint64_t cost_of(const Scene& s, const ModelTable& t, BudgetCount unit) {
  uint64_t c = 0;
  for (size_t i = 0; i < s.level.size(); ++i) {
    if (s.visible[i]) c += level_cost(t, s.model[i], s.level[i], unit);
  }
  return c;
}

// The textbook loop with std::priority_queue (pop + push), as the oracle.
std::vector<uint8_t> reference_select(const Scene& s, const ModelTable& t, const SelectionParams& p) {
  std::vector<uint8_t> level = s.level;
  auto worse = [](const HeapEntry& a, const HeapEntry& b) {
    return a.key < b.key || (a.key == b.key && a.object > b.object);
  };
  auto key = [&](uint32_t i) {
    const uint32_t at = t.first_level[s.model[i]] + level[i];
    return s.weight[i] * static_cast<float>(span_of_level_changed(t.level_l[at], t.level_l[at + 1]));
  };
  std::priority_queue<HeapEntry, std::vector<HeapEntry>, decltype(worse)> q(worse);
  uint64_t cost = 0;
  for (uint32_t i = 0; i < level.size(); ++i) {
    if (!s.visible[i]) continue;
    cost += level_cost(t, s.model[i], level[i], p.count);
    if (level[i] + 1 < t.level_count[s.model[i]]) q.push({key(i), i});
  }
  while (cost > p.budget && !q.empty()) {
    const uint32_t i = q.top().object;
    q.pop();
    cost -= level_cost(t, s.model[i], level[i], p.count) - level_cost(t, s.model[i], level[i] + 1, p.count);
    ++level[i];
    if (level[i] + 1 < t.level_count[s.model[i]]) q.push({key(i), i});
  }
  return level;
}

TEST(Selection, MeetsBudgetWheneverCoarsestLevelsFitInBothUnits) {
  const ModelTable t = paper_table();
  std::mt19937 rng(2024);
  int binding = 0;
  for (BudgetCount unit : {BudgetCount::triangles, BudgetCount::levels}) {
    for (int trial = 0; trial < 200; ++trial) {
      Scene s = random_scene(t, 1 + rng() % 300, rng);
      const Scene initial = s;
      uint64_t coarsest = 0;
      for (size_t i = 0; i < s.level.size(); ++i) {
        if (s.visible[i]) coarsest += level_cost(t, s.model[i], t.level_count[s.model[i]] - 1, unit);
      }
      const uint64_t start = cost_of(s, t, unit);
      SelectionParams p;
      p.count = unit;
      p.budget = coarsest + (start > coarsest ? rng() % (start - coarsest + 1) : 0);
      const SelectionResult r = select_under_budget(s.level, s.visible, s.weight, s.model, t, p, s.heap);
      binding += r.lowered_steps > 0;
      EXPECT_FALSE(r.over_budget);
      EXPECT_LE(r.cost, p.budget);
      EXPECT_EQ(r.cost, cost_of(s, t, unit));
      EXPECT_EQ(r.triangles, cost_of(s, t, BudgetCount::triangles));
      EXPECT_EQ(r.level_cost, cost_of(s, t, BudgetCount::levels));
      EXPECT_EQ(r.coarsest_cost, coarsest);
      uint32_t steps = 0;
      for (size_t i = 0; i < s.level.size(); ++i) {
        if (!s.visible[i]) {
          ASSERT_EQ(s.level[i], initial.level[i]);  // invisible: untouched
        } else {
          ASSERT_GE(s.level[i], initial.level[i]);  // only ever lowered
          steps += s.level[i] - initial.level[i];
        }
      }
      EXPECT_EQ(r.lowered_steps, steps);
      EXPECT_EQ(s.level, reference_select(initial, t, p)) << "trial " << trial;
    }
  }
  EXPECT_GT(binding, 300);  // the budget really bound in most trials
}

// The two-part form (gather on chunks, then lower) gives exactly what the one-call form
// gives, whatever the chunking, in both units, binding or over budget.
TEST(Selection, GatherOnChunksThenLowerEqualsOneCall) {
  const ModelTable t = paper_table();
  const SelectionTables tables = build_selection_tables(t);
  std::mt19937 rng(77);
  int binding = 0, over = 0;
  for (BudgetCount unit : {BudgetCount::triangles, BudgetCount::levels}) {
    for (int trial = 0; trial < 150; ++trial) {
      Scene one = random_scene(t, 1 + rng() % 400, rng);
      Scene two = one;
      const Scene initial = one;
      SelectionParams p;
      p.count = unit;
      const uint64_t start = cost_of(one, t, unit);
      p.budget = trial % 10 == 0 ? 1 : 1 + rng() % (start + 1);
      const SelectionResult a = select_under_budget(one.level, one.visible, one.weight, one.model, t, p, one.heap);

      const size_t n = two.level.size();
      const size_t chunk = 1 + rng() % 64;
      std::vector<uint32_t> counts(t.triangles.size(), 0);
      for (size_t b = 0; b < n; b += chunk) {
        const size_t e = std::min(n, b + chunk);
        std::vector<uint32_t> part(t.triangles.size(), 0);
        gather_selection(std::span(two.heap).subspan(b, e - b), part, std::span(two.level).subspan(b, e - b),
                         std::span(two.visible).subspan(b, e - b), std::span(two.weight).subspan(b, e - b),
                         std::span(two.model).subspan(b, e - b), static_cast<uint32_t>(b), t, tables);
        for (size_t k = 0; k < counts.size(); ++k) counts[k] += part[k];
      }
      const SelectionResult b = lower_under_budget(two.level, two.visible, two.weight, two.model, t, p, counts, two.heap);
      ASSERT_EQ(two.level, one.level) << "trial " << trial << " chunk " << chunk;
      EXPECT_EQ(b.cost, a.cost);
      EXPECT_EQ(b.triangles, a.triangles);
      EXPECT_EQ(b.level_cost, a.level_cost);
      EXPECT_EQ(b.coarsest_cost, a.coarsest_cost);
      EXPECT_EQ(b.lowered_steps, a.lowered_steps);
      EXPECT_EQ(b.over_budget, a.over_budget);
      if (!a.over_budget) {
        EXPECT_EQ(two.level, reference_select(initial, t, p));
      }
      binding += a.lowered_steps > 0;
      over += a.over_budget;
    }
  }
  EXPECT_GT(binding, 100);
  EXPECT_GT(over, 10);
}

TEST(Selection, MatchesReferenceWithManyModelsAndTightScratch) {
  // 400 chains of 2 to 9 levels: more levels than selection's stack tables hold, so the
  // table-free path runs; and scratch with room for exactly the visible objects.
  std::mt19937 rng(5);
  std::vector<std::vector<test::LevelSpec>> chains;
  for (int m = 0; m < 400; ++m) {
    std::vector<test::LevelSpec> levels;
    uint32_t tris = 1000 + rng() % 500000;
    for (uint32_t k = 0, count = 2 + rng() % 8; k < count; ++k, tris = tris * (1 + rng() % 9) / 10 + 1)
      levels.push_back({tris, 0.01f * k});
    chains.push_back(levels);
  }
  const ModelTable many = test::table_of(chains);
  ASSERT_GT(many.triangles.size(), 2048u);
  const ModelTable few = paper_table();
  int compared = 0;
  for (const ModelTable* t : {&many, &few}) {
    for (BudgetCount unit : {BudgetCount::triangles, BudgetCount::levels}) {
      for (int trial = 0; trial < 30; ++trial) {
        Scene s = random_scene(*t, 1 + rng() % 2000, rng);
        for (size_t i = 0; i < s.level.size(); ++i) {
          // Invisible objects may carry any stale level; selection must not trip over it.
          if (!s.visible[i]) s.level[i] = static_cast<uint8_t>(rng());
        }
        const Scene initial = s;
        size_t visible = 0;
        for (uint8_t v : s.visible) visible += v;
        s.heap.assign(visible, HeapEntry{});
        SelectionParams p;
        p.count = unit;
        const uint64_t start = cost_of(s, *t, unit);
        p.budget = start / 2 + rng() % (start / 2 + 1);
        const SelectionResult r = select_under_budget(s.level, s.visible, s.weight, s.model, *t, p, s.heap);
        if (r.over_budget) continue;
        ++compared;
        EXPECT_LE(r.cost, p.budget);
        EXPECT_EQ(r.triangles, cost_of(s, *t, BudgetCount::triangles));
        EXPECT_EQ(s.level, reference_select(initial, *t, p)) << "trial " << trial;
      }
    }
  }
  EXPECT_GT(compared, 80);
}

TEST(Selection, FlagsAndUsesCoarsestWhenEvenTheyExceedBudget) {
  const ModelTable t = paper_table();
  std::mt19937 rng(99);
  for (BudgetCount unit : {BudgetCount::triangles, BudgetCount::levels}) {
    for (int trial = 0; trial < 50; ++trial) {
      Scene s = random_scene(t, 20 + rng() % 200, rng);
      const Scene initial = s;
      SelectionParams p;
      p.count = unit;
      uint64_t coarsest = 0;
      for (size_t i = 0; i < s.level.size(); ++i) {
        if (s.visible[i]) coarsest += level_cost(t, s.model[i], t.level_count[s.model[i]] - 1, unit);
      }
      if (coarsest == 0) continue;  // nothing visible: nothing can exceed
      p.budget = coarsest - 1 - rng() % coarsest;
      const SelectionResult r = select_under_budget(s.level, s.visible, s.weight, s.model, t, p, s.heap);
      EXPECT_TRUE(r.over_budget);
      EXPECT_EQ(r.cost, coarsest);
      EXPECT_EQ(r.coarsest_cost, coarsest);
      EXPECT_EQ(r.cost, cost_of(s, t, unit));
      for (size_t i = 0; i < s.level.size(); ++i) {
        EXPECT_EQ(s.level[i], s.visible[i] ? t.level_count[s.model[i]] - 1 : initial.level[i]);
      }
    }
  }
}

TEST(Selection, LeavesLevelsAloneWhenBudgetAlreadyHolds) {
  const ModelTable t = paper_table();
  Scene s;
  s.level = {0, 1, 1};
  s.visible = {1, 1, 0};
  s.weight = {1, 1, 1};
  s.model = {0, 1, 2};
  SelectionParams p;
  p.budget = 5804 + 41513;  // cow full + armadillo at 12 %; the invisible buddha is free
  const SelectionResult r = select_under_budget(s.level, s.visible, s.weight, s.model, t, p, s.heap);
  EXPECT_EQ(s.level, (std::vector<uint8_t>{0, 1, 1}));
  EXPECT_EQ(r.lowered_steps, 0u);
  EXPECT_EQ(r.cost, p.budget);
  EXPECT_FALSE(r.over_budget);
  const SelectionResult none = select_under_budget({}, {}, {}, {}, t, p, {});
  EXPECT_EQ(none.cost, 0u);
  EXPECT_FALSE(none.over_budget);
}

TEST(Selection, LowersTheHighestImportanceObjectFirst) {
  // Three equal cows; one step of any of them fits the budget.
  const ModelTable t = test::table_of({{{4096, 0}, {2048, 1}, {1024, 2}}});
  Scene s;
  s.level = {0, 0, 0};
  s.visible = {1, 1, 1};
  s.weight = {0.2f, 0.9f, 0.5f};
  s.model = {0, 0, 0};
  s.heap.resize(3);
  SelectionParams p;
  p.budget = 3 * 4096 - 1;
  SelectionResult r = select_under_budget(s.level, s.visible, s.weight, s.model, t, p, s.heap);
  EXPECT_EQ(s.level, (std::vector<uint8_t>{0, 1, 0}));
  EXPECT_EQ(r.lowered_steps, 1u);
  // Lowering object 1 again is worth 0.9 * SLC(11 -> 10) = 9.9, still above 0.5 * 12 = 6.
  s.level = {0, 0, 0};
  p.budget = 3 * 4096 - 2048 - 1;
  r = select_under_budget(s.level, s.visible, s.weight, s.model, t, p, s.heap);
  EXPECT_EQ(s.level, (std::vector<uint8_t>{0, 2, 0}));
  EXPECT_EQ(r.lowered_steps, 2u);
}

TEST(Selection, BreaksTiesByLowerObjectId) {
  const ModelTable t = test::table_of({{{4096, 0}, {2048, 1}}});
  Scene s;
  s.level = {0, 0, 0, 0};
  s.visible = {1, 0, 1, 1};
  s.weight = {0.5f, 0.5f, 0.5f, 0.5f};
  s.model = {0, 0, 0, 0};
  s.heap.resize(4);
  SelectionParams p;
  p.budget = 3 * 4096 - 2 * 2048;  // two steps
  select_under_budget(s.level, s.visible, s.weight, s.model, t, p, s.heap);
  EXPECT_EQ(s.level, (std::vector<uint8_t>{1, 0, 1, 0}));
}

TEST(Selection, LowersFarSmallObjectsBeforeNearLargeOnes) {
  // Importance end to end: near/large objects keep detail, far/small ones give it up.
  const ModelTable t = paper_table();
  ObjectSet o;
  o.resize(6);
  o.cz = {-20, -40, -300, -600, -900, -1200};
  o.radius = {4, 3, 1, 1, 0.5f, 0.5f};
  const std::vector<uint8_t> visible(6, 1);
  std::vector<float> distance(6), area(6), weight(6);
  const ViewMinima mins = measure_objects(distance, area, visible, o.cx, o.cy, o.cz, o.radius, {0, 0, 0}, 1000.f);
  importance_weights(weight, visible, distance, area, mins);
  for (size_t i = 1; i < 6; ++i) EXPECT_GT(weight[i], weight[i - 1]);

  std::vector<uint8_t> level(6, 0);
  const std::vector<uint32_t> model(6, 2);  // all buddhas, levels 18 .. 11
  std::vector<HeapEntry> heap(6);
  SelectionParams p;
  p.count = BudgetCount::levels;
  p.budget = 6 * (uint64_t{1} << 18) - 3 * ((uint64_t{1} << 18) - (uint64_t{1} << 17));  // three steps
  const SelectionResult r = select_under_budget(level, visible, weight, model, t, p, heap);
  EXPECT_LE(r.cost, p.budget);
  EXPECT_EQ(level[0], 0);  // the nearest, largest object keeps full detail
  EXPECT_GE(level[5], level[3]);
  EXPECT_GE(level[5] + level[4] + level[3], 3);
}

}  // namespace
}  // namespace lod

namespace lod {
namespace {

// Every selector on the smallest inputs: no objects, none visible, one, at budgets 0, 1 and
// unbounded, the gathered (chunked) path against the one-call path.
TEST(Selection, EverySelectorIsTotalOnEmptyAndSingleInputs) {
  const ModelTable t = paper_table();
  const SelectionTables tables = build_selection_tables(t);
  std::mt19937 rng(5);
  for (Selector selector : {Selector::greedy, Selector::greedy_multi, Selector::benefit_cost})
    for (BudgetCount unit : {BudgetCount::triangles, BudgetCount::levels})
      for (size_t n : {size_t(0), size_t(1), size_t(3)})
        for (int visibility = 0; visibility < 2; ++visibility)
          for (uint64_t budget : {uint64_t(0), uint64_t(1), UINT64_MAX}) {
            SCOPED_TRACE("selector " + std::to_string(int(selector)) + " n " + std::to_string(n) + " visible " +
                         std::to_string(visibility) + " budget " + std::to_string(budget));
            Scene one = random_scene(t, n, rng);
            for (uint8_t& v : one.visible) v = uint8_t(visibility);
            Scene two = one;
            SelectionParams p;
            p.selector = selector;
            p.count = unit;
            p.budget = budget;
            const std::vector<float> benefit(n, 1.0f);
            const SelectionResult a =
                select_under_budget(one.level, one.visible, one.weight, one.model, t, p, one.heap, benefit);
            std::vector<uint32_t> counts(t.triangles.size(), 0);
            gather_selection(two.heap, counts, two.level, two.visible, two.weight, two.model, 0, t, tables);
            const SelectionResult b =
                lower_under_budget(two.level, two.visible, two.weight, two.model, t, p, counts, two.heap, benefit);
            EXPECT_EQ(a.cost, b.cost);
            EXPECT_EQ(a.over_budget, b.over_budget);
            EXPECT_EQ(one.level, two.level);
            EXPECT_EQ(a.over_budget, a.coarsest_cost > budget);
            if (!a.over_budget) {
              EXPECT_LE(a.cost, budget);
            }
            if (n == 0 || visibility == 0) {
              EXPECT_EQ(a.cost, 0u);
              EXPECT_FALSE(a.over_budget);
            }
          }
}

}  // namespace
}  // namespace lod
