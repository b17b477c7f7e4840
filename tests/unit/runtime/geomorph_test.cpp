#include "runtime/geomorph.h"

#include <gtest/gtest.h>

#include <random>

#include "vd_fixture.h"

namespace lod {
namespace {

TEST(Geomorph, LerpEndpointsAreExact) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1e4f, 1e4f);
  std::vector<float> from(300), to(300), out(300);
  for (size_t i = 0; i < from.size(); ++i) from[i] = u(rng), to[i] = u(rng) * 1e-3f;
  geomorph_lerp(out, from, to, 0.f);
  EXPECT_EQ(out, from);
  geomorph_lerp(out, from, to, 1.f);
  EXPECT_EQ(out, to);
  geomorph_lerp(out, from, to, 7.f);  // clamped
  EXPECT_EQ(out, to);
  geomorph_lerp(out, from, to, 0.25f);
  for (size_t i = 0; i < out.size(); ++i) EXPECT_NEAR(out[i], 0.75f * from[i] + 0.25f * to[i], 1e-2f);
}

TEST(Geomorph, MorphFactorRisesLinearlyOverTheDuration) {
  EXPECT_EQ(morph_factor(1.0, 1.0, 0.5f), 0.f);
  EXPECT_FLOAT_EQ(morph_factor(1.25, 1.0, 0.5f), 0.5f);
  EXPECT_EQ(morph_factor(2.0, 1.0, 0.5f), 1.f);
  EXPECT_EQ(morph_factor(0.0, 1.0, 0.5f), 0.f);
  EXPECT_EQ(morph_factor(0.0, 1.0, 0.f), 1.f);  // no geomorphing
}

TEST(Geomorph, SplitStartsChildrenWhereTheParentIsShown) {
  const VertexTree t = test::square_tree();
  VertexMorph m;
  vertex_morph_init(m, t, 1.f);
  const FrontEvent split[] = {{4, FrontEventKind::split}};
  vertex_morph_apply(m, t, split, 10.0);
  float p[3];
  for (uint32_t c : {0u, 1u}) {
    vertex_morph_position(m, c, 10.0, p);
    EXPECT_EQ(p[0], 0.5f);  // at the parent
    vertex_morph_position(m, c, 11.0, p);
    EXPECT_EQ(p[0], t.positions[3 * c]);  // arrived, exactly
  }
  vertex_morph_position(m, 1, 10.5, p);
  EXPECT_FLOAT_EQ(p[0], 0.75f);  // halfway from 0.5 to 1
}

TEST(Geomorph, CollapseBeginMovesChildrenOntoTheParentAndCancelBringsThemBack) {
  const VertexTree t = test::square_tree();
  VertexMorph m;
  vertex_morph_init(m, t, 1.f);
  const FrontEvent begin[] = {{4, FrontEventKind::collapse_begin}};
  vertex_morph_apply(m, t, begin, 0.0);
  float p[3];
  vertex_morph_position(m, 1, 1.0, p);
  EXPECT_EQ(p[0], 0.5f);
  EXPECT_EQ(p[1], 0.f);
  // Cancelled halfway: the child turns back from where it is shown.
  const FrontEvent cancel[] = {{4, FrontEventKind::collapse_cancel}};
  vertex_morph_apply(m, t, cancel, 0.5);
  vertex_morph_position(m, 1, 0.5, p);
  EXPECT_FLOAT_EQ(p[0], 0.75f);
  vertex_morph_position(m, 1, 1.5, p);
  EXPECT_EQ(p[0], 1.f);
  // A finished collapse settles the parent at its own position.
  const FrontEvent done[] = {{4, FrontEventKind::collapse}};
  vertex_morph_apply(m, t, done, 2.0);
  std::vector<float> shown(3 * t.node_count(), -1);
  const uint32_t nodes[] = {2, 3, 4};
  EXPECT_EQ(vertex_morph_positions(shown, m, nodes, 2.0), 0u);
  EXPECT_EQ(shown[12], 0.5f);
  EXPECT_EQ(shown[0], -1.f);  // nodes not asked for are left alone
}

TEST(Geomorph, LevelTargetsFollowTheSourceMapping) {
  // Fine: 4 vertices from sources 10, 11, 12, 13; coarse kept 10 and 13 (as its 1 and 0).
  const std::vector<float> fine = {0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0};
  const std::vector<uint32_t> fine_src = {10, 11, 12, 13};
  const std::vector<float> coarse = {3.1f, 0, 0, 0.1f, 0, 0};
  const std::vector<uint32_t> coarse_src = {13, 10};
  std::vector<uint32_t> target(4);
  level_morph_targets(target, fine, fine_src, coarse, coarse_src);
  EXPECT_EQ(target, (std::vector<uint32_t>{1, 1, 0, 0}));  // kept by source, else nearest
  std::vector<float> out(12);
  level_morph_positions(out, fine, coarse, target, 0.f);
  EXPECT_EQ(out, fine);
  level_morph_positions(out, fine, coarse, target, 1.f);
  EXPECT_EQ(out[3], 0.1f);
  EXPECT_EQ(out[9], 3.1f);
}

TEST(Geomorph, LevelMorphRestartsOnAChangeAndSettles) {
  std::vector<float> morph = {1, 1, 0.5f};
  const std::vector<uint8_t> level = {2, 3, 1};
  const std::vector<uint8_t> prev = {2, 2, 1};
  EXPECT_EQ(advance_level_morph(morph, level, prev, 0.1f, 0.4f), 2u);
  EXPECT_EQ(morph[0], 1.f);
  EXPECT_EQ(morph[1], 0.f);
  EXPECT_FLOAT_EQ(morph[2], 0.75f);
  EXPECT_EQ(advance_level_morph(morph, level, level, 0.3f, 0.4f), 1u);
  EXPECT_EQ(morph[2], 1.f);
}

}  // namespace
}  // namespace lod

namespace lod {
namespace {

TEST(Geomorph, LevelTargetsMatchABruteForceNearestSearch) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-5, 5);
  std::vector<float> fine(3 * 500), coarse(3 * 60);
  for (float& x : fine) x = u(rng);
  for (float& x : coarse) x = u(rng) * 0.5f;  // a tighter cloud: many fine vertices lie outside its grid
  std::vector<uint32_t> fine_src(500), coarse_src(60);
  for (uint32_t i = 0; i < 500; ++i) fine_src[i] = 1000 + i;  // nothing survives
  for (uint32_t i = 0; i < 60; ++i) coarse_src[i] = i;
  std::vector<uint32_t> target(500);
  level_morph_targets(target, fine, fine_src, coarse, coarse_src);
  for (size_t v = 0; v < 500; ++v) {
    float best = 1e30f;
    uint32_t best_c = 0;
    for (uint32_t c = 0; c < 60; ++c) {
      float d2 = 0;
      for (int k = 0; k < 3; ++k)
        d2 += (fine[3 * v + k] - coarse[3 * c + k]) * (fine[3 * v + k] - coarse[3 * c + k]);
      if (d2 < best) best = d2, best_c = c;
    }
    ASSERT_EQ(target[v], best_c) << "fine vertex " << v;
  }
}

}  // namespace
}  // namespace lod

namespace lod {
namespace {

// C (fine vertex 1) collapsed into B, but QEM's placement left B far from C and D near it:
// the nearest coarse vertex is the wrong one, the collapse-following one is right.
//   T1 --- T2          fine: B=0 C=1 D=2 T1=3 T2=4 U=5
//   | \  / |  \        coarse (C gone): B=0 D=1 T1=2 T2=3 U=4
//   B -- C -- D
//     \  |  /
//        U
TEST(Geomorph, LevelTargetsFollowCollapsesWhereNearestWouldTearTheMesh) {
  const std::vector<float> fine = {0, 0, 0, 1.4f, 0, 0, 2, 0, 0, 0.5f, 1, 0, 1.5f, 1, 0, 1, -1, 0};
  const std::vector<uint32_t> fine_idx = {0, 1, 3, 1, 4, 3, 1, 2, 4, 0, 5, 1, 1, 5, 2};
  const std::vector<uint32_t> fine_src = {0, 1, 2, 3, 4, 5};
  const std::vector<float> coarse = {0, 0, 0, 2, 0, 0, 0.5f, 1, 0, 1.5f, 1, 0, 1, -1, 0};
  const std::vector<uint32_t> coarse_idx = {0, 3, 2, 0, 1, 3, 0, 4, 1};
  const std::vector<uint32_t> coarse_src = {0, 2, 3, 4, 5};
  std::vector<uint32_t> nearest(6), collapse(6);
  level_morph_targets(nearest, fine, fine_src, coarse, coarse_src);
  EXPECT_EQ(nearest[1], 1u);  // D: nearer, but wrong
  EXPECT_EQ(level_morph_misses(nearest, fine_idx, coarse_idx), 2u);  // B-D-T1 and D-T2-T1
  EXPECT_EQ(level_morph_targets_by_collapse(collapse, fine, fine_idx, fine_src, coarse, coarse_idx, coarse_src), 0u);
  EXPECT_EQ(collapse, (std::vector<uint32_t>{0, 0, 1, 2, 3, 4}));
}

TEST(Geomorph, LevelTargetsByCollapseKeepSurvivorsAndHandleAnEmptyCoarseLevel) {
  const std::vector<float> fine = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::vector<uint32_t> idx = {0, 1, 2};
  const std::vector<uint32_t> src = {7, 8, 9};
  std::vector<uint32_t> target(3, 99);
  // Everything survives (same sources): identity, whatever the positions.
  EXPECT_EQ(level_morph_targets_by_collapse(target, fine, idx, src, fine, idx, src), 0u);
  EXPECT_EQ(target, (std::vector<uint32_t>{0, 1, 2}));
  // Nothing to map into: targets untouched, the triangle lands nowhere.
  target = {5, 6, 7};
  EXPECT_EQ(level_morph_targets_by_collapse(target, fine, idx, src, {}, {}, {}), 1u);
  EXPECT_EQ(target, (std::vector<uint32_t>{5, 6, 7}));
}

// Texture coordinates travel with the positions: a split child's uv starts at its parent's
// shown uv and reaches its own, halfway at half the duration; a collapse takes them to the
// parent's and settles it there.
TEST(GeomorphUv, VertexUvsMorphWithThePositions) {
  VertexTree t = test::square_tree();
  t.uvs = {0, 0, 1, 0, 1, 1, 0, 1, 0.5f, 0};  // node 4 between its children 0 and 1
  std::string msg;
  ASSERT_TRUE(validate_vertex_tree(t, &msg)) << msg;
  VertexMorph m;
  vertex_morph_init(m, t, 1.f);
  const FrontEvent split[] = {{4, FrontEventKind::split}};
  vertex_morph_apply(m, t, split, 10.0);
  std::vector<float> uv(2 * size_t(t.node_count()), -1.f);
  const uint32_t nodes[] = {0, 1, 2, 3};
  vertex_morph_uvs(uv, m, nodes, 10.0);
  EXPECT_EQ(uv[0], 0.5f);  // both children at the parent's uv
  EXPECT_EQ(uv[2], 0.5f);
  EXPECT_EQ(uv[4], 1.f);  // untouched nodes show their own
  vertex_morph_uvs(uv, m, nodes, 10.5);
  EXPECT_FLOAT_EQ(uv[0], 0.25f);  // halfway from 0.5 to 0
  EXPECT_FLOAT_EQ(uv[2], 0.75f);  // halfway from 0.5 to 1
  vertex_morph_uvs(uv, m, nodes, 11.0);
  EXPECT_EQ(uv[0], 0.f);  // arrived, exactly
  EXPECT_EQ(uv[2], 1.f);
  const FrontEvent begin[] = {{4, FrontEventKind::collapse_begin}};
  vertex_morph_apply(m, t, begin, 20.0);
  vertex_morph_uvs(uv, m, nodes, 20.5);
  EXPECT_FLOAT_EQ(uv[0], 0.25f);  // on the way to the parent's 0.5
  EXPECT_FLOAT_EQ(uv[2], 0.75f);
  const FrontEvent collapse[] = {{4, FrontEventKind::collapse}};
  vertex_morph_apply(m, t, collapse, 21.0);
  const uint32_t parent[] = {4};
  vertex_morph_uvs(uv, m, parent, 21.0);
  EXPECT_EQ(uv[8], 0.5f);
  EXPECT_EQ(uv[9], 0.f);
}

// Discrete level blends: uvs (or any attribute) go from the level's own towards its morph
// target's in the coarser level, halfway at t = 0.5, exact at both ends.
TEST(GeomorphUv, LevelBlendPutsUvsHalfwayBetweenTheLevelsAndTheTargets) {
  const std::vector<float> fine = {0.1f, 0.2f, 0.9f, 0.3f, 0.4f, 0.8f};  // three vertices
  const std::vector<float> coarse = {0.f, 0.f, 1.f, 1.f};                // two
  const std::vector<uint32_t> target = {1, 0, 1};
  std::vector<float> out(fine.size());
  level_morph_attributes(out, fine, coarse, target, 2, 0.f);
  EXPECT_EQ(out, fine);
  level_morph_attributes(out, fine, coarse, target, 2, 0.5f);
  for (size_t v = 0; v < 3; ++v)
    for (int k = 0; k < 2; ++k)
      EXPECT_FLOAT_EQ(out[2 * v + k], 0.5f * (fine[2 * v + k] + coarse[2 * target[v] + k])) << v;
  level_morph_attributes(out, fine, coarse, target, 2, 1.f);
  EXPECT_EQ(out, (std::vector<float>{1, 1, 0, 0, 1, 1}));
}

}  // namespace
}  // namespace lod
