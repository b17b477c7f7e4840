#include "preprocess/cluster_simplifier.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>

#include "preprocess/mesh_clean.h"
#include "preprocess/mesh_io.h"
#include "test_support.h"

namespace lod {
namespace {

struct Soup {
  std::vector<float> positions;
  std::vector<uint32_t> indices;
  size_t vertex_count() const { return positions.size() / 3; }
  size_t triangle_count() const { return indices.size() / 3; }
};

// Closed UV sphere built directly (big ones are too slow to go through OFF text).
Soup uv_sphere(int rings, int segments, float radius = 1) {
  Soup s;
  s.positions.insert(s.positions.end(), {0, radius, 0, 0, -radius, 0});
  for (int r = 1; r < rings; ++r) {
    const double phi = M_PI * r / rings;
    for (int k = 0; k < segments; ++k) {
      const double th = 2 * M_PI * k / segments;
      s.positions.insert(s.positions.end(), {float(radius * std::sin(phi) * std::cos(th)), float(radius * std::cos(phi)),
                                             float(radius * std::sin(phi) * std::sin(th))});
    }
  }
  auto ring = [&](int r, int k) { return uint32_t(2 + (r - 1) * segments + (k % segments)); };
  for (int k = 0; k < segments; ++k) s.indices.insert(s.indices.end(), {0, ring(1, k + 1), ring(1, k)});
  for (int r = 1; r < rings - 1; ++r)
    for (int k = 0; k < segments; ++k) {
      s.indices.insert(s.indices.end(), {ring(r, k), ring(r, k + 1), ring(r + 1, k + 1)});
      s.indices.insert(s.indices.end(), {ring(r, k), ring(r + 1, k + 1), ring(r + 1, k)});
    }
  for (int k = 0; k < segments; ++k) s.indices.insert(s.indices.end(), {1, ring(rings - 1, k), ring(rings - 1, k + 1)});
  return s;
}

struct Out {
  std::vector<uint32_t> indices;
  std::vector<float> positions;
  ClusterResult result;
};

Out run(const Soup& s, size_t target, const ClusterOptions& o = {}) {
  Out out;
  out.indices.resize(s.indices.size());
  out.positions.resize(s.positions.size());
  const size_t n = cluster_simplify(out.indices.data(), out.positions.data(), s.positions.data(), s.vertex_count(),
                                    s.indices.data(), s.indices.size(), target, o, &out.result);
  EXPECT_EQ(n, out.result.triangles);
  out.indices.resize(3 * n);
  out.positions.resize(3 * out.result.vertices);
  return out;
}

void expect_valid_unique_faces(const Out& out) {
  std::set<std::tuple<uint32_t, uint32_t, uint32_t>> seen;
  for (size_t t = 0; t < out.indices.size() / 3; ++t) {
    uint32_t a = out.indices[3 * t], b = out.indices[3 * t + 1], c = out.indices[3 * t + 2];
    ASSERT_LT(std::max({a, b, c}), out.result.vertices);
    ASSERT_TRUE(a != b && b != c && a != c) << "degenerate face " << t;
    uint32_t k[3] = {a, b, c};
    std::sort(k, k + 3);  // either orientation counts as the same face
    EXPECT_TRUE(seen.insert({k[0], k[1], k[2]}).second) << "duplicate face " << t;
  }
  for (float x : out.positions) ASSERT_TRUE(std::isfinite(x));
}

TEST(ClusterSimplifier, LandsWithinFivePercentOfTargets) {
  const Soup s = uv_sphere(150, 200);  // 59,600 faces
  for (double ratio : {0.5, 0.25, 0.1, 0.03, 0.01, 0.004}) {
    const size_t target = size_t(ratio * double(s.triangle_count()));
    const Out out = run(s, target);
    EXPECT_NEAR(double(out.result.triangles), double(target), 0.05 * double(target)) << "ratio " << ratio;
    expect_valid_unique_faces(out);
  }
}

TEST(ClusterSimplifier, ReachesPointEighteenPercentOfAMillionFaces) {
  const Soup s = uv_sphere(708, 708);  // 1,000,000 faces
  ASSERT_GE(s.triangle_count(), 999000u);
  const size_t target = size_t(0.0018 * double(s.triangle_count()));
  const Out out = run(s, target);
  EXPECT_NEAR(double(out.result.triangles), double(target), 0.05 * double(target));
  expect_valid_unique_faces(out);
  // Cells' vertices stay on the unit sphere within about a cell.
  for (size_t v = 0; v < out.result.vertices; ++v) {
    const float* p = &out.positions[3 * v];
    EXPECT_NEAR(std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]), 1.0, out.result.cell_size);
  }
}

TEST(ClusterSimplifier, ErrorGrowsAlongTheChainAndAttributesFollow) {
  const Soup s = uv_sphere(80, 100);
  std::vector<float> normals = s.positions;
  ClusterOptions o;
  o.attributes = normals.data();
  o.attribute_count = 3;
  const size_t targets[] = {8000, 2000, 500, 100};
  std::vector<ChainLevelOut> levels(4);
  EXPECT_EQ(cluster_simplify_chain(levels.data(), s.positions.data(), s.vertex_count(), s.indices.data(),
                                   s.indices.size(), targets, 4, o),
            4u);
  for (size_t l = 0; l < 4; ++l) {
    EXPECT_NEAR(double(levels[l].triangle_count()), double(targets[l]), 0.05 * double(targets[l]));
    EXPECT_TRUE(levels[l].reached);
    ASSERT_EQ(levels[l].attributes.size(), levels[l].positions.size());
    ASSERT_EQ(levels[l].source_vertex.size(), levels[l].positions.size() / 3);
    for (size_t v = 0; v < levels[l].positions.size() / 3; ++v) {
      const float* p = &levels[l].positions[3 * v];
      const float* n = &levels[l].attributes[3 * v];
      EXPECT_GT(p[0] * n[0] + p[1] * n[1] + p[2] * n[2], 0.5f);  // averaged normal still points out
    }
    if (l) {
      EXPECT_GE(levels[l].error, levels[l - 1].error);
    }
  }
}

TEST(ClusterSimplifier, SameInputGivesIdenticalOutput) {
  const Soup s = uv_sphere(60, 80);
  const Out a = run(s, 900), b = run(s, 900);
  EXPECT_EQ(a.indices, b.indices);
  EXPECT_EQ(a.positions, b.positions);
}

TEST(ClusterSimplifier, TargetAboveInputReturnsTheValidFaces) {
  Soup s = uv_sphere(10, 12);
  const size_t faces = s.triangle_count();
  s.indices.insert(s.indices.end(), {0, 0, 1, 0, 1, 12345});  // degenerate and out of range
  const Out out = run(s, faces * 2);
  EXPECT_EQ(out.result.triangles, faces);
  expect_valid_unique_faces(out);
}

TEST(ClusterSimplifier, DegenerateAndEmptyInputsNeverCrash) {
  std::vector<uint32_t> di(3);
  std::vector<float> dp(3);
  ClusterResult r;
  EXPECT_EQ(cluster_simplify(di.data(), dp.data(), nullptr, 0, nullptr, 0, 10, {}, &r), 0u);
  // All vertices on one spot, a NaN vertex, a flat line of faces.
  Soup s;
  s.positions = {1, 1, 1, 1, 1, 1, 1, 1, 1, std::nanf(""), 0, 0, 0, 0, 0, 1, 0, 0, 2, 0, 0};
  s.indices = {0, 1, 2, 3, 4, 5, 4, 5, 6, 0, 4, 5};
  const Out out = run(s, 1);
  expect_valid_unique_faces(out);
  EXPECT_LE(out.result.triangles, 3u);
  const Out none = run(uv_sphere(20, 20), 0);
  EXPECT_EQ(none.result.triangles, 0u);
}

TEST(ClusterSimplifier, TinyMeshKeepsFacesRatherThanVanishing) {
  // A cube offers only "all 12 faces" or "none" to a grid: asked for 6, it keeps them all.
  Soup cube;
  cube.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  cube.indices = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                  1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
  const Out out = run(cube, 6);
  EXPECT_EQ(out.result.triangles, 12u);
  expect_valid_unique_faces(out);
}

// A closed tube along x (faces outwards), far thinner than the cells a coarse target needs.
Soup thin_tube(int rings, int segments, float radius) {
  Soup s;
  for (int r = 0; r <= rings; ++r)
    for (int k = 0; k < segments; ++k) {
      const double th = 2 * M_PI * k / segments;
      s.positions.insert(s.positions.end(),
                         {float(r) / float(rings), float(radius * std::cos(th)), float(radius * std::sin(th))});
    }
  const uint32_t first_cap = uint32_t(s.vertex_count());
  s.positions.insert(s.positions.end(), {0, 0, 0, 1, 0, 0});
  auto id = [&](int r, int k) { return uint32_t(r * segments + (k % segments)); };
  for (int r = 0; r < rings; ++r)
    for (int k = 0; k < segments; ++k) {
      s.indices.insert(s.indices.end(), {id(r, k), id(r + 1, k + 1), id(r + 1, k)});
      s.indices.insert(s.indices.end(), {id(r, k), id(r, k + 1), id(r + 1, k + 1)});
    }
  for (int k = 0; k < segments; ++k) {  // outward-facing caps
    s.indices.insert(s.indices.end(), {first_cap, id(0, k + 1), id(0, k)});
    s.indices.insert(s.indices.end(), {first_cap + 1, id(rings, k), id(rings, k + 1)});
  }
  return s;
}

TEST(ClusterSimplifier, TubeThinnerThanACellKeepsItsLength) {
  // Both sides of the tube share every cell; folded into one vertex per cell, all its faces
  // would degenerate and the tube would vanish. Split by facing, it survives as a ribbon.
  const Soup tube = thin_tube(200, 8, 0.004f);
  const Out out = run(tube, tube.triangle_count() / 10);
  expect_valid_unique_faces(out);
  ASSERT_GT(out.result.triangles, 0u);
  EXPECT_GT(out.result.cell_size, 0.008f);  // the grid is coarser than the tube
  float lo = 1e30f, hi = -1e30f;
  for (size_t v = 0; v < out.positions.size() / 3; ++v)
    lo = std::min(lo, out.positions[3 * v]), hi = std::max(hi, out.positions[3 * v]);
  EXPECT_GT(hi - lo, 0.9f);
  // The faces cover the tube's length, not just its ends.
  std::set<int> covered;
  for (uint32_t i : out.indices) covered.insert(int(out.positions[3 * size_t(i)] * 10));
  EXPECT_GE(covered.size(), 9u);
}

TEST(ClusterSimplifier, ThinSlabKeepsItsThickness) {
  // A flat closed slab, 0.6 wide and 0.02 thick (a four-sided tube squashed along z): one
  // vertex per cell would fold top and bottom into one sheet at mid-thickness; split by
  // facing, the upward faces stay on top and the downward ones below.
  Soup slab = thin_tube(40, 4, 0.01f);
  for (size_t v = 0; v < slab.vertex_count(); ++v) slab.positions[3 * v + 1] *= 30;
  const Out out = run(slab, slab.triangle_count() / 8);
  expect_valid_unique_faces(out);
  EXPECT_GT(out.result.cell_size, 0.02f);
  double up = 0, down = 0, up_z = 0, down_z = 0;
  for (size_t t = 0; t < out.indices.size() / 3; ++t) {
    const float* a = &out.positions[3 * size_t(out.indices[3 * t])];
    const float* b = &out.positions[3 * size_t(out.indices[3 * t + 1])];
    const float* c = &out.positions[3 * size_t(out.indices[3 * t + 2])];
    const double nz = double(b[0] - a[0]) * (c[1] - a[1]) - double(b[1] - a[1]) * (c[0] - a[0]);
    const double z = (double(a[2]) + b[2] + c[2]) / 3, area = 0.5 * std::fabs(nz);
    if (nz > 0) up += area, up_z += area * z;
    else down += area, down_z += area * z;
  }
  ASSERT_GT(up, 0.3);  // each side is about 1 x 0.6
  ASSERT_GT(down, 0.3);
  EXPECT_GT(up_z / up, 0.004);  // 0 when folded
  EXPECT_LT(down_z / down, -0.004);
}

TEST(ClusterSimplifierRealMesh, DragonToPointEighteenPercent) {
  LOD_REQUIRE_SHARED_MESH(path, "stanford-dragon.ply");
  MeshData mesh;
  ASSERT_TRUE(load_mesh(path, mesh).ok);
  clean_mesh(mesh);
  const Soup s{mesh.positions, mesh.indices};
  const size_t target = size_t(0.0018 * double(s.triangle_count()));
  const Out out = run(s, target);
  EXPECT_NEAR(double(out.result.triangles), double(target), 0.05 * double(target));
  expect_valid_unique_faces(out);
}

}  // namespace
}  // namespace lod
