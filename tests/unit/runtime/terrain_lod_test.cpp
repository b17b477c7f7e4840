// TerrainLod: the terrain's share of M by feedback, ROAM under it, and the frame mesh.
#include "runtime/terrain_lod.h"

#include <gtest/gtest.h>

#include <cmath>

#include "runtime/terrain_mesh_check.h"

namespace lod {
namespace {

TerrainModel make_model(uint32_t levels = 6) {
  HeightField f;
  f.width = f.height = (1u << levels) + 1;
  f.heights.resize(f.sample_count());
  for (uint32_t y = 0; y < f.height; ++y)
    for (uint32_t x = 0; x < f.width; ++x)
      f.heights[size_t(y) * f.width + x] = 5.f * std::sin(0.2f * float(x)) * std::cos(0.13f * float(y));
  TerrainModel m;
  m.roam = build_roam_terrain(f);
  m.pixel_error = 0.5f;
  return m;
}

View low_view(const TerrainModel& m) {
  const float side = float(m.roam.size - 1);
  View v;
  v.eye = {0.2f * side, 8.f, 0.2f * side};
  v.target = v.eye + glm::vec3(0.7f, -0.3f, 0.7f);
  v.width = 640;
  v.height = 360;
  v.near_plane = 0.1f;
  v.far_plane = 8 * side;
  return v;
}

TerrainFeedback feedback(uint64_t share, uint64_t tris, bool bound, uint64_t objects, bool lowered) {
  TerrainFeedback f;
  f.budget = 10000;
  f.share = share;
  f.terrain_tris = tris;
  f.terrain_bound = bound;
  f.objects_tris = objects;
  f.objects_lowered = lowered;
  return f;
}

TEST(TerrainShare, FirstShareIsTheInitialFractionOfM) {
  const TerrainModel m = make_model();
  EXPECT_EQ(first_terrain_share(10000, m), 5000u);
  EXPECT_EQ(first_terrain_share(0, m), m.max_triangles) << "levels budgets: the cap";
}

TEST(TerrainShare, TerrainThatMetItsErrorGetsWhatItUsedPlusRoomToGrow) {
  const TerrainModel m = make_model();
  EXPECT_EQ(next_terrain_share(feedback(5000, 1000, false, 2000, false), m), 1000u + 125 + 64);
}

TEST(TerrainShare, BoundTerrainTakesHalfTheRoomTheObjectsLeave) {
  const TerrainModel m = make_model();
  EXPECT_EQ(next_terrain_share(feedback(4000, 4000, true, 2000, false), m), 4000u + 2000);
}

TEST(TerrainShare, BothShortMoveTowardsTheLargerError) {
  const TerrainModel m = make_model();
  TerrainFeedback f = feedback(4000, 4000, true, 6000, true);
  f.terrain_error = 3, f.objects_error = 1;
  EXPECT_GT(next_terrain_share(f, m), 4000u);
  f.terrain_error = 1, f.objects_error = 3;
  EXPECT_LT(next_terrain_share(f, m), 4000u);
  f.objects_error = 0;
  EXPECT_EQ(next_terrain_share(f, m), 4000u) << "no measure: hold";
}

TEST(TerrainShare, StaysWithinTheFractionsAndLeavesTheObjectsTheirCoarsest) {
  const TerrainModel m = make_model();
  EXPECT_EQ(next_terrain_share(feedback(5000, 0, false, 0, false), m), 500u) << "min_share 5 %";
  EXPECT_EQ(next_terrain_share(feedback(9000, 9000, true, 0, false), m), 9000u) << "max_share 90 %";
  TerrainFeedback f = feedback(6000, 6000, true, 1000, false);
  f.objects_coarsest = 4000;
  EXPECT_LE(next_terrain_share(f, m), 10000u - 5000 - 64);
}

TEST(TerrainLod, MeshStaysWithinEveryShareAndCrackFree) {
  const TerrainModel m = make_model();
  TerrainLod lod;
  terrain_lod_reset(lod, m);
  std::vector<float> pos;
  std::vector<uint32_t> idx, samples, grid;
  for (uint64_t share : {4000u, 600u, 2500u, 50u, 10000u}) {
    const RoamFrameStats st = terrain_lod_update(lod, m, low_view(m), share);
    EXPECT_LE(st.triangles, share);
    const size_t tris = terrain_compact_mesh(pos, idx, samples, lod, m.roam);
    ASSERT_EQ(tris, st.triangles);
    grid.clear();
    for (uint32_t i : idx) grid.push_back(samples[i]);
    const TerrainMeshCheck c = check_terrain_mesh(grid, m.roam.size);
    EXPECT_TRUE(c.ok()) << c.first_problem;
  }
}

TEST(TerrainLod, CompactMeshHoldsEachUsedSampleOnceWithItsPosition) {
  const TerrainModel m = make_model();
  TerrainLod lod;
  terrain_lod_reset(lod, m);
  terrain_lod_update(lod, m, low_view(m), 3000);
  std::vector<float> pos;
  std::vector<uint32_t> idx, samples, direct;
  terrain_compact_mesh(pos, idx, samples, lod, m.roam);
  roam_triangles(direct, lod.roam, m.roam);
  ASSERT_EQ(idx.size(), direct.size());
  for (size_t i = 0; i < idx.size(); ++i) ASSERT_EQ(samples[idx[i]], direct[i]);
  std::vector<uint8_t> seen(m.roam.positions.size(), 0);
  for (size_t v = 0; v < samples.size(); ++v) {
    EXPECT_EQ(seen[samples[v]]++, 0) << "sample " << samples[v] << " twice";
    EXPECT_EQ(pos[3 * v + 1], m.roam.positions[samples[v]].y);
  }
  for (uint32_t r : lod.remap) ASSERT_EQ(r, UINT32_MAX) << "scratch left clean";
}

TEST(TerrainLod, TriangleTargetDrawsTheShare) {
  TerrainModel m = make_model();
  m.target = RoamTarget::triangle_count;
  TerrainLod lod;
  terrain_lod_reset(lod, m);
  const RoamFrameStats st = terrain_lod_update(lod, m, low_view(m), 1200);
  EXPECT_LE(st.triangles, 1200u);
  EXPECT_GE(st.triangles, 1198u);
}

}  // namespace
}  // namespace lod
