#include "preprocess/decimater_chain.h"

#include <gtest/gtest.h>

#include <cmath>
#include <thread>

#include "preprocess/mesh_clean.h"
#include "preprocess/mesh_io.h"
#include "test_support.h"

namespace lod {
namespace {

MeshData sphere(int rings, int segments) {
  const auto dir = test::temp_dir("chain-sphere");
  test::write_text(dir / "s.off", test::sphere_off(rings, segments));
  MeshData m;
  const Status s = load_mesh(dir / "s.off", m);
  EXPECT_TRUE(s.ok) << s.message;
  return m;
}

void expect_level_well_formed(const ChainLevel& l) {
  ASSERT_EQ(l.positions.size() % 3, 0u);
  ASSERT_EQ(l.normals.size(), l.positions.size());
  ASSERT_EQ(l.indices.size() % 3, 0u);
  std::vector<uint8_t> used(l.vertex_count(), 0);
  for (uint32_t i : l.indices) {
    ASSERT_LT(i, l.vertex_count());
    used[i] = 1;
  }
  // Compact: every vertex of a level is used by one of its triangles.
  for (uint8_t u : used) EXPECT_EQ(u, 1);
  for (size_t v = 0; v < l.vertex_count(); ++v) {
    const float* n = &l.normals[3 * v];
    EXPECT_NEAR(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), 1.0f, 1e-4f);
  }
}

TEST(DecimaterChain, ReachesEachTargetOnASphere) {
  const MeshData m = sphere(40, 60);  // 4,680 triangles
  const std::vector<float> ratios = {1.0f, 0.5f, 0.25f, 0.12f, 0.06f};
  std::vector<ChainLevel> levels;
  DecimaterChainStats stats;
  std::vector<float> progress;
  const Status s = bake_decimater_chain(m, ratios, levels, &stats, [&](float f) { progress.push_back(f); });
  ASSERT_TRUE(s.ok) << s.message;
  ASSERT_EQ(levels.size(), ratios.size());
  EXPECT_EQ(levels[0].triangle_count(), m.triangle_count());
  for (size_t i = 0; i < levels.size(); ++i) {
    expect_level_well_formed(levels[i]);
    const double target = ratios[i] * double(m.triangle_count());
    EXPECT_EQ(levels[i].target_triangles, size_t(std::llround(target)));
    EXPECT_NEAR(double(levels[i].triangle_count()), target, 0.02 * target) << "level " << i;
  }
  EXPECT_TRUE(stats.notes.empty());
  EXPECT_EQ(stats.refused_faces, 0u);
  EXPECT_GT(stats.collapses, m.triangle_count() / 2 * 9 / 10);
  ASSERT_FALSE(progress.empty());
  for (size_t i = 1; i < progress.size(); ++i) EXPECT_GE(progress[i], progress[i - 1]);
  EXPECT_EQ(progress.back(), 1.0f);
}

TEST(DecimaterChain, KeepsNonManifoldFacesInLevelZero) {
  // Four triangles on edge (0,1): OpenMesh refuses the third and fourth (complex edge).
  MeshData m;
  m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0.5f, 0.5f, 0.5f};
  m.indices = {0, 1, 2, 1, 0, 3, 0, 1, 4, 0, 1, 5};
  std::vector<ChainLevel> levels;
  DecimaterChainStats stats;
  const std::vector<float> ratios = {1.0f};
  ASSERT_TRUE(bake_decimater_chain(m, ratios, levels, &stats, nullptr).ok);
  EXPECT_EQ(levels[0].triangle_count(), 4u);
  EXPECT_GE(stats.refused_faces, 1u);
  EXPECT_GE(stats.copied_vertices, 1u);
  expect_level_well_formed(levels[0]);
}

TEST(DecimaterChain, NotesALevelThatCannotReachItsTarget) {
  // A single tetrahedron cannot lose 94 % of its four faces.
  MeshData m;
  m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  m.indices = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  std::vector<ChainLevel> levels;
  DecimaterChainStats stats;
  const std::vector<float> ratios = {1.0f, 0.06f};
  ASSERT_TRUE(bake_decimater_chain(m, ratios, levels, &stats, nullptr).ok);
  ASSERT_EQ(levels.size(), 2u);
  EXPECT_EQ(levels[1].target_triangles, 1u);
  EXPECT_GT(levels[1].triangle_count(), 1u);
  ASSERT_EQ(stats.notes.size(), 1u);
  EXPECT_NE(stats.notes[0].find("level 1"), std::string::npos) << stats.notes[0];
}

TEST(DecimaterChain, RefusesBadRatiosAndEmptyInput) {
  const MeshData m = sphere(6, 8);
  std::vector<ChainLevel> levels;
  for (const std::vector<float>& bad : {std::vector<float>{}, std::vector<float>{1.0f, 0.5f, 0.5f},
                                        std::vector<float>{1.0f, 0.0f}, std::vector<float>{1.5f},
                                        std::vector<float>{1.0f, NAN}}) {
    EXPECT_FALSE(bake_decimater_chain(m, bad, levels, nullptr, nullptr).ok);
  }
  MeshData empty;
  const std::vector<float> one = {1.0f};
  EXPECT_FALSE(bake_decimater_chain(empty, one, levels, nullptr, nullptr).ok);
}

TEST(DecimaterChain, GivesTheSameChainWhenRunConcurrently) {
  // Non-manifold input makes OpenMesh complain on omerr(), which is silenced under the
  // shared OpenMesh lock; several threads must still get identical, complete chains.
  MeshData m = sphere(16, 20);
  const size_t n = m.vertex_count();
  m.positions.insert(m.positions.end(), {0, 0, 2});
  m.indices.insert(m.indices.end(), {m.indices[0], m.indices[1], uint32_t(n)});  // a fin on edge 0
  const std::vector<float> ratios = {1.0f, 0.5f, 0.25f};
  std::vector<ChainLevel> ref;
  ASSERT_TRUE(bake_decimater_chain(m, ratios, ref, nullptr, nullptr).ok);
  std::vector<ChainLevel> out[4];
  Status st[4];
  std::vector<std::thread> threads;
  for (int i = 0; i < 4; ++i)
    threads.emplace_back([&, i] { st[i] = bake_decimater_chain(m, ratios, out[i], nullptr, nullptr); });
  for (std::thread& t : threads) t.join();
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(st[i].ok);
    ASSERT_EQ(out[i].size(), ref.size());
    for (size_t l = 0; l < ref.size(); ++l) {
      EXPECT_EQ(out[i][l].indices, ref[l].indices);
      EXPECT_EQ(out[i][l].positions, ref[l].positions);
    }
  }
  EXPECT_EQ(ref[0].triangle_count(), m.triangle_count());
}

TEST(DecimaterChain, CowChainHitsTheReferenceRatios) {
  std::filesystem::path cow;
  if (!test::shared_meshes().empty() && std::filesystem::exists(test::shared_meshes() / "cow.obj"))
    cow = test::shared_meshes() / "cow.obj";
  else if (!test::data_dir().empty())
    cow = test::data_dir() / "cow.off";
  else
    GTEST_SKIP() << "needs ../shared/data/meshes/cow.obj or the CGAL cow.off (absent on this machine)";
  MeshData m;
  ASSERT_TRUE(load_mesh(cow, m).ok);
  clean_mesh(m);
  const std::vector<float> ratios = {1.0f, 0.5f, 0.25f, 0.12f, 0.06f};
  std::vector<ChainLevel> levels;
  DecimaterChainStats stats;
  ASSERT_TRUE(bake_decimater_chain(m, ratios, levels, &stats, nullptr).ok);
  for (size_t i = 0; i < levels.size(); ++i) {
    const double target = ratios[i] * double(m.triangle_count());
    EXPECT_NEAR(double(levels[i].triangle_count()), target, 0.02 * target) << "level " << i;
    expect_level_well_formed(levels[i]);
  }
}

TEST(VertexNormals, AreAreaWeightedAndUnit) {
  // Two triangles at a right angle sharing edge (0,1); the larger one dominates.
  const std::vector<float> p = {0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 1};
  const std::vector<uint32_t> idx = {0, 1, 2, 1, 0, 3};
  std::vector<float> n(p.size());
  compute_vertex_normals(p.data(), 4, idx.data(), idx.size(), n.data());
  // Vertex 0: (0,0,1)*2 + (0,1,0)*1 (cross products of both faces), normalised.
  EXPECT_NEAR(n[0], 0.0f, 1e-6f);
  EXPECT_NEAR(n[1], 1.0f / std::sqrt(5.0f), 1e-6f);
  EXPECT_NEAR(n[2], 2.0f / std::sqrt(5.0f), 1e-6f);
  EXPECT_NEAR(n[8], 1.0f, 1e-6f);  // vertex 2 only in the z-facing triangle
}

}  // namespace
}  // namespace lod
