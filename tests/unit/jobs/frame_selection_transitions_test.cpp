// Selection is total: every selector, budget count and thread count gives a frame for a busy
// view under a binding budget, a view of nothing (the sky), a view of one object, and budgets
// below the coarsest levels, whichever of these came the frame before. With no hysteresis and
// no blends a frame depends only on its own view and budget, so after every transition it must
// equal the frame a fresh graph gives for the same view and budget.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "jobs/frame_graph.h"
#include "unit/jobs/synthetic_scene.h"

namespace lod {
namespace {

// Sparse enough (about 100 units between objects, radii up to 9) that a close view sees one.
Scene sparse_scene() { return test::synthetic_scene(400, 1000); }

View top_view() {
  View v;
  v.eye = {0, 2500, 1};
  v.target = {0, 0, 0};
  v.far_plane = 10000;
  return v;
}

View sky_view() {
  View v;
  v.eye = {0, 10, 0};
  v.target = {0, 1000, 0};
  v.up = {0, 0, 1};
  return v;
}

// Just past object 0's sphere, looking at it, far plane short of any neighbour.
View one_object_view(const Scene& scene) {
  const ObjectSet& o = scene.objects;
  View v;
  v.target = {o.cx[0], o.cy[0], o.cz[0]};
  v.eye = v.target + glm::vec3(0, 0, 3 * o.radius[0]);
  v.near_plane = 0.01f;
  v.far_plane = 5 * o.radius[0];
  return v;
}

struct State {
  std::string name;
  View view;
  uint64_t budget;
};

FrameGraphOptions options_for(Selector selector, BudgetCount count, uint32_t threads, uint64_t budget) {
  FrameGraphOptions o;
  o.threads = threads;
  o.grain = 64;  // several chunks, some with nothing visible
  o.selection.selector = selector;
  o.selection.count = count;
  o.selection.budget = budget;
  o.hysteresis = 0;
  o.geomorph_seconds = 0;
  o.measure_quality = true;  // the optimum oracle runs on small frames too
  return o;
}

uint64_t cost_of(const Frame& f, BudgetCount count) {
  return count == BudgetCount::triangles ? f.tris_selected : f.level_cost;
}

std::vector<State> states_for(const Scene& scene, Selector selector, BudgetCount count, uint32_t threads) {
  FrameGraph probe(scene, options_for(selector, count, threads, UINT64_MAX));
  Frame f;
  probe.run(top_view(), f);
  EXPECT_GT(f.visible, 100u) << "the busy view must see much of the scene";
  const uint64_t binding = f.coarsest_cost + (cost_of(f, count) - f.coarsest_cost) / 4;
  return {
      {"busy", top_view(), binding},          {"busy-loose", top_view(), UINT64_MAX},
      {"busy-below-coarsest", top_view(), 1}, {"sky", sky_view(), binding},
      {"sky-zero-budget", sky_view(), 0},     {"one", one_object_view(scene), binding},
      {"one-below-coarsest", one_object_view(scene), 1},
  };
}

void expect_same_selection(const Frame& got, const Frame& want, BudgetCount count, uint64_t budget) {
  EXPECT_EQ(got.visible, want.visible);
  EXPECT_EQ(got.objects, want.objects);
  EXPECT_EQ(got.levels, want.levels);
  EXPECT_EQ(got.tris_selected, want.tris_selected);
  EXPECT_EQ(got.level_cost, want.level_cost);
  EXPECT_EQ(got.coarsest_cost, want.coarsest_cost);
  EXPECT_EQ(got.over_budget, want.over_budget);
  EXPECT_EQ(got.lowered_steps, want.lowered_steps);
  EXPECT_EQ(got.over_budget, got.coarsest_cost > budget);
  if (!got.over_budget) {
    EXPECT_LE(cost_of(got, count), budget);
  }
}

class SelectionTransitions : public ::testing::TestWithParam<std::tuple<Selector, BudgetCount, uint32_t>> {};

TEST_P(SelectionTransitions, EveryTransitionGivesTheFreshFrame) {
  const auto [selector, count, threads] = GetParam();
  const Scene scene = sparse_scene();
  const std::vector<State> states = states_for(scene, selector, count, threads);

  std::vector<Frame> fresh(states.size());
  for (size_t s = 0; s < states.size(); ++s) {
    FrameGraph g(scene, options_for(selector, count, threads, states[s].budget));
    g.run(states[s].view, fresh[s]);
  }
  ASSERT_EQ(fresh[3].visible, 0u) << "the sky view must see nothing";
  ASSERT_EQ(fresh[5].visible, 1u) << "the close view must see exactly one object";
  ASSERT_GT(fresh[0].lowered_steps, 0u) << "the busy budget must bind";
  ASSERT_TRUE(fresh[2].over_budget);
  ASSERT_TRUE(fresh[6].over_budget);

  FrameGraph g(scene, options_for(selector, count, threads, states[0].budget));
  Frame f;
  for (size_t a = 0; a < states.size(); ++a)
    for (size_t b = 0; b < states.size(); ++b) {
      for (size_t s : {a, b}) {
        g.set_budget(states[s].budget);
        g.run(states[s].view, f);
        SCOPED_TRACE(states[a].name + " then " + states[b].name + ", at " + states[s].name);
        expect_same_selection(f, fresh[s], count, states[s].budget);
      }
    }
}

std::string case_name(const ::testing::TestParamInfo<SelectionTransitions::ParamType>& param) {
  const char* selectors[] = {"greedy", "greedy_multi", "benefit_cost"};
  const auto [selector, count, threads] = param.param;
  return std::string(selectors[int(selector)]) + (count == BudgetCount::triangles ? "_triangles_" : "_levels_") +
         std::to_string(threads) + "threads";
}

INSTANTIATE_TEST_SUITE_P(AllSelectors, SelectionTransitions,
                         ::testing::Combine(::testing::Values(Selector::greedy, Selector::greedy_multi,
                                                              Selector::benefit_cost),
                                            ::testing::Values(BudgetCount::triangles, BudgetCount::levels),
                                            ::testing::Values(1u, 2u)),
                         case_name);

}  // namespace
}  // namespace lod
