// The three selectors in the frame graph and the Service: benefit_cost meets the same budget,
// and each frame's fraction of the optimum (measured where a frame has <= 300 entries) is in
// (0, 1], 1 when the budget is loose, and at least 1/2 for benefit_cost.
#include <gtest/gtest.h>

#include "jobs/frame_graph.h"
#include "jobs/service.h"
#include "runtime/lod_asset.h"
#include "test_support.h"
#include "unit/jobs/synthetic_scene.h"
#include "unit/runtime/runtime_fixtures.h"

namespace lod {
namespace {

FrameGraphOptions options(Selector s) {
  FrameGraphOptions o;
  o.threads = 2;
  o.grain = 64;
  o.selection.selector = s;
  o.measure_quality = true;
  return o;
}

TEST(FrameSelectors, EveryFrameHasItsFractionOfTheOptimumAndBenefitCostHoldsTheBudget) {
  const Scene scene = test::synthetic_scene(250, 120);
  const CameraPath path = test::synthetic_config(250, 120).camera;
  FrameGraphOptions probe_options = options(Selector::greedy);
  probe_options.selection.budget = UINT64_MAX;
  FrameGraph probe(scene, probe_options);
  Frame f;
  probe.run(view_at(path, 0), f);
  ASSERT_GT(f.visible, 20u);
  ASSERT_LE(f.visible, 300u) << "the oracle's limit";
  EXPECT_EQ(f.benefit_optimum_fraction, 1.0) << "loose: the initial levels are the optimum";
  EXPECT_TRUE(f.benefit_optimum_exact);
  const uint64_t budget = f.coarsest_cost + (f.tris_selected - f.coarsest_cost) / 5;
  for (Selector s : {Selector::greedy, Selector::greedy_multi, Selector::benefit_cost}) {
    FrameGraphOptions o = options(s);
    o.selection.budget = budget;
    FrameGraph g(scene, o);
    double worst = 1;
    for (uint32_t n = 0; n < 30; ++n) {
      g.run(view_at(path, n * 5), f);
      ASSERT_FALSE(f.over_budget);
      EXPECT_LE(f.tris_selected, budget);
      ASSERT_GT(f.benefit_optimum_fraction, 0.0) << "selector " << int(s) << " frame " << n;
      EXPECT_LE(f.benefit_optimum_fraction, 1.0);
      worst = std::min(worst, f.benefit_optimum_fraction);
    }
    if (s == Selector::benefit_cost) {
      EXPECT_GE(worst, 0.5) << "Funkhouser-Sequin's guarantee";
    }
    std::printf("selector %d: worst fraction of the optimum %.4f\n", int(s), worst);
  }
}

TEST(FrameSelectors, NoFractionWithoutQualityOrAboveTheEntryLimit) {
  const Scene big = test::synthetic_scene(3000, 150);
  const CameraPath path = test::synthetic_config(3000, 150).camera;
  Frame f;
  FrameGraph g(big, options(Selector::benefit_cost));
  g.run(view_at(path, 0), f);
  ASSERT_GT(f.visible, 300u);
  EXPECT_EQ(f.benefit_optimum_fraction, -1.0);
  FrameGraphOptions o = options(Selector::greedy);
  o.measure_quality = false;
  const Scene small = test::synthetic_scene(100, 100);
  FrameGraph quiet(small, o);
  quiet.run(view_at(test::synthetic_config(100, 100).camera, 0), f);
  EXPECT_EQ(f.benefit_optimum_fraction, -1.0);
}

TEST(ServiceSelectors, BenefitCostThroughTheServiceMeetsTheBudget) {
  ServiceOptions o;
  o.threads = 1;
  o.selector = BudgetSelector::benefit_cost;
  o.pixel_error = 0.01f;  // initial levels at full detail
  o.budget = 40 * 50 + 3000;
  const auto file = test::temp_dir("service-selectors") / "fan.lod";
  ASSERT_TRUE(write_lod_asset(file, test::fan_chain("fan", {400, 200, 100, 50})));
  Service service(o);
  ModelId model = 0;
  ASSERT_TRUE(service.add_model(file, &model)) << service.last_error();
  for (int i = 0; i < 40; ++i) {
    Transform t;
    t.position[0] = float(i % 8) * 3 - 12;
    t.position[2] = -4.0f * float(i / 8 + 1);
    ASSERT_NE(service.create(model, t), 0u);
  }
  service.commit(1);
  Camera camera;
  camera.forward[0] = 0, camera.forward[1] = 0, camera.forward[2] = -1;
  ASSERT_TRUE(service.set_view(0, camera));
  ASSERT_TRUE(service.step(1.0 / 60));
  const FrameRef f = service.acquire_frame();
  ASSERT_TRUE(f);
  ASSERT_GT(f->visible, 10u);
  EXPECT_LE(f->tris_selected, o.budget);
  EXPECT_GT(f->tris_selected, f->coarsest_cost) << "it raises some objects";
}

}  // namespace
}  // namespace lod
