#include "runtime/vertex_normals.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace lod {
namespace {

float length3(const float* n) { return std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]); }

TEST(VertexNormals, FlatGridPointsAlongItsFaceNormal) {
  // 3 x 3 vertices in the z = 0 plane, counter-clockwise seen from +z.
  std::vector<float> p;
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 3; ++x) p.insert(p.end(), {float(x), float(y), 0.f});
  std::vector<uint32_t> idx;
  for (uint32_t y = 0; y < 2; ++y)
    for (uint32_t x = 0; x < 2; ++x) {
      const uint32_t a = 3 * y + x;
      idx.insert(idx.end(), {a, a + 1, a + 4, a, a + 4, a + 3});
    }
  std::vector<float> n(p.size(), 7.f);
  EXPECT_EQ(area_weighted_normals(n, p, idx), 9u);
  for (size_t v = 0; v < 9; ++v) {
    EXPECT_FLOAT_EQ(n[3 * v + 2], 1.f) << v;
    EXPECT_FLOAT_EQ(n[3 * v], 0.f) << v;
  }
}

TEST(VertexNormals, LargerFacesWeighMore) {
  // Vertex 0 shared by a big face in the z = 0 plane and a small one in the x = 0 plane.
  const std::vector<float> p = {0, 0, 0, 10, 0, 0, 0, 10, 0, 0, 0, 1, 0, 1, 0};
  const std::vector<uint32_t> idx = {0, 1, 2, 0, 4, 3};
  std::vector<float> n(p.size());
  area_weighted_normals(n, p, idx);
  EXPECT_NEAR(length3(&n[0]), 1.f, 1e-6f);
  EXPECT_GT(n[2], 0.99f);  // the 50-unit face dominates the 0.5-unit one
  EXPECT_GT(n[0], 0.f);
  EXPECT_LT(n[0], 0.02f);
}

TEST(VertexNormals, SplitCopiesKeepAHardEdge) {
  // Two faces folded at 90 degrees along x, the fold's vertices one copy per side.
  const std::vector<float> p = {0, 0, 0, 1, 0, 0, 0, 1, 0,   // face A in z = 0, normal +z
                                0, 0, 0, 1, 0, 0, 0, 0, -1};  // face B in y = 0, normal +y
  const std::vector<uint32_t> idx = {0, 1, 2, 3, 4, 5};
  std::vector<float> n(p.size());
  EXPECT_EQ(area_weighted_normals(n, p, idx), 6u);
  for (int v = 0; v < 3; ++v) EXPECT_FLOAT_EQ(n[3 * v + 2], 1.f) << v;
  for (int v = 3; v < 6; ++v) EXPECT_FLOAT_EQ(n[3 * v + 1], 1.f) << v;
}

TEST(VertexNormals, DegenerateAndUnusedVerticesGetZero) {
  const std::vector<float> p = {0, 0, 0, 1, 1, 1, 2, 2, 2, 5, 5, 5};  // collinear face, vertex 3 unused
  const std::vector<uint32_t> idx = {0, 1, 2};
  std::vector<float> n(p.size(), 3.f);
  EXPECT_EQ(area_weighted_normals(n, p, idx), 0u);
  for (float x : n) EXPECT_EQ(x, 0.f);
}

TEST(VertexNormals, SphereNormalsPointOutward) {
  // A uv sphere (poles shared): every vertex normal within a few degrees of its radial direction.
  const int rings = 16, segs = 32;
  std::vector<float> p;
  p.insert(p.end(), {0, 0, 1});
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < segs; ++s) {
      const float th = float(M_PI) * r / rings, ph = 2 * float(M_PI) * s / segs;
      p.insert(p.end(), {std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)});
    }
  p.insert(p.end(), {0, 0, -1});
  const uint32_t south = uint32_t(p.size() / 3 - 1);
  auto at = [&](int r, int s) { return uint32_t(1 + (r - 1) * segs + (s % segs)); };
  std::vector<uint32_t> idx;
  for (int s = 0; s < segs; ++s) idx.insert(idx.end(), {0, at(1, s), at(1, s + 1)});
  for (int r = 1; r + 1 < rings; ++r)
    for (int s = 0; s < segs; ++s) idx.insert(idx.end(), {at(r, s), at(r + 1, s), at(r + 1, s + 1), at(r, s), at(r + 1, s + 1), at(r, s + 1)});
  for (int s = 0; s < segs; ++s) idx.insert(idx.end(), {at(rings - 1, s), south, at(rings - 1, s + 1)});
  std::vector<float> n(p.size());
  ASSERT_EQ(area_weighted_normals(n, p, idx), p.size() / 3);
  for (size_t v = 0; v < p.size() / 3; ++v) {
    const float d = n[3 * v] * p[3 * v] + n[3 * v + 1] * p[3 * v + 1] + n[3 * v + 2] * p[3 * v + 2];
    EXPECT_GT(d, 0.995f) << v;
  }
}

}  // namespace
}  // namespace lod
