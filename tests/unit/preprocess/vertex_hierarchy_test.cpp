#include "preprocess/vertex_hierarchy.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "preprocess/mesh_clean.h"
#include "preprocess/mesh_io.h"
#include "runtime/vertex_front.h"
#include "test_support.h"
#include "vd_meshes.h"

namespace lod {
namespace {

VertexTree build(const MeshData& m, CollapseOrder order = CollapseOrder::quadric) {
  VertexTree t;
  HierarchyOptions o;
  o.order = order;
  const Status s = build_vertex_hierarchy(t, m, o);
  EXPECT_TRUE(s.ok) << s.message;
  std::string msg;
  EXPECT_TRUE(validate_vertex_tree(t, &msg)) << msg;
  return t;
}

// Faces as oriented triples rotated to start at their smallest id, as a sorted list.
std::vector<std::array<uint32_t, 3>> canonical(const uint32_t* idx, size_t tris) {
  std::vector<std::array<uint32_t, 3>> out;
  for (size_t f = 0; f < tris; ++f) {
    std::array<uint32_t, 3> c = {idx[3 * f], idx[3 * f + 1], idx[3 * f + 2]};
    std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
    out.push_back(c);
  }
  std::sort(out.begin(), out.end());
  return out;
}

size_t depth_of(const VertexTree& t) {
  std::vector<uint32_t> depth(t.node_count(), 0);
  size_t deepest = 0;
  for (uint32_t v = t.leaf_count; v < t.node_count(); ++v) {
    const uint32_t i = v - t.leaf_count;
    depth[v] = 1 + std::max(depth[t.children[2 * i]], depth[t.children[2 * i + 1]]);
    deepest = std::max<size_t>(deepest, depth[v]);
  }
  return deepest;
}

TEST(VertexHierarchy, ClosedSphereCollapsesToASmallBalancedBase) {
  const MeshData m = test::vd_sphere(24, 32);
  const VertexTree t = build(m);
  VertexFront f;
  front_init(f, t, 1);
  std::string msg;
  EXPECT_TRUE(check_front(f, t, EdgeCheck::closed, &msg)) << msg;
  EXPECT_LT(f.tri_count, m.triangle_count() / 20);
  EXPECT_GE(f.tri_count, 4u);  // never below a tetrahedron
  // Independent-set passes keep the forest O(log n) deep, not a chain.
  EXPECT_LT(depth_of(t), 60u);
}

TEST(VertexHierarchy, RefiningEverythingGivesTheInputExactly) {
  const MeshData m = test::vd_sphere(12, 16);
  const VertexTree t = build(m);
  VertexFront f;
  front_init(f, t, 1);
  front_refine_all(f, t);
  std::string msg;
  ASSERT_TRUE(check_front(f, t, EdgeCheck::closed, &msg)) << msg;
  EXPECT_EQ(f.active_count, m.vertex_count());
  EXPECT_EQ(canonical(f.tri_indices.data(), f.tri_count), canonical(m.indices.data(), m.triangle_count()));
  for (size_t i = 0; i < m.positions.size(); ++i) ASSERT_EQ(t.positions[i], m.positions[i]);
}

TEST(VertexHierarchy, CoarseningEverythingGivesTheBaseMesh) {
  const MeshData m = test::vd_concat(test::vd_sphere(10, 12), test::vd_grid(8, 8, 1, 3, 0));
  const VertexTree t = build(m);
  VertexFront base;
  front_init(base, t, 1);
  VertexFront f;
  front_init(f, t, 1);
  front_refine_all(f, t);
  front_coarsen_all(f, t);
  std::string msg;
  ASSERT_TRUE(check_front(f, t, EdgeCheck::oriented, &msg)) << msg;
  EXPECT_EQ(canonical(f.tri_indices.data(), f.tri_count), canonical(base.tri_indices.data(), base.tri_count));
  std::vector<uint32_t> a(f.active.begin(), f.active.begin() + f.active_count);
  std::vector<uint32_t> b(base.active.begin(), base.active.begin() + base.active_count);
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  EXPECT_EQ(a, b);
}

TEST(VertexHierarchy, OpenGridKeepsItsOutlineAndStaysValid) {
  const MeshData m = test::vd_grid(20, 16);
  const VertexTree t = build(m);
  VertexFront f;
  front_init(f, t, 1);
  std::string msg;
  EXPECT_TRUE(check_front(f, t, EdgeCheck::oriented, &msg)) << msg;
  EXPECT_LT(f.tri_count, m.triangle_count() / 4);
  // Border planes hold the outline: the base mesh still spans the grid's square.
  float lo[2] = {1e9f, 1e9f}, hi[2] = {-1e9f, -1e9f};
  for (uint32_t k = 0; k < f.active_count; ++k) {
    const float* p = &t.positions[3 * size_t(f.active[k])];
    lo[0] = std::min(lo[0], p[0]), hi[0] = std::max(hi[0], p[0]);
    lo[1] = std::min(lo[1], p[2]), hi[1] = std::max(hi[1], p[2]);
  }
  EXPECT_GT(hi[0] - lo[0], 0.9f);
  EXPECT_GT(hi[1] - lo[1], 0.9f);
  front_refine_all(f, t);
  EXPECT_EQ(canonical(f.tri_indices.data(), f.tri_count), canonical(m.indices.data(), m.triangle_count()));
}

TEST(VertexHierarchy, EveryComponentKeepsAtLeastOneTriangle) {
  MeshData m = test::vd_concat(test::vd_sphere(6, 8), test::vd_grid(4, 4, 1, 3, 0));
  // A lone triangle and a lone quad as components of their own.
  const uint32_t base = static_cast<uint32_t>(m.vertex_count());
  m.positions.insert(m.positions.end(),
                     {10, 0, 0, 11, 0, 0, 10, 1, 0, 20, 0, 0, 21, 0, 0, 21, 1, 0, 20, 1, 0});
  m.indices.insert(m.indices.end(),
                   {base, base + 1, base + 2, base + 3, base + 4, base + 5, base + 3, base + 5, base + 6});
  const VertexTree t = build(m);
  VertexFront f;
  front_init(f, t, 1);
  std::string msg;
  ASSERT_TRUE(check_front(f, t, EdgeCheck::oriented, &msg)) << msg;
  // The lone triangle survives whole; each component shows up in the base mesh.
  bool lone = false;
  for (uint32_t s = 0; s < f.tri_count; ++s) lone |= f.tri_face[s] == m.triangle_count() - 3;
  EXPECT_TRUE(lone);
  std::set<int> components;
  for (uint32_t s = 0; s < f.tri_count; ++s) {
    const float x = t.positions[3 * size_t(f.tri_indices[3 * s])];
    components.insert(x < 2 ? 0 : x < 5 ? 1 : x < 15 ? 2 : 3);
  }
  EXPECT_EQ(components.size(), 4u);
}

TEST(VertexHierarchy, ShortestEdgeOrderBuildsAValidForestToo) {
  const MeshData m = test::vd_concat(test::vd_sphere(10, 14), test::vd_grid(6, 6, 1, 3, 0));
  const VertexTree t = build(m, CollapseOrder::shortest);
  VertexFront f;
  front_init(f, t, 1);
  std::string msg;
  EXPECT_TRUE(check_front(f, t, EdgeCheck::oriented, &msg)) << msg;
  EXPECT_LT(f.tri_count, m.triangle_count() / 4);
  front_refine_all(f, t);
  EXPECT_EQ(canonical(f.tri_indices.data(), f.tri_count), canonical(m.indices.data(), m.triangle_count()));
}

TEST(VertexHierarchy, NodesBoundTheirChildrenAndNeverHaveLessError) {
  const VertexTree t = build(test::vd_sphere(16, 20));
  for (uint32_t v = t.leaf_count; v < t.node_count(); ++v) {
    const uint32_t i = v - t.leaf_count;
    for (int k = 0; k < 2; ++k) {
      const uint32_t c = t.children[2 * i + k];
      const float d =
          std::hypot(t.positions[3 * v] - t.positions[3 * c], t.positions[3 * v + 1] - t.positions[3 * c + 1],
                     t.positions[3 * v + 2] - t.positions[3 * c + 2]);
      EXPECT_LE(d + t.radius[c], t.radius[v] * 1.0001f + 1e-6f) << "node " << v;
      EXPECT_GE(t.error[v], t.error[c]) << "node " << v;
      // The child's cone axis lies inside the parent's cone whenever the parent's is narrow.
      if (t.cone_cos[v] > 0 && t.cone_cos[c] > 0) {
        const float dot = t.cone_axis[3 * v] * t.cone_axis[3 * c] +
                          t.cone_axis[3 * v + 1] * t.cone_axis[3 * c + 1] +
                          t.cone_axis[3 * v + 2] * t.cone_axis[3 * c + 2];
        EXPECT_GE(dot, t.cone_cos[v] - 1e-4f) << "node " << v;
      }
    }
    EXPECT_GT(t.error[v], 0.f);
  }
}

TEST(VertexHierarchy, DropsFacesWithARepeatedCorner) {
  MeshData m = test::vd_sphere(6, 8);
  const size_t real = m.triangle_count();
  m.indices.insert(m.indices.end(), {3, 3, 4});
  const VertexTree t = build(m);
  EXPECT_EQ(t.face_count, real);
}

TEST(VertexHierarchy, RefusesBadIndicesAndNonFinitePositionsNamingTheElement) {
  MeshData m = test::vd_sphere(6, 8);
  m.source = "ball.off";
  m.indices[7] = 9999;
  VertexTree t;
  Status s = build_vertex_hierarchy(t, m);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("ball.off"), std::string::npos);
  EXPECT_NE(s.message.find("face 2 references vertex 9999"), std::string::npos) << s.message;
  EXPECT_TRUE(t.empty());

  MeshData n = test::vd_sphere(6, 8);
  n.source = "nan.off";
  n.positions[4] = std::nanf("");
  s = build_vertex_hierarchy(t, n);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("vertex 1"), std::string::npos) << s.message;
}

TEST(VertexHierarchy, BowTieVertexStaysValidAtEveryFront) {
  // A second fan (one triangle) touching the grid at vertex 24 only.
  MeshData m = test::vd_grid(6, 6);
  const uint32_t base = static_cast<uint32_t>(m.vertex_count());
  m.positions.insert(m.positions.end(), {0.5f, 1, 0.5f, 0.6f, 1, 0.4f});
  m.indices.insert(m.indices.end(), {24, base, base + 1});
  const VertexTree t = build(m);
  VertexFront f;
  front_init(f, t, 1);
  std::string msg;
  EXPECT_TRUE(check_front(f, t, EdgeCheck::oriented, &msg)) << msg;
  EXPECT_EQ(t.parent[24], kNoNode);  // a non-manifold vertex is never collapsed
  front_refine_all(f, t);
  EXPECT_TRUE(check_front(f, t, EdgeCheck::oriented, &msg)) << msg;
  EXPECT_EQ(f.tri_count, m.triangle_count());
}

TEST(VertexHierarchy, EdgeWithThreeFacesIsKeptAndRefinesBack) {
  MeshData m = test::vd_grid(6, 6);
  const uint32_t base = static_cast<uint32_t>(m.vertex_count());
  m.positions.insert(m.positions.end(), {0.5f, 1, 0.5f});
  m.indices.insert(m.indices.end(), {24, 25, base});  // grid edge 24-25 gets a third face (a fin)
  const VertexTree t = build(m);
  EXPECT_EQ(t.parent[24], kNoNode);
  EXPECT_EQ(t.parent[25], kNoNode);
  VertexFront f;
  front_init(f, t, 1);
  front_refine_all(f, t);
  EXPECT_EQ(canonical(f.tri_indices.data(), f.tri_count), canonical(m.indices.data(), m.triangle_count()));
}

TEST(VertexHierarchy, EmptyMeshGivesAnEmptyForest) {
  MeshData m;
  m.positions = {0, 0, 0, 1, 0, 0};
  VertexTree t;
  ASSERT_TRUE(build_vertex_hierarchy(t, m).ok);
  EXPECT_EQ(t.node_count(), 2u);
  EXPECT_EQ(t.face_count, 0u);
  VertexFront f;
  front_init(f, t, 1);
  EXPECT_EQ(f.active_count, 2u);
  EXPECT_EQ(f.tri_count, 0u);
}

TEST(VertexHierarchy, RealCowRoundTripsThroughRefineAndCoarsen) {
  const std::filesystem::path dir = test::data_dir();
  if (dir.empty() || !std::filesystem::exists(dir / "cow.off"))
    GTEST_SKIP() << "needs cow.off in the data dir";
  MeshData m;
  ASSERT_TRUE(load_mesh(dir / "cow.off", m).ok);
  clean_mesh(m);
  const VertexTree t = build(m);
  VertexFront f;
  front_init(f, t, 1);
  std::string msg;
  ASSERT_TRUE(check_front(f, t, EdgeCheck::oriented, &msg)) << msg;
  front_refine_all(f, t);
  ASSERT_TRUE(check_front(f, t, EdgeCheck::oriented, &msg)) << msg;
  EXPECT_EQ(canonical(f.tri_indices.data(), f.tri_count), canonical(m.indices.data(), m.triangle_count()));
}

}  // namespace
}  // namespace lod
