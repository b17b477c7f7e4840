// Budget modes in the runtime: the culled level (a last ratio of 0) through chain checks, the
// asset, blends, initial levels and selection; lod.max_distance; the multi-level-per-pop
// selector against the span-of-level-changed heap and the optimum; the per-frame benefit and pixel error.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "runtime/initial_levels.h"
#include "runtime/level_blend.h"
#include "runtime/lod_asset.h"
#include "runtime/selection_oracle.h"
#include "runtime/selection_quality.h"
#include "runtime/slc_selection.h"
#include "runtime/visibility.h"
#include "unit/runtime/random_knapsack.h"
#include "unit/runtime/runtime_fixtures.h"

namespace lod {
namespace {

// fan_chain's levels plus an empty last level, as the bake makes it.
LodChain with_culled_level(LodChain c) {
  LodLevel l;
  l.first_index = static_cast<uint32_t>(c.indices.size());
  l.first_vertex = static_cast<uint32_t>(c.positions.size() / 3);
  l.error = c.levels.back().error + 1;
  l.error_rms = c.levels.back().error_rms + 1;
  l.bounds = c.levels.front().bounds;
  c.levels.push_back(l);
  return c;
}

// Morph targets for every drawn level but the last: vertex v goes to vertex 0 of the next.
void add_morph_targets(LodChain& c) { c.morph_targets.assign(morph_target_count(c), 0u); }

TEST(CulledLevel, ChainAcceptsExactlyATrailingEmptyLevel) {
  std::string why;
  LodChain c = with_culled_level(test::fan_chain("fan", {40, 20, 10}));
  EXPECT_TRUE(validate_chain(c, &why)) << why;
  EXPECT_TRUE(has_culled_level(c));
  EXPECT_EQ(drawn_levels(c), 3u);

  LodChain twice = with_culled_level(c);
  EXPECT_FALSE(validate_chain(twice, &why)) << "two empty levels";
  LodChain middle = test::fan_chain("fan", {40, 20, 10});
  middle.levels[1].index_count = 0;
  middle.levels[1].vertex_count = 0;
  middle.levels[1].level = 0;
  EXPECT_FALSE(validate_chain(middle, &why));
  EXPECT_NE(why.find("level 1 has no triangles"), std::string::npos) << why;
  LodChain only;
  only.levels.emplace_back();  // just an empty level 0
  EXPECT_FALSE(validate_chain(only, &why)) << "an empty level 0 is no model";
  LodChain with_vertices = c;
  with_vertices.levels.back().vertex_count = 1;
  EXPECT_FALSE(validate_chain(with_vertices, &why));
}

TEST(CulledLevel, MorphTargetsStopBeforeTheCulledLevel) {
  LodChain plain = test::fan_chain("fan", {40, 20, 10});
  LodChain c = with_culled_level(plain);
  EXPECT_EQ(morph_target_count(c), morph_target_count(plain)) << "no targets into a level without vertices";
  add_morph_targets(c);
  std::string why;
  EXPECT_TRUE(validate_chain(c, &why)) << why;
  EXPECT_TRUE(can_morph_levels(c));
  EXPECT_FALSE(can_morph_levels(with_culled_level(test::fan_chain("one", {4}))))
      << "one drawn level: nothing to blend";
}

TEST(CulledLevel, AssetRoundTripsAndRefusesAnEmptyMiddleLevel) {
  LodChain c = with_culled_level(test::fan_chain("fan", {40, 20, 10}));
  add_morph_targets(c);
  const std::vector<uint8_t> bytes = encode_lod_asset(c);
  LodChain back;
  const Status st = decode_lod_asset(bytes, "fan.lod", back);
  ASSERT_TRUE(st) << st.message;
  ASSERT_EQ(back.levels.size(), 4u);
  EXPECT_EQ(back.levels.back().triangles(), 0u);
  EXPECT_EQ(encode_lod_asset(back), bytes);

  LodChain bad = test::fan_chain("fan", {40, 20, 10});
  bad.levels[1].index_count = 0;
  bad.levels[1].vertex_count = 0;
  bad.levels[1].level = 0;
  LodChain out;
  EXPECT_FALSE(decode_lod_asset(encode_lod_asset(bad), "bad.lod", out));
}

struct OneObjectBlend {
  // Levels 0..2 drawn, level 3 culled.
  ModelTable models = test::table_of({{{1000, 0}, {500, 1}, {250, 2}, {0, 10}}});
  std::vector<uint8_t> blends = {1};
  std::vector<double> start = {-1e300};
  std::vector<uint8_t> from = {0}, prev = {0}, was = {0};
  std::vector<uint32_t> ids = {0}, model = {0};
  std::vector<uint8_t> level = {0}, from_level = {0};
  std::vector<float> morph = {0};

  BlendTotals run(uint8_t new_level, double now) {
    level[0] = new_level;
    const BlendTotals t = advance_level_blends(morph, from_level, ids, level, model, {start, from, prev, was},
                                               blends, models, now, 1.0f);
    prev[0] = new_level;
    was[0] = 1;
    return t;
  }
};

TEST(CulledLevel, NoBlendIntoOrOutOfTheCulledLevel) {
  OneObjectBlend b;
  b.run(2, 0.0);
  BlendTotals t = b.run(3, 10.0);  // into the culled level
  EXPECT_EQ(t.morphing, 0u);
  EXPECT_EQ(t.extra_tris, 0u);
  EXPECT_EQ(b.from_level[0], 3) << "disappears at once";
  t = b.run(2, 20.0);  // and back
  EXPECT_EQ(t.morphing, 0u);
  EXPECT_EQ(b.from_level[0], 2) << "appears at once";
  t = b.run(1, 30.0);  // drawn levels still blend
  EXPECT_EQ(t.morphing, 1u);
  EXPECT_EQ(b.from_level[0], 2);
}

TEST(CulledLevel, InitialLevelsCullWhatLooksSmallerThanThePixelError) {
  const ModelTable t = test::table_of({{{1000, 0}, {500, 0.01f}, {0, 2.0f}}});  // culled error: the diameter
  std::vector<uint8_t> level(2, 0), visible = {1, 1}, prev(2, 0), was(2, 0);
  std::vector<float> distance = {10.f, 5000.f}, scale = {1.f, 1.f};
  std::vector<uint32_t> model = {0, 0};
  choose_initial_levels(level, visible, prev, was, distance, scale, model, t, {1000.f, 1.0f, 0.f});
  EXPECT_EQ(level[0], 1) << "2 m at 10 m is 200 px: drawn";
  EXPECT_EQ(level[1], 2) << "2 m at 5 km is 0.4 px: culled";
}

TEST(CulledLevel, SelectionLowersIntoTheCulledLevelLikeAnyOther) {
  const ModelTable t = test::table_of({{{1000, 0}, {100, 1}, {0, 2}}});
  std::vector<uint8_t> level(10, 0), visible(10, 1);
  std::vector<float> weight(10);
  for (size_t i = 0; i < 10; ++i) weight[i] = 1.0f / float(i + 1);  // object 0 matters most to lower
  std::vector<uint32_t> model(10, 0);
  std::vector<HeapEntry> heap(10);
  SelectionParams p;
  p.budget = 500;  // the coarsest drawn levels (1,000) do not fit: some objects must be culled
  const SelectionResult r = select_under_budget(level, visible, weight, model, t, p, heap);
  EXPECT_FALSE(r.over_budget) << "culling makes any budget reachable";
  EXPECT_LE(r.triangles, 500u);
  uint32_t culled = 0;
  for (uint8_t l : level) culled += l == 2;
  EXPECT_GE(culled, 5u);
  EXPECT_EQ(r.coarsest_cost, 0u);
}

// The paper's span from l = 11 to the culled level's l = 0 would be 121, so the heap would cull small
// objects before it lowers a 65k-triangle one; culling counts as one more level instead.
TEST(CulledLevel, CullingWeighsLikeOneMoreLevel) {
  const ModelTable t = test::table_of({{{65536, 0}, {32768, 1}}, {{2048, 0}, {0, 5}}});
  std::vector<uint8_t> level(11, 0), visible(11, 1);
  std::vector<float> weight(11, 1.f);
  std::vector<uint32_t> model(11, 1);
  model[0] = 0;
  std::vector<HeapEntry> heap(11);
  SelectionParams p;
  p.budget = 65536 - 32768 + 10 * 2048;  // one step of object 0 is enough
  for (Selector s : {Selector::greedy, Selector::greedy_multi}) {
    p.selector = s;
    std::vector<uint8_t> l = level;
    const SelectionResult r = select_under_budget(l, visible, weight, model, t, p, heap);
    EXPECT_EQ(r.triangles, p.budget);
    EXPECT_EQ(l[0], 1) << "SLC 16 (l 16 -> 15) beats SLC 11 (l 11 -> culled)";
    EXPECT_EQ(std::count(l.begin() + 1, l.end(), uint8_t{1}), 0) << "nothing culled";
  }
}

TEST(MaxDistance, CullsSpheresWhoseNearestPointIsFarther) {
  // Along x from the eye at the origin: nearest points at 90, 99, 101 and 150.
  std::vector<float> cx = {100, 100, 102, 200}, cy(4, 0), cz(4, 0), r = {10, 1, 1, 50};
  std::vector<uint8_t> visible = {1, 1, 1, 0};
  const size_t cleared = cull_beyond_distance(visible, cx, cy, cz, r, glm::vec3(0), 100.f);
  EXPECT_EQ(visible, (std::vector<uint8_t>{1, 1, 0, 0}));
  EXPECT_EQ(cleared, 1u) << "only visible ones count";
  // Sub-ranges give the same result.
  std::vector<uint8_t> a = {1, 1, 1, 0};
  cull_beyond_distance(std::span(a).first(2), std::span(cx).first(2), std::span(cy).first(2),
                       std::span(cz).first(2), std::span(r).first(2), glm::vec3(0), 100.f);
  cull_beyond_distance(std::span(a).subspan(2), std::span(cx).subspan(2), std::span(cy).subspan(2),
                       std::span(cz).subspan(2), std::span(r).subspan(2), glm::vec3(0), 100.f);
  EXPECT_EQ(a, visible);
}

// Bunny-like chains (Yu, Liang and Chen's 100/50/25/12/6/3 %) for the selector comparisons.
ModelTable bunny_like_table() {
  std::vector<std::vector<test::LevelSpec>> chains;
  for (uint32_t full : {69451u, 5804u, 20000u}) {
    std::vector<test::LevelSpec> levels;
    float error = 0;
    for (double r : {1.0, 0.5, 0.25, 0.12, 0.06, 0.03}) {
      levels.push_back({static_cast<uint32_t>(full * r), error});
      error = error * 2 + 0.01f;
    }
    chains.push_back(levels);
  }
  return test::table_of(chains);
}

struct ColdStart {
  std::vector<uint8_t> level, visible;
  std::vector<float> weight;
  std::vector<uint32_t> model;
  std::vector<HeapEntry> heap;
  uint64_t coarsest = 0;
  ColdStart(const ModelTable& t, size_t n, uint32_t seed)
      : level(n, 0), visible(n, 1), weight(n), model(n), heap(n) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> w(0.001f, 1.f);
    for (size_t i = 0; i < n; ++i) {
      model[i] = static_cast<uint32_t>(rng() % t.model_count());
      weight[i] = w(rng);
      coarsest += t.triangles[t.first_level[model[i]] + t.level_count[model[i]] - 1];
    }
  }
};

TEST(MultiLevelSelector, SlackOneGivesGreedysLevelsWithFewerPops) {
  const ModelTable t = bunny_like_table();
  for (uint32_t seed = 1; seed <= 5; ++seed) {
    for (double share : {0.05, 0.3, 0.7}) {
      ColdStart a(t, 3000, seed), b(t, 3000, seed);
      SelectionParams p;
      uint64_t finest = 0;
      for (uint32_t m : a.model) finest += t.triangles[t.first_level[m]];
      p.budget = a.coarsest + uint64_t(double(finest - a.coarsest) * share);
      const SelectionResult g = select_under_budget(a.level, a.visible, a.weight, a.model, t, p, a.heap);
      p.selector = Selector::greedy_multi;
      p.multi_level_slack = 1.0f;
      const SelectionResult m = select_under_budget(b.level, b.visible, b.weight, b.model, t, p, b.heap);
      EXPECT_EQ(a.level, b.level) << "seed " << seed << " share " << share;
      EXPECT_EQ(m.triangles, g.triangles);
      EXPECT_EQ(m.levels_lowered, g.levels_lowered);
      EXPECT_EQ(g.levels_lowered, g.lowered_steps) << "greedy: one level per pop";
      EXPECT_LE(m.lowered_steps, g.lowered_steps);
    }
  }
}

TEST(MultiLevelSelector, ColdStartOf100kObjectsTakesAQuarterOfTheHeapPops) {
  const ModelTable t = bunny_like_table();
  ColdStart a(t, 100000, 7), b(t, 100000, 7);
  SelectionParams p;
  p.budget = a.coarsest + a.coarsest / 20;  // nearly everything goes to its coarsest level
  const SelectionResult g = select_under_budget(a.level, a.visible, a.weight, a.model, t, p, a.heap);
  p.selector = Selector::greedy_multi;
  const SelectionResult m = select_under_budget(b.level, b.visible, b.weight, b.model, t, p, b.heap);
  ASSERT_FALSE(g.over_budget);
  EXPECT_LE(g.cost, p.budget);
  EXPECT_LE(m.cost, p.budget) << "the same budget guarantee";
  EXPECT_GT(g.lowered_steps, 100000u);
  EXPECT_LE(4 * uint64_t{m.lowered_steps}, g.lowered_steps)
      << "greedy " << g.lowered_steps << " pops, greedy_multi " << m.lowered_steps;
}

TEST(MultiLevelSelector, BothSelectorsAgainstTheOptimum) {
  double worst_greedy = 1, worst_multi = 1;
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    for (double share : {0.1, 0.3, 0.6}) {
      test::RandomScene s(120, seed, share);
      std::vector<uint8_t> opt(120);
      ASSERT_TRUE(optimal_choice(s.problem, 10, opt));
      const double o = benefit_of(s.problem, opt);
      uint64_t gc = 0, mc = 0;
      const double g = benefit_of(s.problem, s.heap_choice(Selector::greedy), &gc);
      const double m = benefit_of(s.problem, s.heap_choice(Selector::greedy_multi), &mc);
      EXPECT_LE(gc, s.problem.capacity);
      EXPECT_LE(mc, s.problem.capacity);
      EXPECT_LE(m, o * (1 + 1e-9));
      if (o > 0) worst_greedy = std::min(worst_greedy, g / o), worst_multi = std::min(worst_multi, m / o);
    }
  }
  EXPECT_GE(worst_greedy, 0.95) << "the span-of-level-changed heap's worst frame";
  EXPECT_GE(worst_multi, 0.90) << "greedy_multi gives up a little benefit for its pops";
  std::printf("worst fraction of the optimum: greedy %.4f, greedy_multi %.4f\n", worst_greedy, worst_multi);
}

TEST(SelectionQuality, BenefitIsTheOraclesAndPixelErrorTheProjectedError) {
  test::RandomScene s(40, 3, 0.3);
  const std::vector<uint8_t> chosen = s.heap_choice();
  std::vector<uint32_t> ids(40);
  for (uint32_t i = 0; i < 40; ++i) ids[i] = i;
  std::vector<uint8_t> mask(40, 1);
  mask[5] = 2;  // another view's object: not measured
  const SelectionQuality q =
      measure_selection_quality(ids, chosen, s.model, mask, 1, s.distance, s.area, s.scale, s.models, 1000.f);
  double want = 0, err_sum = 0, err_max = 0;
  for (size_t i = 0; i < 40; ++i) {
    if (i == 5) continue;
    want += s.problem.benefit[s.problem.first[i] + chosen[i]];
    const double e = s.models.error[s.models.first_level[s.model[i]] + chosen[i]] * 1000.0 / s.distance[i];
    err_sum += e;
    err_max = std::max(err_max, e);
  }
  EXPECT_NEAR(q.benefit, want, 1e-6 * want);
  EXPECT_EQ(q.measured, 39u);
  EXPECT_NEAR(q.pixel_error_sum, err_sum, 1e-6 * err_sum);
  EXPECT_NEAR(q.pixel_error_max, err_max, 1e-4 * err_max);
  // Parts merge to the whole.
  const auto part = [&](size_t b, size_t e) {
    return measure_selection_quality(std::span(ids).subspan(b, e - b), std::span(chosen).subspan(b, e - b),
                                     std::span(s.model).subspan(b, e - b), mask, 1, s.distance, s.area,
                                     s.scale, s.models, 1000.f);
  };
  const SelectionQuality merged = merge_quality(part(0, 17), part(17, 40));
  EXPECT_NEAR(merged.benefit, q.benefit, 1e-9 * q.benefit);
  EXPECT_EQ(merged.measured, q.measured);
  EXPECT_EQ(merged.pixel_error_max, q.pixel_error_max);
}

}  // namespace
}  // namespace lod
