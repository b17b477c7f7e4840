// Budget modes in the frame graph: objects at a culled level are entries that draw nothing and
// never blend; lod.max_distance drops far objects; greedy_multi meets the same budget; the
// frame's benefit, pixel error and level changes say what selection did.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "jobs/frame_graph.h"
#include "unit/jobs/synthetic_scene.h"

namespace lod {
namespace {

// The synthetic chains with a culled last level (a last ratio of 0).
Scene culled_scene(uint32_t count, float extent) {
  std::vector<LodChain> chains = test::synthetic_chains();
  for (LodChain& c : chains) {
    LodLevel l;
    l.first_index = c.levels.back().first_index + c.levels.back().index_count;
    l.error = 2 * c.levels.back().error + 2 * c.levels.front().bounds.radius;
    l.error_rms = l.error;
    l.bounds = c.levels.front().bounds;
    c.levels.push_back(l);
  }
  return make_scene(test::synthetic_config(count, extent), std::move(chains));
}

FrameGraphOptions options() {
  FrameGraphOptions o;
  o.threads = 2;
  o.grain = 64;
  o.selection.reserve_blends = false;
  o.geomorph_seconds = 0.25f;
  return o;
}

bool is_culled(const Scene& s, uint32_t model, uint8_t level) {
  return s.models.triangles[s.models.first_level[model] + level] == 0;
}

TEST(FrameBudgetModes, CulledEntriesDrawNothingAreCountedAndNeverBlend) {
  const Scene scene = culled_scene(3000, 250);
  const CameraPath path = test::synthetic_config(3000, 250).camera;
  FrameGraphOptions o = options();
  FrameGraph g(scene, o);
  Frame f;
  g.run(view_at(path, 0), f);
  // Less than every visible object at its coarsest drawn level: only culling reaches it.
  uint64_t coarsest_drawn = 0;
  for (size_t k = 0; k < f.visible; ++k) {
    const uint32_t m = f.models[k];
    coarsest_drawn += scene.models.triangles[scene.models.first_level[m] + scene.models.level_count[m] - 2];
  }
  const uint64_t budget = coarsest_drawn / 2;
  g.set_budget(budget);
  uint64_t culled_seen = 0, blends = 0;
  for (uint32_t n = 1; n < 40; ++n) {
    g.run(view_at(path, n), f);
    ASSERT_FALSE(f.over_budget) << "frame " << n << ": culling makes the budget reachable";
    EXPECT_LE(f.tris_selected, budget);
    uint32_t culled = 0;
    for (size_t k = 0; k < f.visible; ++k) {
      const bool to = is_culled(scene, f.models[k], f.levels[k]);
      const bool from = is_culled(scene, f.models[k], f.from_levels[k]);
      culled += to;
      if (f.from_levels[k] != f.levels[k]) {
        ++blends;
        EXPECT_FALSE(to || from) << "frame " << n << " entry " << k
                                 << ": a blend into or out of the culled level";
      }
    }
    EXPECT_EQ(f.culled, culled) << "frame " << n;
    culled_seen += culled;
  }
  EXPECT_GT(culled_seen, 0u);
  EXPECT_GT(blends, 0u) << "drawn levels still blend (else the test shows nothing)";
}

TEST(FrameBudgetModes, MaxDistanceDropsFarObjectsAndCountsThem) {
  const Scene scene = test::synthetic_scene(3000, 250);
  const View view = view_at(test::synthetic_config(3000, 250).camera, 0);
  FrameGraphOptions o = options();
  o.selection.budget = UINT64_MAX;
  FrameGraph all(scene, o);
  Frame everything;
  all.run(view, everything);
  o.max_distance = 120;
  FrameGraph near(scene, o);
  Frame f;
  near.run(view, f);
  ASSERT_GT(f.visible, 0u);
  ASSERT_LT(f.visible, everything.visible) << "the limit must cut something for this test to mean anything";
  EXPECT_EQ(f.culled, everything.visible - f.visible) << "one view: every object cut was in its frustum";
  for (size_t k = 0; k < f.visible; ++k) {
    const uint32_t i = f.objects[k];
    const float dx = scene.objects.cx[i] - view.eye.x, dy = scene.objects.cy[i] - view.eye.y,
                dz = scene.objects.cz[i] - view.eye.z;
    EXPECT_LE(std::sqrt(dx * dx + dy * dy + dz * dz) - scene.objects.radius[i], 120.f * (1 + 1e-5f));
  }
}

TEST(FrameBudgetModes, GreedyMultiMeetsTheSameBudgetWithFewerPops) {
  const Scene scene = test::synthetic_scene(5000, 300);
  const CameraPath path = test::synthetic_config(5000, 300).camera;
  FrameGraphOptions o = options();
  o.selection.budget = UINT64_MAX;
  FrameGraph probe(scene, o);
  Frame f;
  probe.run(view_at(path, 0), f);
  o.selection.budget = f.coarsest_cost + (f.tris_selected - f.coarsest_cost) / 4;
  uint64_t pops[2] = {0, 0}, lowered[2] = {0, 0};
  for (Selector s : {Selector::greedy, Selector::greedy_multi}) {
    o.selection.selector = s;
    FrameGraph g(scene, o);
    for (uint32_t n = 0; n < 20; ++n) {
      g.run(view_at(path, 0), f);
      ASSERT_FALSE(f.over_budget);
      EXPECT_LE(f.tris_selected, o.selection.budget);
      pops[int(s)] += f.lowered_steps;
      lowered[int(s)] += f.levels_lowered;
    }
  }
  EXPECT_EQ(pops[0], lowered[0]) << "greedy: one level per pop";
  ASSERT_GT(pops[0], 0u);
  EXPECT_LT(pops[1], pops[0]);
}

TEST(FrameBudgetModes, BenefitPixelErrorAndLevelChangesFollowTheBudget) {
  const Scene scene = test::synthetic_scene(3000, 250);
  const View view = view_at(test::synthetic_config(3000, 250).camera, 0);
  FrameGraphOptions o = options();
  o.selection.budget = UINT64_MAX;
  o.measure_quality = true;
  FrameGraph g(scene, o);
  Frame f;
  g.run(view, f);
  EXPECT_EQ(f.level_changes, 0u) << "nothing was visible before";
  EXPECT_LE(f.pixel_error_max, o.pixel_error * (1 + 1e-4f)) << "unbounded: every level within the threshold";
  EXPECT_GT(f.pixel_error_max, 0.f);
  EXPECT_LE(f.pixel_error_mean, f.pixel_error_max);
  const double free_benefit = f.benefit;
  ASSERT_GT(free_benefit, 0.0);
  const std::vector<uint8_t> before = f.levels;

  g.set_budget(f.tris_selected / 4);
  g.run(view, f);
  uint32_t changed = 0;
  for (size_t k = 0; k < f.visible; ++k) changed += f.levels[k] != before[k];
  ASSERT_GT(changed, 0u);
  EXPECT_EQ(f.level_changes, changed);
  EXPECT_LT(f.benefit, free_benefit) << "coarser levels are worth less";
  EXPECT_GT(f.pixel_error_max, o.pixel_error) << "a binding budget leaves more error than the threshold";
  g.run(view, f);
  EXPECT_EQ(f.level_changes, 0u) << "same view, same budget: levels hold";
}

}  // namespace
}  // namespace lod

namespace lod {
namespace {

TEST(FrameBudgetModes, QualityIsMeasuredOnlyWhenAsked) {
  const Scene scene = test::synthetic_scene(500, 100);
  const View view = view_at(test::synthetic_config(500, 100).camera, 0);
  FrameGraphOptions o = options();
  FrameGraph quiet(scene, o);
  Frame f;
  quiet.run(view, f);
  ASSERT_GT(f.visible, 0u);
  EXPECT_EQ(f.benefit, 0.0);
  EXPECT_EQ(f.pixel_error_max, 0.f);
  o.measure_quality = true;
  FrameGraph asked(scene, o);
  asked.run(view, f);
  EXPECT_GT(f.pixel_error_max, 0.f);
}

}  // namespace
}  // namespace lod
