// Model HLOD build (Zhou and Tian 3.1): octree limits, the partition of the original triangles, layer
// sizes, monotonic errors, crack-free random cuts, and identical output at any thread count.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <filesystem>
#include <functional>
#include <random>
#include <thread>
#include <vector>

#include "preprocess/hlod_build.h"
#include "preprocess/mesh_clean.h"
#include "preprocess/mesh_io.h"
#include "runtime/hlod_asset.h"
#include "runtime/hlod_cut_check.h"
#include "test_support.h"
#include "vd_meshes.h"

namespace lod {
namespace {

const ParallelFor kSequential = [](size_t n, const std::function<void(size_t)>& body) {
  for (size_t i = 0; i < n; ++i) body(i);
};
// Backwards, so that a result depending on the order children finish in would show.
const ParallelFor kBackwards = [](size_t n, const std::function<void(size_t)>& body) {
  for (size_t i = n; i-- > 0;) body(i);
};
// Two threads: odd and even children at once (nested at every level).
const ParallelFor kTwoThreads = [](size_t n, const std::function<void(size_t)>& body) {
  std::thread other([&] {
    for (size_t i = 1; i < n; i += 2) body(i);
  });
  for (size_t i = 0; i < n; i += 2) body(i);
  other.join();
};

HlodModel build(const MeshData& mesh, uint32_t min_verts, const ParallelFor& parallel_for = {},
                HlodBuildReport* report = nullptr) {
  HlodBuildOptions options;
  options.min_verts = min_verts;
  options.parallel_for = parallel_for;
  HlodModel model;
  const Status st = build_hlod(model, mesh, options, report);
  EXPECT_TRUE(st) << st.message;
  return model;
}

MeshData sphere_mesh() { return test::vd_sphere(60, 80); }  // closed, 9,480 triangles
MeshData grid_mesh() { return test::vd_grid(60, 50); }       // open: a border all round
// Two components, one open and one closed, side by side.
MeshData mixed_mesh() { return test::vd_concat(test::vd_sphere(40, 50, 0.4f, 0.5f, 0.3f, 0.5f), test::vd_grid(40, 40)); }

std::vector<const HlodPayload*> pointers(const HlodModel& m) {
  std::vector<const HlodPayload*> p;
  for (const HlodPayload& x : m.payloads) p.push_back(&x);
  return p;
}

using TriangleKey = std::array<uint32_t, 9>;  // the three corners' float bits, corners sorted

TriangleKey key_of(const float* a, const float* b, const float* c) {
  std::array<std::array<uint32_t, 3>, 3> corners;
  const float* v[3] = {a, b, c};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) corners[i][j] = std::bit_cast<uint32_t>(v[i][j]);
  std::sort(corners.begin(), corners.end());
  TriangleKey k;
  for (int i = 0; i < 9; ++i) k[i] = corners[i / 3][i % 3];
  return k;
}

void add_keys(const HlodPayload& p, const LodLevel& r, std::vector<TriangleKey>& out) {
  const float* pos = p.positions.data() + 3 * size_t(r.first_vertex);
  for (uint32_t i = 0; i < r.index_count; i += 3) {
    const uint32_t* f = &p.indices[r.first_index + i];
    out.push_back(key_of(pos + 3 * f[0], pos + 3 * f[1], pos + 3 * f[2]));
  }
}

void expect_leaves_within(const HlodModel& m, uint32_t min_verts) {
  for (size_t i = 0; i < m.tree.nodes.size(); ++i) {
    const HlodNode& n = m.tree.nodes[i];
    if (n.leaf()) {
      EXPECT_LE(n.layers[0].vertices, min_verts) << "leaf " << i;
    }
  }
}

void expect_partition(const MeshData& mesh, const HlodModel& m) {
  std::vector<TriangleKey> original, drawn;
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const uint32_t* f = &mesh.indices[3 * t];
    original.push_back(key_of(&mesh.positions[3 * size_t(f[0])], &mesh.positions[3 * size_t(f[1])],
                              &mesh.positions[3 * size_t(f[2])]));
  }
  for (size_t i = 0; i < m.tree.nodes.size(); ++i) {
    if (m.tree.nodes[i].leaf()) add_keys(m.payloads[i], m.payloads[i].layers[0], drawn);
    add_keys(m.payloads[i], m.payloads[i].boundary, drawn);
  }
  std::sort(original.begin(), original.end());
  std::sort(drawn.begin(), drawn.end());
  EXPECT_EQ(drawn.size(), original.size());
  EXPECT_TRUE(drawn == original) << "every original triangle is in exactly one leaf or one patch";
}

void expect_monotonic_errors(const HlodModel& m) {
  for (size_t i = 0; i < m.tree.nodes.size(); ++i) {
    const HlodNode& n = m.tree.nodes[i];
    ASSERT_GE(n.layer_count, 1);
    if (n.leaf()) {
      EXPECT_EQ(n.layers[0].error, 0.0f) << "a leaf's finest layer is the original";
    }
    for (uint32_t k = 1; k < n.layer_count; ++k) EXPECT_GE(n.layers[k].error, n.layers[k - 1].error) << "node " << i;
    if (n.parent >= 0) {
      const HlodNode& p = m.tree.nodes[size_t(n.parent)];
      EXPECT_GE(p.layers[0].error, n.layers[n.layer_count - 1].error) << "node " << i << " vs its parent";
    }
  }
}

// Fewer triangles in every layer than in the one before; about half over the whole tree.
void expect_layers_halve(const HlodModel& m) {
  uint64_t sum[kHlodMaxLayers] = {0, 0, 0}, prev_sum[kHlodMaxLayers] = {0, 0, 0};
  for (const HlodNode& n : m.tree.nodes)
    for (uint32_t k = 1; k < n.layer_count; ++k) {
      EXPECT_LT(n.layers[k].triangles, n.layers[k - 1].triangles);
      sum[k] += n.layers[k].triangles;
      prev_sum[k] += n.layers[k - 1].triangles;
    }
  for (uint32_t k = 1; k < kHlodMaxLayers; ++k) {
    ASSERT_GT(prev_sum[k], 0u);
    const double ratio = double(sum[k]) / double(prev_sum[k]);
    EXPECT_GT(ratio, 0.4) << "layer " << k;
    EXPECT_LT(ratio, 0.7) << "layer " << k;
  }
}

// Each node of the cut drawn at a random layer or (inner nodes, with probability `open`) opened.
std::vector<int8_t> random_cut(const HlodTree& tree, std::mt19937& rng, double open) {
  std::vector<int8_t> cut(tree.nodes.size(), kHlodCutOutside);
  std::vector<uint32_t> stack{0};
  std::uniform_real_distribution<double> u(0, 1);
  while (!stack.empty()) {
    const uint32_t i = stack.back();
    stack.pop_back();
    const HlodNode& n = tree.nodes[i];
    if (!n.leaf() && u(rng) < open) {
      cut[i] = kHlodCutOpened;
      for (uint32_t c = 0; c < n.child_count; ++c) stack.push_back(n.first_child + c);
    } else {
      cut[i] = int8_t(std::uniform_int_distribution<int>(0, n.layer_count - 1)(rng));
    }
  }
  return cut;
}

void expect_random_cuts_crack_free(const HlodModel& m, int cuts) {
  const auto payloads = pointers(m);
  const HlodCutReference ref = hlod_cut_reference(m.tree, payloads);
  std::mt19937 rng(7);
  for (int k = 0; k < cuts; ++k) {
    const std::vector<int8_t> cut = random_cut(m.tree, rng, k % 3 == 0 ? 0.9 : 0.6);
    std::string why;
    ASSERT_TRUE(validate_hlod_cut(m.tree, cut, &why)) << why;
    EXPECT_EQ(count_cut_gaps(m.tree, payloads, cut, ref), 0u) << "cut " << k;
  }
}

void expect_all_properties(const MeshData& mesh, uint32_t min_verts, int cuts) {
  HlodBuildReport report;
  const HlodModel m = build(mesh, min_verts, kSequential, &report);
  ASSERT_GT(report.nodes, 8u) << "the mesh must split for the test to mean anything";
  EXPECT_EQ(report.oversized_leaves, 0u);
  expect_leaves_within(m, min_verts);
  expect_partition(mesh, m);
  expect_monotonic_errors(m);
  expect_layers_halve(m);
  expect_random_cuts_crack_free(m, cuts);
}

TEST(HlodBuild, ClosedSphereHasEveryProperty) { expect_all_properties(sphere_mesh(), 300, 200); }
TEST(HlodBuild, OpenGridHasEveryProperty) { expect_all_properties(grid_mesh(), 250, 200); }
TEST(HlodBuild, TwoComponentsHaveEveryProperty) { expect_all_properties(mixed_mesh(), 200, 200); }

TEST(HlodBuild, StanfordBunnyHasEveryProperty) {
  LOD_REQUIRE_SHARED_MESH(file, "stanford-bunny.obj");
  MeshData mesh;
  ASSERT_TRUE(load_mesh(file, mesh));
  clean_mesh(mesh);
  expect_all_properties(mesh, 1000, 30);
}

// Stanford's decimated buddha: 2,151 non-manifold edges, fins, 1,423 open edges. Its
// non-manifold vertices are locked (moving them opened 80-150 edges per cut), so its layers
// shrink less than half. Known limit, left visible here: QEM's link condition lets a valence-3
// vertex over a triangle that is itself a face (a tetrahedron glued into the surface) collapse,
// and one of the doubled faces goes, opening an edge. Tips there when a node's simplification
// starts are locked (3-11 open edges per cut before); tips the simplification itself makes still
// open a few (0-3 per cut), never more than 1 in 1,000 of the drawn edges.
TEST(HlodBuild, NonManifoldBuddhaKeepsItsPropertiesAndAlmostAllEdges) {
  LOD_REQUIRE_SHARED_MESH(file, "happy-buddha-res3.ply");
  MeshData mesh;
  ASSERT_TRUE(load_mesh(file, mesh));
  clean_mesh(mesh);
  const HlodModel m = build(mesh, 500, kSequential);
  expect_leaves_within(m, 500);
  expect_partition(mesh, m);
  expect_monotonic_errors(m);
  const auto payloads = pointers(m);
  const HlodCutReference ref = hlod_cut_reference(m.tree, payloads);
  std::mt19937 rng(7);
  for (int k = 0; k < 20; ++k) {
    const std::vector<int8_t> cut = random_cut(m.tree, rng, 0.7);
    size_t edges = 0;
    for (size_t i = 0; i < cut.size(); ++i)
      if (cut[i] >= 0) edges += 3 * m.tree.nodes[i].layers[cut[i]].triangles / 2;
    EXPECT_LT(count_cut_gaps(m.tree, payloads, cut, ref), edges / 1000 + 1) << "cut " << k;
  }
}

TEST(HlodBuild, TreeIsBreadthFirstWithCellsHalving) {
  const HlodModel m = build(sphere_mesh(), 300);
  const HlodTree& t = m.tree;
  ASSERT_FALSE(t.nodes.empty());
  EXPECT_EQ(t.nodes[0].parent, -1);
  uint32_t next = 1;
  for (size_t i = 0; i < t.nodes.size(); ++i) {
    const HlodNode& n = t.nodes[i];
    EXPECT_EQ(std::popcount(unsigned(n.child_mask)), int(n.child_count));
    if (n.leaf()) continue;
    EXPECT_EQ(n.first_child, next) << "children follow in breadth-first order";
    next += n.child_count;
    for (uint32_t c = 0; c < n.child_count; ++c) {
      const HlodNode& k = t.nodes[n.first_child + c];
      EXPECT_EQ(k.parent, int32_t(i));
      EXPECT_EQ(k.depth, n.depth + 1);
      EXPECT_EQ(k.box_half, n.box_half / 2);
    }
    EXPECT_GT(n.boundary_triangles, 0u) << "a surface cut into octants crosses them";
  }
  EXPECT_EQ(next, t.nodes.size());
}

TEST(HlodBuild, CoarseLayersHaveMeasuredNonzeroErrors) {
  const HlodModel m = build(sphere_mesh(), 300);
  size_t measured = 0;
  for (const HlodNode& n : m.tree.nodes)
    for (uint32_t k = 1; k < n.layer_count; ++k) measured += n.layers[k].error > 0;
  EXPECT_GT(measured, m.tree.nodes.size()) << "simplified layers of a curved surface are off it";
  // A halved unit sphere is off by far less than its radius.
  EXPECT_LT(m.tree.nodes[0].layers[m.tree.nodes[0].layer_count - 1].error, 0.2f);
}

TEST(HlodBuild, BoundsHoldEveryDrawnVertexOfTheSubtree) {
  const HlodModel m = build(mixed_mesh(), 200);
  for (size_t i = 0; i < m.tree.nodes.size(); ++i) {
    for (int64_t a = int64_t(i); a >= 0; a = m.tree.nodes[size_t(a)].parent) {
      const Sphere& s = m.tree.nodes[size_t(a)].bounds;
      const auto& pos = m.payloads[i].positions;
      for (size_t v = 0; v < pos.size(); v += 3) {
        const double d = std::hypot(pos[v] - s.center[0], pos[v + 1] - s.center[1], pos[v + 2] - s.center[2]);
        ASSERT_LE(d, s.radius * (1 + 1e-5)) << "node " << i << " vertex outside ancestor " << a;
      }
    }
  }
}

TEST(HlodBuild, IdenticalBytesWhateverRunsTheSubtrees) {
  const MeshData mesh = mixed_mesh();
  const HlodModel serial = build(mesh, 200, kSequential);
  const HlodModel none = build(mesh, 200);
  const HlodModel backwards = build(mesh, 200, kBackwards);
  const HlodModel two = build(mesh, 200, kTwoThreads);
  const std::vector<uint8_t> bytes = encode_hlod_asset(serial.tree, serial.payloads);
  EXPECT_EQ(encode_hlod_asset(none.tree, none.payloads), bytes);
  EXPECT_EQ(encode_hlod_asset(backwards.tree, backwards.payloads), bytes);
  EXPECT_EQ(encode_hlod_asset(two.tree, two.payloads), bytes) << "1 vs 2 threads";
}

TEST(HlodBuild, BuiltModelSurvivesItsFile) {
  const HlodModel m = build(sphere_mesh(), 300);
  HlodTree tree;
  std::vector<HlodPayload> payloads;
  const std::vector<uint8_t> bytes = encode_hlod_asset(m.tree, m.payloads);
  const Status st = decode_hlod_asset(bytes, "sphere.hlod", tree, payloads);
  ASSERT_TRUE(st) << st.message;
  ASSERT_EQ(tree.nodes.size(), m.tree.nodes.size());
  for (size_t i = 0; i < tree.nodes.size(); ++i) {
    EXPECT_EQ(tree.nodes[i].resident_bytes, m.tree.nodes[i].resident_bytes);
    EXPECT_EQ(payloads[i].indices, m.payloads[i].indices);
  }
}

TEST(HlodBuild, ProgressRisesToOne) {
  HlodBuildOptions options;
  options.min_verts = 300;
  std::vector<float> seen;
  options.progress = [&](float f) { seen.push_back(f); };
  HlodModel m;
  ASSERT_TRUE(build_hlod(m, sphere_mesh(), options));
  ASSERT_EQ(seen.size(), 2 * m.tree.nodes.size()) << "once per node built, once per node measured";
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_FLOAT_EQ(seen.back(), 1.0f);
}

TEST(HlodBuild, SmallMeshIsOneLeaf) {
  const HlodModel m = build(test::vd_sphere(20, 24), 1000);
  ASSERT_EQ(m.tree.nodes.size(), 1u);
  EXPECT_TRUE(m.tree.nodes[0].leaf());
  EXPECT_EQ(m.tree.nodes[0].layer_count, 3);
  EXPECT_EQ(m.payloads[0].boundary.index_count, 0u);
}

TEST(HlodBuild, RefusesBadInputNamingIt) {
  HlodModel m;
  MeshData mesh = test::vd_sphere(8, 10);
  mesh.source = "bad.obj";
  mesh.indices[7] = 9999;
  Status st = build_hlod(m, mesh, HlodBuildOptions{});
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("bad.obj: face 2 references vertex 9999"), std::string::npos) << st.message;
  mesh = test::vd_sphere(8, 10);
  mesh.source = "nan.obj";
  mesh.positions[4] = NAN;
  st = build_hlod(m, mesh, HlodBuildOptions{});
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("nan.obj: vertex 1"), std::string::npos) << st.message;
  MeshData empty;
  EXPECT_FALSE(build_hlod(m, empty, HlodBuildOptions{}));
  EXPECT_TRUE(m.tree.nodes.empty()) << "untouched on failure";
}

// The checker itself must see a gap: drop one opened node's patch and edges open.
TEST(HlodCutCheck, SeesTheGapOfAMissingPatch) {
  HlodModel m = build(sphere_mesh(), 300);
  std::vector<int8_t> cut(m.tree.nodes.size(), kHlodCutOutside);
  cut[0] = kHlodCutOpened;
  for (uint32_t c = 0; c < m.tree.nodes[0].child_count; ++c) cut[m.tree.nodes[0].first_child + c] = 0;
  auto payloads = pointers(m);
  const HlodCutReference ref = hlod_cut_reference(m.tree, payloads);
  EXPECT_EQ(count_cut_gaps(m.tree, payloads, cut, ref), 0u);
  HlodPayload no_patch = m.payloads[0];
  no_patch.boundary.index_count = 0;
  payloads[0] = &no_patch;
  EXPECT_GT(count_cut_gaps(m.tree, payloads, cut, ref), 0u);
  payloads[0] = &m.payloads[0];
  payloads[m.tree.nodes[0].first_child] = nullptr;  // a drawn node that is not there: a hole
  EXPECT_GT(count_cut_gaps(m.tree, payloads, cut, ref), 0u);
}

// Unlocked patch vertices would move in the children's coarse layers: the check must see it.
TEST(HlodCutCheck, SeesAMovedBoundaryVertex) {
  HlodModel m = build(sphere_mesh(), 300);
  const HlodNode& root = m.tree.nodes[0];
  std::vector<int8_t> cut(m.tree.nodes.size(), kHlodCutOutside);
  cut[0] = kHlodCutOpened;
  for (uint32_t c = 0; c < root.child_count; ++c) cut[root.first_child + c] = 0;
  auto payloads = pointers(m);
  const HlodCutReference ref = hlod_cut_reference(m.tree, payloads);
  HlodPayload moved = m.payloads[0];
  moved.positions[3 * size_t(moved.boundary.first_vertex)] += 1e-3f;
  payloads[0] = &moved;
  EXPECT_GT(count_cut_gaps(m.tree, payloads, cut, ref), 0u);
}

TEST(HlodCutCheck, RefusesWhatIsNotACut) {
  const HlodModel m = build(sphere_mesh(), 300);
  std::string why;
  std::vector<int8_t> cut(m.tree.nodes.size(), kHlodCutOutside);
  EXPECT_FALSE(validate_hlod_cut(m.tree, cut, &why)) << "the root must be in the cut";
  cut[0] = 0;
  EXPECT_TRUE(validate_hlod_cut(m.tree, cut, &why)) << why;
  cut[0] = 3;
  EXPECT_FALSE(validate_hlod_cut(m.tree, cut, &why));
  cut[0] = kHlodCutOpened;
  EXPECT_FALSE(validate_hlod_cut(m.tree, cut, &why)) << "an opened node's children must be in the cut";
  EXPECT_NE(why.find("node 1"), std::string::npos) << why;
}

}  // namespace
}  // namespace lod
