// Geomorphs of ROAM splits and merges: a split rises from its base edge, a merge lowers before
// it is removed, both monotone and ending exact; the drawn mesh stays crack-free and within the
// share on a flight with morphs in progress.
#include "runtime/terrain_morph.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "runtime/terrain_lod.h"
#include "runtime/terrain_mesh_check.h"

namespace lod {
namespace {

RoamTerrain make_terrain(uint32_t levels) {
  HeightField f;
  f.width = f.height = (1u << levels) + 1;
  f.heights.resize(f.sample_count());
  for (uint32_t y = 0; y < f.height; ++y)
    for (uint32_t x = 0; x < f.width; ++x)
      f.heights[size_t(y) * f.width + x] =
          6.f * std::sin(0.31f * float(x)) * std::cos(0.17f * float(y)) + 0.05f * float(x * y);
  return build_roam_terrain(f);
}

struct Morphing {
  RoamTerrain t = make_terrain(4);
  RoamState s;
  TerrainMorph m;
  explicit Morphing(float duration) {
    roam_reset(s, t);
    terrain_morph_reset(m, t, duration);
  }
  TerrainMorphStats at(double now) {
    const TerrainMorphStats st = terrain_morph_update(m, s, t, now, 1u << 20);
    s.events.clear();  // as roam_update does before its changes
    return st;
  }
  float mid(int32_t d) const {
    const auto e = roam_base_ends(t, d);
    return 0.5f * (m.height[e[0]] + m.height[e[1]]);
  }
  size_t drawn() {
    std::vector<uint32_t> idx;
    return roam_triangles_of(idx, m.shown, t);
  }
};

TEST(TerrainMorph, SplitRisesFromItsBaseEdgeMonotoneAndEndsExact) {
  Morphing k(1.0f);
  const int32_t d = k.t.root;
  roam_split(k.s, k.t, d);
  ASSERT_EQ(k.at(0.0).morphing, 1u);
  const float truth = k.t.positions[d].y, start = k.mid(d);
  ASSERT_NE(truth, start) << "the test needs a diamond with error";
  EXPECT_FLOAT_EQ(k.m.height[d], start) << "on the edge it splits: nothing moves on the frame of the split";
  float last = start;
  for (double now : {0.1, 0.3, 0.55, 0.9}) {
    k.at(now);
    const float h = k.m.height[d];
    EXPECT_TRUE(truth > start ? (h > last && h < truth) : (h < last && h > truth)) << now;
    last = h;
  }
  EXPECT_EQ(k.at(1.0).morphing, 0u);
  EXPECT_EQ(k.m.height[d], truth) << "ends exactly at the true height";
  EXPECT_EQ(k.drawn(), 4u);
}

TEST(TerrainMorph, MergeLowersBeforeItIsRemoved) {
  Morphing k(0.5f);
  const int32_t d = k.t.root;
  roam_split(k.s, k.t, d);
  k.at(0.0);
  k.at(1.0);  // settled
  roam_merge(k.s, k.t, d);
  ASSERT_EQ(k.s.triangle_count, 2u);
  TerrainMorphStats st = k.at(2.0);
  EXPECT_EQ(st.ghost_triangles, 2u);
  EXPECT_EQ(k.drawn(), 4u) << "still drawn split while it lowers";
  const float truth = k.t.positions[d].y, flat = k.mid(d);
  EXPECT_EQ(k.m.height[d], truth);
  float last = truth;
  for (double now : {2.1, 2.25, 2.4}) {
    k.at(now);
    const float h = k.m.height[d];
    EXPECT_TRUE(flat > truth ? (h > last && h < flat) : (h < last && h > flat)) << now;
    last = h;
  }
  st = k.at(2.5);
  EXPECT_EQ(st.morphing, 0u);
  EXPECT_EQ(st.ghost_triangles, 0u);
  EXPECT_EQ(k.drawn(), 2u) << "removed once flat";
}

TEST(TerrainMorph, SplitAgainWhileLoweringRisesFromWhereItIs) {
  Morphing k(1.0f);
  const int32_t d = k.t.root;
  roam_split(k.s, k.t, d);
  k.at(0.0);
  k.at(1.0);
  roam_merge(k.s, k.t, d);
  k.at(2.0);
  k.at(2.4);
  const float t_lowered = terrain_morph_factor(k.m, d, 2.4);
  EXPECT_NEAR(t_lowered, 0.6f, 1e-5f);
  roam_split(k.s, k.t, d);
  k.at(2.4);
  EXPECT_NEAR(k.m.factor[d], 0.6f, 1e-5f) << "no jump";
  k.at(2.6);
  EXPECT_NEAR(k.m.factor[d], 0.8f, 1e-5f);
  k.at(2.8);
  EXPECT_EQ(k.m.height[d], k.t.positions[d].y);
}

TEST(TerrainMorph, MergedParentWaitsForItsLoweringChildren) {
  Morphing k(1.0f);
  const int32_t root = k.t.root;
  roam_split(k.s, k.t, root);
  k.at(0.0);
  const int32_t child = k.t.children[root][0];
  roam_split(k.s, k.t, child);  // forces its other parent too
  k.at(0.5);
  k.at(2.0);
  // Merge everything below the root, then the root, in one frame.
  while (!k.s.merge_queue.heap.empty()) roam_merge(k.s, k.t, k.s.merge_queue.heap.front());
  ASSERT_EQ(k.s.triangle_count, 2u);
  k.at(2.0);
  for (double now = 2.0; now <= 3.2; now += 0.1) {
    k.at(now);
    std::vector<uint32_t> idx;
    roam_triangles_of(idx, k.m.shown, k.t);
    const TerrainMeshCheck c = check_terrain_mesh(idx, k.t.size);
    ASSERT_TRUE(c.ok()) << now << ": " << c.first_problem;
    for (int32_t d = 0; d < int32_t(k.m.shown.size()); ++d)
      if (k.m.shown[d])
        for (int32_t p : k.t.parents[d]) ASSERT_TRUE(p < 0 || k.m.shown[p]) << "drawn flags closed under parents";
  }
  EXPECT_EQ(k.drawn(), 2u);
}

View flight_view(const RoamTerrain& t, int frame) {
  const float side = float(t.size - 1);
  View v;
  const float a = 0.02f * float(frame);
  v.eye = {side * (0.5f + 0.3f * std::cos(a)), 9.f, side * (0.5f + 0.3f * std::sin(a))};
  v.target = v.eye + glm::vec3(-std::sin(a), -0.35f, std::cos(a));
  v.width = 640;
  v.height = 360;
  v.near_plane = 0.1f;
  v.far_plane = 8 * side;
  return v;
}

std::multiset<std::array<uint32_t, 3>> triangle_set(const std::vector<uint32_t>& idx) {
  std::multiset<std::array<uint32_t, 3>> out;
  for (size_t i = 0; i < idx.size(); i += 3) out.insert({idx[i], idx[i + 1], idx[i + 2]});
  return out;
}

class TerrainMorphFlight : public ::testing::TestWithParam<RoamTarget> {};

TEST_P(TerrainMorphFlight, DrawnMeshIsCrackFreeWithinTheShareAndSettlesOnRoams) {
  TerrainModel model;
  model.roam = make_terrain(6);
  model.pixel_error = 0.4f;
  model.target = GetParam();
  TerrainLod lod;
  terrain_lod_reset(lod, model, 0.3f);
  const uint64_t share = 1500;
  std::vector<float> pos;
  std::vector<uint32_t> idx, samples, grid;
  size_t frames_morphing = 0, most_lowering = 0, cut = 0;
  double now = 0;
  auto frame = [&](int i) {
    terrain_lod_update(lod, model, flight_view(model.roam, i), share, now);
    const size_t tris = terrain_compact_mesh(pos, idx, samples, lod, model.roam);
    EXPECT_LE(tris, share) << "frame " << i;
    grid.resize(idx.size());
    for (size_t j = 0; j < idx.size(); ++j) grid[j] = samples[idx[j]];
    const TerrainMeshCheck c = check_terrain_mesh(grid, model.roam.size);
    EXPECT_TRUE(c.ok()) << "frame " << i << ": " << c.first_problem;
    std::set<uint32_t> distinct(samples.begin(), samples.end());
    EXPECT_EQ(distinct.size(), samples.size()) << "one vertex (one height) per sample";
    for (size_t v = 0; v < samples.size(); ++v) {
      const int32_t d = int32_t(samples[v]);
      const float truth = model.roam.positions[d].y, y = pos[3 * v + 1];
      if (!lod.morph.in_active[d]) {
        EXPECT_EQ(y, truth);
        continue;
      }
      const auto e = roam_base_ends(model.roam, d);
      const float mid = 0.5f * (lod.morph.height[e[0]] + lod.morph.height[e[1]]);
      EXPECT_GE(y, std::min(mid, truth) - 1e-4f);
      EXPECT_LE(y, std::max(mid, truth) + 1e-4f);
    }
    frames_morphing += lod.last_morph.morphing > 0;
    most_lowering = std::max<size_t>(most_lowering, lod.last_morph.ghost_triangles);
    cut += lod.last_morph.cut_short;
  };
  for (int i = 0; i < 240; ++i, now += 1.0 / 60) frame(i);
  EXPECT_GT(frames_morphing, 100u) << "the flight must exercise the morphs";
  EXPECT_GT(most_lowering, 0u) << "and merges lowering";
  std::printf("frames morphing %zu of 240, most lowering triangles %zu, cut short %zu\n", frames_morphing,
              most_lowering, cut);
  for (int i = 0; i < 30; ++i, now += 1.0 / 60) frame(239);  // hover: every morph ends
  EXPECT_EQ(lod.last_morph.morphing, 0u);
  EXPECT_EQ(lod.morph.ghost_triangles, 0u);
  std::vector<uint32_t> roam;
  roam_triangles(roam, lod.roam, model.roam);
  grid.resize(idx.size());
  for (size_t j = 0; j < idx.size(); ++j) grid[j] = samples[idx[j]];
  EXPECT_EQ(triangle_set(grid), triangle_set(roam)) << "settled: the drawn mesh is ROAM's";
  for (size_t v = 0; v < samples.size(); ++v) EXPECT_EQ(pos[3 * v + 1], model.roam.positions[samples[v]].y);
}

INSTANTIATE_TEST_SUITE_P(Targets, TerrainMorphFlight, ::testing::Values(RoamTarget::pixel_error, RoamTarget::triangle_count));

TEST(TerrainMorph, ZeroDurationDrawsRoamsMeshEveryFrame) {
  TerrainModel model;
  model.roam = make_terrain(6);
  model.pixel_error = 0.4f;
  TerrainLod lod;
  terrain_lod_reset(lod, model, 0.f);
  std::vector<float> pos;
  std::vector<uint32_t> idx, samples, grid, roam;
  for (int i = 0; i < 80; ++i) {
    terrain_lod_update(lod, model, flight_view(model.roam, 3 * i), 4000, i / 60.0);
    terrain_compact_mesh(pos, idx, samples, lod, model.roam);
    grid.resize(idx.size());
    for (size_t j = 0; j < idx.size(); ++j) grid[j] = samples[idx[j]];
    roam_triangles(roam, lod.roam, model.roam);
    ASSERT_EQ(triangle_set(grid), triangle_set(roam)) << i;
    EXPECT_EQ(lod.last_morph.morphing, 0u);
  }
}

}  // namespace
}  // namespace lod
