// The public ServiceOptions for budget modes reach the frame graph: max_distance leaves far
// objects out (counted culled), the selector is chosen, and an asset with a culled level loads.
#include <gtest/gtest.h>

#include "jobs/service.h"
#include "runtime/lod_asset.h"
#include "test_support.h"
#include "unit/jobs/box_chain.h"

namespace lod {
namespace {

TEST(ServiceBudgetModes, OptionsReachTheFrameAndACulledAssetLoads) {
  LodChain chain = test::box_chain("box", 1, 1, 1);
  LodLevel culled;
  culled.first_index = static_cast<uint32_t>(chain.indices.size());
  culled.first_vertex = static_cast<uint32_t>(chain.positions.size() / 3);
  culled.error = 4;
  culled.bounds = chain.levels[0].bounds;
  chain.levels.push_back(culled);
  const auto file = test::temp_dir("service-budget") / "box.lod";
  ASSERT_TRUE(write_lod_asset(file, chain));

  ServiceOptions o;
  o.threads = 1;
  o.max_distance = 50;
  o.selector = BudgetSelector::greedy_multi;
  o.budget = 12 * 5;  // five boxes drawn, the rest must go to the culled level
  Service service(o);
  ModelId model = 0;
  ASSERT_TRUE(service.add_model(file, &model)) << service.last_error();
  for (int i = 0; i < 20; ++i) {  // boxes at z = -5, -10, ... -100 in front of the camera
    Transform t;
    t.position[2] = -5.0f * float(i + 1);
    ASSERT_NE(service.create(model, t), 0u);
  }
  service.commit(1);
  Camera camera;
  camera.eye[1] = 1;
  camera.forward[0] = 0, camera.forward[1] = 0, camera.forward[2] = -1;
  ASSERT_TRUE(service.set_view(0, camera));
  ASSERT_TRUE(service.step(1.0 / 60));
  const FrameRef f = service.acquire_frame();
  ASSERT_TRUE(f);
  EXPECT_EQ(f->visible, 10u) << "boxes up to 50 m (plus their radius) are in range";
  uint32_t at_culled = 0;
  for (uint8_t l : f->levels) at_culled += l == 1;
  EXPECT_EQ(at_culled, 5u);
  EXPECT_EQ(f->culled, 10u + 5u) << "10 beyond max_distance, 5 at the culled level";
  EXPECT_EQ(f->tris_selected, 60u);
  EXPECT_FALSE(f->over_budget);
}

}  // namespace
}  // namespace lod
