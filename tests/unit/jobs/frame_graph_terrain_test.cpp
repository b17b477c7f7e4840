// The terrain node: ROAM under its share of M beside the other LOD nodes, in one budget.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <mutex>

#include "jobs/frame_graph.h"
#include "runtime/terrain_mesh_check.h"
#include "synthetic_scene.h"

namespace lod {
namespace {

// A 129 x 129 field of hills under the synthetic scene's square (half size `extent`).
std::shared_ptr<const TerrainModel> hills(float extent, float relief = 6.f, uint32_t samples = 129) {
  HeightField f;
  f.width = f.height = samples;
  f.cell_size_x = f.cell_size_y = 2 * extent / float(samples - 1);
  f.heights.resize(f.sample_count());
  for (uint32_t y = 0; y < f.height; ++y)
    for (uint32_t x = 0; x < f.width; ++x)
      f.heights[size_t(y) * f.width + x] =
          relief * std::sin(0.15f * 128 / float(samples - 1) * float(x)) * std::cos(0.1f * 128 / float(samples - 1) * float(y)) +
          0.1f * relief * std::sin(2.3f * float(x)) * std::sin(1.7f * float(y)) - 8.f;
  auto m = std::make_shared<TerrainModel>();
  m->roam = build_roam_terrain(f);
  for (glm::vec3& p : m->roam.positions) p -= glm::vec3(extent, 0, extent);
  m->pixel_error = 0.5f;
  return m;
}

struct TerrainScene {
  static constexpr float kExtent = 200;
  Scene scene = test::synthetic_scene(2000, kExtent);
  CameraPath path = test::synthetic_config(2000, kExtent).camera;
  std::shared_ptr<const TerrainModel> terrain = hills(kExtent);

  FrameGraphOptions options(uint32_t threads, uint64_t budget) const {
    FrameGraphOptions o;
    o.threads = threads;
    o.selection.budget = budget;
    o.grain = 256;
    o.measure_quality = true;
    o.terrain = terrain;
    return o;
  }
};

bool crack_free(const Frame& f, std::string* why) {
  std::vector<uint32_t> grid;
  for (uint32_t i : f.terrain_indices) grid.push_back(f.terrain_samples[i]);
  const TerrainMeshCheck c = check_terrain_mesh(grid, f.terrain_grid);
  *why = c.first_problem;
  return c.ok();
}

TEST(FrameGraphTerrain, TerrainAndObjectsShareOneBudget) {
  const TerrainScene t;
  // Half of what the objects alone would take: objects and terrain must compete.
  FrameGraphOptions free = t.options(1, UINT64_MAX);
  free.terrain.reset();
  FrameGraph alone(t.scene, free);
  Frame f0;
  alone.run(view_at(t.path, 0), f0);
  const uint64_t budget = f0.tris_selected / 2;
  FrameGraph g(t.scene, t.options(2, budget));
  Frame f;
  uint32_t lowered = 0;
  uint64_t min_share = UINT64_MAX, max_share = 0;
  for (uint32_t n = 0; n < 40; ++n) {
    g.run(view_at(t.path, n * 3), f);
    SCOPED_TRACE(n);
    ASSERT_GT(f.terrain_tris, 0u);
    EXPECT_EQ(f.terrain_grid, 129u);
    EXPECT_EQ(f.terrain_indices.size(), 3 * f.terrain_tris);
    EXPECT_LE(f.terrain_tris, f.terrain_share);
    EXPECT_GE(f.tris_selected, f.terrain_tris) << "the terrain counts in tris_selected";
    EXPECT_TRUE(f.over_budget || f.tris_selected <= budget) << f.tris_selected;
    std::string why;
    EXPECT_TRUE(crack_free(f, &why)) << why;
    lowered += f.levels_lowered > 0;
    min_share = std::min(min_share, f.terrain_share);
    max_share = std::max(max_share, f.terrain_share);
  }
  EXPECT_GT(lowered, 0u) << "the budget must bind for this test to mean anything";
  EXPECT_LT(min_share, max_share) << "the share moves by feedback";
}

// The feedback share as the joint importance ordering would split M: by screen-space error.
// A greedy ordering of terrain splits and object refinements by projected error refines
// whichever side has the larger worst error, so at its fixed point both sides' worst errors
// are equal (or one side is at a bound); the share moves towards that point by 6 % a frame.
// A 513 x 513 terrain that never meets its tau and 2,000 objects in M = 3,000,000 (the objects
// alone would take 6.2M): a gentle terrain (its worst error below the objects') ends at its
// minimum share; a rough one takes a large share and its worst error meets the objects'.
// One thread: kept out of the TSan list's FrameGraphTerrain prefix (nothing concurrent to see).
TEST(TerrainShareInTheGraph, GoesWhereTheScreenSpaceErrorIs) {
  TerrainScene t;
  const uint64_t budget = 3000000;
  struct End {
    double share = 0, worst_ratio = 1;
    float terrain_error = 0, objects_error = 0;
  };
  auto settle = [&](float relief) {
    FrameGraphOptions o = t.options(1, budget);
    auto m = std::make_shared<TerrainModel>(*hills(TerrainScene::kExtent, relief, 513));
    m->pixel_error = 0.01f;  // never met: the terrain always wants more
    m->min_share = 0.01f;
    o.terrain = m;
    FrameGraph g(t.scene, o);
    Frame f;
    End e;
    for (uint32_t n = 0; n < 70; ++n) {
      g.run(view_at(t.path, 60), f);  // one view: the share converges
      EXPECT_TRUE(!f.over_budget && f.tris_selected <= budget) << n << ": " << f.tris_selected;
      EXPECT_LE(f.terrain_tris, f.terrain_share);
      if (n < 55) continue;  // from half of M, 6 % a frame reaches 1 % in ~40 frames
      e.share += double(f.terrain_share) / 15;
      EXPECT_GT(f.levels_lowered, 0u) << "the budget binds";
      const double r = f.terrain_pixel_error / f.pixel_error_max;
      e.worst_ratio = std::max(e.worst_ratio, std::max(r, 1 / r));
    }
    e.terrain_error = f.terrain_pixel_error, e.objects_error = f.pixel_error_max;
    std::printf("relief %.0f: share %.0f of %llu, worst error terrain %.2f px, objects %.2f px\n", relief, e.share,
                (unsigned long long)budget, e.terrain_error, e.objects_error);
    return e;
  };
  const End gentle = settle(2.f), rough = settle(100.f);
  EXPECT_EQ(gentle.share, 0.01 * budget) << "its error is below the objects': the minimum share";
  EXPECT_LT(gentle.terrain_error, gentle.objects_error);
  EXPECT_GT(rough.share, 5 * gentle.share);
  EXPECT_LT(rough.worst_ratio, 1.5) << "the two worst errors meet";
}

TEST(FrameGraphTerrain, SameTerrainAtOneAndTwoThreads) {
  const TerrainScene t;
  FrameGraph a(t.scene, t.options(1, 60000)), b(t.scene, t.options(2, 60000));
  Frame fa, fb;
  for (uint32_t n = 0; n < 10; ++n) {
    a.run(view_at(t.path, n * 5), fa);
    b.run(view_at(t.path, n * 5), fb);
    ASSERT_EQ(fa.terrain_indices, fb.terrain_indices) << n;
    ASSERT_EQ(fa.terrain_share, fb.terrain_share) << n;
    ASSERT_EQ(fa.levels, fb.levels) << n;
  }
}

TEST(FrameGraphTerrain, WithoutTerrainTheColumnsStayEmpty) {
  const TerrainScene t;
  FrameGraphOptions o = t.options(2, 60000);
  o.terrain.reset();
  FrameGraph g(t.scene, o);
  Frame f;
  g.run(view_at(t.path, 0), f);
  EXPECT_EQ(f.terrain_tris, 0u);
  EXPECT_EQ(f.terrain_grid, 0u);
  EXPECT_TRUE(f.terrain_positions.empty());
}

TEST(FrameGraphTerrain, BudgetTooSmallForTheTerrainIsOverBudget) {
  const TerrainScene t;
  FrameGraph g(t.scene, t.options(2, 2));
  Frame f;
  g.run(view_at(t.path, 0), f);
  EXPECT_EQ(f.terrain_tris, 2u) << "the two base triangles at least";
  EXPECT_TRUE(f.over_budget) << "M = 2 cannot hold terrain and objects";
}

TEST(FrameGraphTerrain, NodeFollowsViewAndPrecedesPublish) {
  const std::string dot = FrameGraph::dot();
  EXPECT_NE(dot.find("view -> terrain;"), std::string::npos) << dot;
  EXPECT_NE(dot.find("terrain -> publish;"), std::string::npos) << dot;
  EXPECT_EQ(dot.find("selection -> terrain;"), std::string::npos) << "terrain runs beside selection";
  const TerrainScene t;
  FrameGraphOptions o = t.options(2, 60000);
  std::mutex mutex;
  std::vector<Stage> seen;
  o.stage_hook = [&](Stage s) {
    std::lock_guard lock(mutex);
    seen.push_back(s);
  };
  FrameGraph g(t.scene, o);
  Frame f;
  g.run(view_at(t.path, 0), f);
  auto at = [&](Stage s) { return std::find(seen.begin(), seen.end(), s) - seen.begin(); };
  EXPECT_LT(at(Stage::view), at(Stage::terrain));
  EXPECT_LT(at(Stage::terrain), at(Stage::publish));
  EXPECT_GE(f.stage_ms[size_t(Stage::terrain)], 0.0);
}

}  // namespace
}  // namespace lod
