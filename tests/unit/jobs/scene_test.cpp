// Scene: instance placement and world bounding spheres.
#include "jobs/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "unit/jobs/synthetic_scene.h"

namespace lod {
namespace {

SceneConfig one_block(uint32_t count, bool grid, uint64_t seed = 5) {
  SceneConfig c;
  c.models.push_back(ModelConfig{"m", {}, {}});
  InstanceConfig i;
  i.count = count;
  i.grid = grid;
  i.box_min[0] = -10, i.box_min[1] = 2, i.box_min[2] = -30;
  i.box_max[0] = 10, i.box_max[1] = 4, i.box_max[2] = 30;
  i.scale_min = 0.5f, i.scale_max = 2.0f;
  i.seed = seed;
  c.instances.push_back(i);
  return c;
}

std::vector<LodChain> one_chain() { return {test::synthetic_chain("m", {1000, 500, 250}, 0.01f, 1.0f)}; }

TEST(Scene, RandomPlacementStaysInTheBoxAndScaleRange) {
  const ObjectSet o = place_instances(one_block(500, false), one_chain());
  ASSERT_EQ(o.size(), 500u);
  for (size_t i = 0; i < o.size(); ++i) {
    EXPECT_GE(o.x[i], -10);
    EXPECT_LE(o.x[i], 10);
    EXPECT_GE(o.y[i], 2);
    EXPECT_LE(o.y[i], 4);
    EXPECT_GE(o.z[i], -30);
    EXPECT_LE(o.z[i], 30);
    EXPECT_GE(o.scale[i], 0.5f);
    EXPECT_LE(o.scale[i], 2.0f);
    EXPECT_GE(o.yaw[i], 0.f);
    EXPECT_LT(o.yaw[i], 6.2832f);
    EXPECT_EQ(o.model[i], 0u);
  }
}

TEST(Scene, PlacementIsDeterministicPerSeed) {
  const ObjectSet a = place_instances(one_block(100, false, 7), one_chain());
  const ObjectSet b = place_instances(one_block(100, false, 7), one_chain());
  const ObjectSet c = place_instances(one_block(100, false, 8), one_chain());
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.z, b.z);
  EXPECT_EQ(a.yaw, b.yaw);
  EXPECT_EQ(a.scale, b.scale);
  EXPECT_NE(a.x, c.x);
}

TEST(Scene, GridFillsTheBoxWithDistinctCells) {
  const ObjectSet o = place_instances(one_block(10, true), one_chain());
  ASSERT_EQ(o.size(), 10u);
  // ceil(sqrt(10)) = 4 columns over x in [-10, 10] -> cell centres -7.5, -2.5, 2.5, 7.5;
  // 3 rows over z in [-30, 30] -> -20, 0, 20; y in the middle of [2, 4].
  std::set<std::pair<float, float>> cells;
  for (size_t i = 0; i < o.size(); ++i) {
    cells.insert({o.x[i], o.z[i]});
    EXPECT_FLOAT_EQ(o.y[i], 3.0f);
  }
  EXPECT_EQ(cells.size(), 10u);
  EXPECT_FLOAT_EQ(o.x[0], -7.5f);
  EXPECT_FLOAT_EQ(o.z[0], -20.f);
  EXPECT_FLOAT_EQ(o.x[3], 7.5f);
  EXPECT_FLOAT_EQ(o.x[4], -7.5f);
  EXPECT_FLOAT_EQ(o.z[4], 0.f);
  EXPECT_FLOAT_EQ(o.z[9], 20.f);
}

TEST(Scene, GridOfOneSitsInTheMiddle) {
  const ObjectSet o = place_instances(one_block(1, true), one_chain());
  ASSERT_EQ(o.size(), 1u);
  EXPECT_FLOAT_EQ(o.x[0], 0.f);
  EXPECT_FLOAT_EQ(o.z[0], 0.f);
}

TEST(Scene, WorldSphereIsTheRotatedScaledModelSphere) {
  std::vector<LodChain> chains = one_chain();
  for (LodLevel& l : chains[0].levels) {
    l.bounds.center[0] = 2, l.bounds.center[1] = 1, l.bounds.center[2] = 0;
    l.bounds.radius = 3;
  }
  const ObjectSet o = place_instances(one_block(50, false), chains);
  for (size_t i = 0; i < o.size(); ++i) {
    const float c = std::cos(o.yaw[i]), s = std::sin(o.yaw[i]), k = o.scale[i];
    // glm::rotate(yaw, +y) maps (2, 1, 0) to (2 cos, 1, -2 sin).
    EXPECT_NEAR(o.cx[i], o.x[i] + k * 2 * c, 1e-4);
    EXPECT_NEAR(o.cy[i], o.y[i] + k * 1, 1e-4);
    EXPECT_NEAR(o.cz[i], o.z[i] - k * 2 * s, 1e-4);
    EXPECT_FLOAT_EQ(o.radius[i], 3 * k);
  }
}

TEST(Scene, WorldSphereAlsoHoldsCoarserLevelsThatBulge) {
  std::vector<LodChain> chains = one_chain();
  chains[0].levels[2].bounds.center[0] += 0.5f;  // a coarse level reaching past level 0
  chains[0].levels[2].bounds.radius = 1.0f;
  const ObjectSet o = place_instances(one_block(3, false), chains);
  for (size_t i = 0; i < o.size(); ++i) EXPECT_FLOAT_EQ(o.radius[i], 1.5f * o.scale[i]);
}

TEST(Scene, BlocksFollowEachOtherInConfigOrder) {
  SceneConfig c = one_block(4, false);
  c.models.push_back(ModelConfig{"n", {}, {}});
  InstanceConfig second = c.instances[0];
  second.model = 1;
  second.count = 3;
  c.instances.push_back(second);
  std::vector<LodChain> chains = one_chain();
  chains.push_back(test::synthetic_chain("n", {800, 400}, 0.01f, 2.0f));
  const Scene scene = make_scene(c, chains);
  ASSERT_EQ(scene.objects.size(), 7u);
  EXPECT_EQ(scene.objects.model, (std::vector<uint32_t>{0, 0, 0, 0, 1, 1, 1}));
  EXPECT_EQ(scene.models.model_count(), 2u);
  EXPECT_EQ(scene.chains.size(), 2u);
  EXPECT_EQ(scene.models.level_count[1], 2u);
}

}  // namespace
}  // namespace lod
