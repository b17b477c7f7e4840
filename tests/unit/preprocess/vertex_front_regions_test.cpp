// One object's hierarchy cut into parts (HierarchyOptions::parts) and its regions' fronts
// updated separately: each region stays a valid mesh, together they are crack-free, and
// updating them on two threads gives exactly what one thread gives.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <thread>
#include <vector>

#include "preprocess/vertex_hierarchy.h"
#include "runtime/vertex_front.h"
#include "vd_meshes.h"

namespace lod {
namespace {

FrontView view_at(glm::vec3 eye, glm::vec3 target) {
  View v;
  v.eye = eye;
  v.target = target;
  v.width = 640;
  v.height = 480;
  v.near_plane = 0.01f;
  v.far_plane = 100.f;
  const float origin[3] = {0, 0, 0};
  return front_view_of(v, origin, 1.f, 0.f);
}

struct Regions {
  VertexTree tree;
  std::vector<uint8_t> region;
  uint32_t count = 0;
};

Regions build(const MeshData& m, uint32_t parts) {
  Regions r;
  HierarchyOptions o;
  o.parts = parts;
  const Status s = build_vertex_hierarchy(r.tree, m, o);
  EXPECT_TRUE(s.ok) << s.message;
  r.count = vertex_tree_regions(r.region, r.tree, parts);
  return r;
}

std::vector<std::array<uint32_t, 3>> sorted_leaf_triangles(std::span<const uint32_t> idx) {
  std::vector<std::array<uint32_t, 3>> out;
  for (size_t s = 0; s + 2 < idx.size(); s += 3) {
    std::array<uint32_t, 3> t{idx[s], idx[s + 1], idx[s + 2]};
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());  // keeps orientation
    out.push_back(t);
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(VertexFrontRegions, PartsGiveIndependentRegionsWithAFixedSeam) {
  const MeshData m = test::vd_sphere(40, 60);
  const Regions r = build(m, 2);
  ASSERT_EQ(r.count, 2u);
  std::string msg;
  ASSERT_TRUE(validate_vertex_tree(r.tree, &msg)) << msg;
  uint32_t seam = 0, in[2] = {0, 0};
  for (uint32_t l = 0; l < r.tree.leaf_count; ++l) {
    if (r.region[l] == kSharedRegion) {
      ++seam;
      EXPECT_EQ(r.tree.parent[l], kNoNode) << "a seam vertex must never collapse";
    } else {
      ++in[r.region[l]];
    }
  }
  EXPECT_GT(seam, 0u);
  EXPECT_LT(seam, r.tree.leaf_count / 10) << "the seam is a thin band";
  EXPECT_GT(std::min(in[0], in[1]), r.tree.leaf_count / 3) << "the parts are balanced";
  // No parent, child or dependency crosses regions.
  for (uint32_t i = 0; i < r.tree.interior_count(); ++i) {
    const uint32_t x = r.tree.leaf_count + i;
    for (int j = 0; j < 2; ++j) EXPECT_EQ(r.region[r.tree.children[2 * i + j]], r.region[x]);
    for (uint32_t k = r.tree.dep_offsets[i]; k < r.tree.dep_offsets[i + 1]; ++k) {
      const uint8_t d = r.region[r.tree.deps[k]];
      EXPECT_TRUE(d == r.region[x] || d == kSharedRegion) << "node " << x;
    }
  }
}

// Absurd part counts on a tiny mesh: almost every vertex is on a seam, and it all still works.
TEST(VertexFrontRegions, ManyPartsOnATinyMeshStayValid) {
  const MeshData m = test::vd_sphere(6, 8);
  for (uint32_t parts : {64u, 1000u}) {
    Regions r = build(m, parts);
    std::string msg;
    ASSERT_TRUE(validate_vertex_tree(r.tree, &msg)) << msg;
    ASSERT_GE(r.count, 1u);
    std::vector<VertexFront> f(r.count);
    for (uint32_t k = 0; k < r.count; ++k) front_init(f[k], r.tree, 1.f, r.region, uint8_t(k));
    for (auto& fr : f) {
      front_update(fr, r.tree, view_at({0, 0.3f, 2.5f}, {0, 0, 0}), FrontParams{});
      ASSERT_TRUE(check_front(fr, r.tree, EdgeCheck::closed, &msg)) << parts << " parts: " << msg;
    }
    std::vector<const VertexFront*> fronts;
    for (auto& fr : f) fronts.push_back(&fr);
    std::vector<float> pos(3 * size_t(r.tree.node_count()));
    std::vector<uint32_t> idx(3 * size_t(r.tree.face_count)), scratch(r.tree.node_count());
    uint32_t nv = 0;
    const uint32_t nt = fronts_compact_mesh(pos, idx, scratch, fronts, r.tree, {}, &nv);
    EXPECT_TRUE(check_triangles({idx.data(), 3 * size_t(nt)}, nv, EdgeCheck::closed, &msg)) << msg;
  }
}

// Each region's front holds per-node and per-face state for its own nodes and faces (plus the
// fixed seam leaves every region shares), not for the whole tree: together about one front.
TEST(VertexFrontRegions, RegionFrontsHoldStateForTheirOwnRegionOnly) {
  const MeshData m = test::vd_sphere(60, 80);
  const Regions r = build(m, 4);
  ASSERT_EQ(r.count, 4u);
  const auto numbering = std::make_shared<const RegionNumbering>(number_regions(r.tree, r.region, r.count));
  VertexFront whole;
  front_init(whole, r.tree, 1.f);
  std::vector<VertexFront> f(r.count);
  size_t nodes = 0, faces = 0, bytes = 0;
  for (uint32_t k = 0; k < r.count; ++k) {
    front_init(f[k], r.tree, 1.f, numbering, uint8_t(k));
    nodes += f[k].state.size();
    faces += f[k].face_slot.size();
    bytes += front_memory_bytes(f[k]);
    EXPECT_LT(f[k].state.size(), r.tree.node_count() / 2) << "region " << k << " sized for the whole tree";
  }
  EXPECT_EQ(nodes, r.tree.node_count() + (r.count - 1) * size_t(numbering->shared));
  EXPECT_EQ(faces, r.tree.face_count);
  // The calendars' bucket heads are per front (4 x 2 x 4097 entries); the rest splits.
  const size_t fixed = r.count * (f[0].buckets.capacity() * sizeof(f[0].buckets[0]));
  EXPECT_LT(bytes - fixed, 13 * (front_memory_bytes(whole) - fixed / r.count) / 10);
  // The local ids are a numbering: distinct within a region, fixed leaves first, leaves before
  // interior nodes.
  for (uint32_t k = 0; k < r.count; ++k) {
    std::vector<uint8_t> used(numbering->nodes[k], 0);
    for (uint32_t v = 0; v < r.tree.node_count(); ++v) {
      if (!f[k].covers(v)) continue;
      const uint32_t id = numbering->local[v];
      ASSERT_LT(id, used.size());
      EXPECT_EQ(used[id]++, 0) << "node " << v << " shares local id " << id;
      EXPECT_EQ(id < numbering->shared, r.region[v] == kSharedRegion) << "node " << v;
      EXPECT_EQ(id < numbering->leaves[k], r.tree.is_leaf(v)) << "node " << v;
    }
  }
  // And they still walk as one crack-free mesh.
  std::string msg;
  for (int i = 0; i < 40; ++i) {
    const float a = 0.1f * i;
    const FrontView v = view_at({2.0f * std::sin(a), 0.3f, 2.0f * std::cos(a)}, {0, 0, 0});
    for (auto& fr : f) {
      front_update(fr, r.tree, v, FrontParams{});
      ASSERT_TRUE(check_front(fr, r.tree, EdgeCheck::closed, &msg)) << "frame " << i << ": " << msg;
    }
  }
}

TEST(VertexFrontRegions, OnePartHierarchyIsOneRegionPerComponent) {
  const MeshData two = test::vd_concat(test::vd_sphere(12, 16), test::vd_sphere(12, 16, 1, 3, 0));
  const Regions r = build(two, 1);
  EXPECT_EQ(r.count, 1u) << "max_regions 1 puts everything together";
  std::vector<uint8_t> region;
  EXPECT_EQ(vertex_tree_regions(region, r.tree, 8), 2u) << "two spheres are two independent components";
}

TEST(VertexFrontRegions, RegionFrontsTogetherAreTheWholeMeshCrackFree) {
  const MeshData m = test::vd_sphere(40, 60);
  const Regions r = build(m, 2);
  ASSERT_EQ(r.count, 2u);
  VertexFront f[2];
  for (uint8_t k = 0; k < 2; ++k) front_init(f[k], r.tree, 1.f, r.region, k);
  const VertexFront* fronts[2] = {&f[0], &f[1]};
  std::vector<float> pos(3 * size_t(r.tree.node_count()));
  std::vector<uint32_t> idx(3 * size_t(r.tree.face_count)), scratch(r.tree.node_count());
  std::string msg;
  auto check_union = [&](const char* when) {
    uint32_t nv = 0;
    const uint32_t nt = fronts_compact_mesh(pos, idx, scratch, fronts, r.tree, {}, &nv);
    ASSERT_TRUE(check_triangles({idx.data(), 3 * size_t(nt)}, nv, EdgeCheck::closed, &msg)) << when << ": " << msg;
  };
  check_union("base mesh");
  for (int i = 0; i < 120; ++i) {
    const float a = 0.05f * i;
    const FrontView v = view_at({2.2f * std::sin(a), 0.4f, 2.2f * std::cos(a)}, {0, 0, 0});
    for (auto& fr : f) {
      front_update(fr, r.tree, v, FrontParams{});
      ASSERT_TRUE(check_front(fr, r.tree, EdgeCheck::closed, &msg)) << "frame " << i << ": " << msg;
    }
    check_union("walk");
  }
  // Refining every region reproduces the input mesh exactly.
  for (auto& fr : f) front_refine_all(fr, r.tree);
  std::vector<uint32_t> all;
  for (auto& fr : f)
    for (uint32_t x : fr.triangles()) all.push_back(x);
  EXPECT_EQ(sorted_leaf_triangles(all), sorted_leaf_triangles(r.tree.face_leaves));
}

TEST(VertexFrontRegions, TwoThreadsGiveExactlyWhatOneGives) {
  const MeshData m = test::vd_sphere(50, 70);
  const Regions r = build(m, 2);
  ASSERT_EQ(r.count, 2u);
  VertexFront serial[2], parallel[2];
  for (uint8_t k = 0; k < 2; ++k) {
    front_init(serial[k], r.tree, 1.f, r.region, k);
    front_init(parallel[k], r.tree, 1.f, r.region, k);
  }
  FrontParams p;
  p.max_triangles = 3000;
  for (int i = 0; i < 60; ++i) {
    const float a = 0.04f * i;
    const FrontView v = view_at({1.8f * std::sin(a), 0.3f, 1.8f * std::cos(a)}, {0.1f, 0, 0});
    for (auto& fr : serial) front_update(fr, r.tree, v, p);
    std::thread other([&] { front_update(parallel[1], r.tree, v, p); });
    front_update(parallel[0], r.tree, v, p);
    other.join();
    for (int k = 0; k < 2; ++k) {
      ASSERT_EQ(serial[k].tri_count, parallel[k].tri_count) << "frame " << i;
      ASSERT_TRUE(std::equal(serial[k].triangles().begin(), serial[k].triangles().end(),
                             parallel[k].triangles().begin()))
          << "frame " << i << " region " << k;
    }
  }
}

TEST(VertexFrontRegions, SharedThresholdFeedbackMovesEveryRegionAlike) {
  const MeshData m = test::vd_sphere(50, 70);
  const Regions r = build(m, 2);
  VertexFront f[2];
  for (uint8_t k = 0; k < 2; ++k) front_init(f[k], r.tree, 1.f, r.region, k);
  FrontParams p;
  const uint64_t target = 2000;
  const FrontView v = view_at({0, 0.2f, 2.0f}, {0, 0, 0});
  uint64_t total = 0;
  for (int i = 0; i < 40; ++i) {
    total = 0;
    for (auto& fr : f) total += front_update(fr, r.tree, v, p).active_tris;
    const float next = front_next_threshold(f[0].threshold, total, target, p);
    for (auto& fr : f) front_set_threshold(fr, next);
  }
  EXPECT_EQ(f[0].threshold, f[1].threshold);
  EXPECT_GT(total, target * 7 / 10);
  EXPECT_LT(total, target * 12 / 10);
}

}  // namespace
}  // namespace lod
