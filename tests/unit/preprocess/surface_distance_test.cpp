// SurfaceDistance: one surface queried from many threads, with and without known bounds.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <random>
#include <thread>
#include <vector>

#include "preprocess/surface_error.h"
#include "vd_meshes.h"

namespace lod {
namespace {

TriangleMeshView view_of(const MeshData& m) { return {m.positions.data(), m.vertex_count(), m.indices.data(), m.indices.size()}; }

// Points at distance 0.5 outside a unit sphere's vertices (radially), so the answer is known.
std::vector<float> pushed_out(const MeshData& m, float by) {
  std::vector<float> p = m.positions;
  for (float& v : p) v *= 1 + by;
  return p;
}

TEST(SurfaceDistance, MeasuresKnownDistancesWithOrWithoutBounds) {
  const MeshData sphere = test::vd_sphere(30, 40);
  SurfaceDistance d;
  ASSERT_TRUE(d.set_surface(view_of(sphere), "sphere"));
  const std::vector<float> points = pushed_out(sphere, 0.5f);
  const size_t n = points.size() / 3;
  SurfaceError plain, bounded;
  ASSERT_TRUE(d.from_points(points.data(), n, nullptr, plain));
  EXPECT_NEAR(plain.max, 0.5f, 1e-4f);
  EXPECT_EQ(plain.samples, n);
  // True upper bounds (distance to the vertex each point came from) change nothing.
  std::vector<float> known(n, 0.5f * (1 + 1e-6f));
  ASSERT_TRUE(d.from_points(points.data(), n, known.data(), bounded));
  EXPECT_EQ(bounded.max, plain.max);
  EXPECT_EQ(bounded.rms, plain.rms);
  // Points of the surface itself, declared so, count as 0.
  std::vector<float> zeros(sphere.vertex_count(), 0.0f);
  SurfaceError on;
  ASSERT_TRUE(d.from_points(sphere.positions.data(), sphere.vertex_count(), zeros.data(), on));
  EXPECT_EQ(on.max, 0.0f);
}

TEST(SurfaceDistance, MeasuresToAnotherMeshAndFromManyThreads) {
  const MeshData sphere = test::vd_sphere(30, 40);
  const MeshData small = test::vd_sphere(30, 40, 0.5f);
  SurfaceDistance d;
  ASSERT_TRUE(d.set_surface(view_of(sphere), "sphere"));
  SurfaceError to_small;
  ASSERT_TRUE(d.from_points_to(view_of(small), sphere.positions.data(), sphere.vertex_count(), nullptr, to_small));
  EXPECT_NEAR(to_small.max, 0.5f, 1e-4f);
  std::vector<SurfaceError> got(4);
  const std::vector<float> points = pushed_out(sphere, 0.25f);
  std::vector<std::thread> threads;
  for (size_t t = 0; t < got.size(); ++t)
    threads.emplace_back([&, t] {
      EXPECT_TRUE(t % 2 ? d.from_points(points.data(), points.size() / 3, nullptr, got[t])
                        : d.from_points_to(view_of(small), points.data(), points.size() / 3, nullptr, got[t]));
    });
  for (auto& th : threads) th.join();
  EXPECT_NEAR(got[1].max, 0.25f, 1e-4f);
  EXPECT_NEAR(got[0].max, 0.75f, 1e-4f);
  EXPECT_EQ(got[0].max, got[2].max);
  EXPECT_EQ(got[1].rms, got[3].rms);
}

// The answers never depend on the BVH (every triangle within rounding of the nearest is visited),
// so the fast-built Morton tree and the SAH tree agree to the bit, point by point and in sum.
TEST(SurfaceDistance, MortonAndSahTreesAnswerToTheBit) {
  const MeshData sphere = test::vd_sphere(60, 80);
  SurfaceDistance morton(BvhBuilder::morton), sah(BvhBuilder::sah);
  ASSERT_TRUE(morton.set_surface(view_of(sphere), "sphere"));
  ASSERT_TRUE(sah.set_surface(view_of(sphere), "sphere"));
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> box(-1.6f, 1.6f);
  std::vector<float> points;
  for (int i = 0; i < 3000; ++i) points.insert(points.end(), {box(rng), box(rng), box(rng)});
  for (size_t i = 0; i < points.size(); i += 3) {
    SurfaceError a, b;
    ASSERT_TRUE(morton.from_points(&points[i], 1, nullptr, a));
    ASSERT_TRUE(sah.from_points(&points[i], 1, nullptr, b));
    ASSERT_EQ(std::bit_cast<uint32_t>(a.max), std::bit_cast<uint32_t>(b.max)) << "point " << i / 3;
  }
  SurfaceError a, b;
  ASSERT_TRUE(morton.from_points(points.data(), points.size() / 3, nullptr, a));
  ASSERT_TRUE(sah.from_points(points.data(), points.size() / 3, nullptr, b));
  EXPECT_EQ(std::bit_cast<uint32_t>(a.rms), std::bit_cast<uint32_t>(b.rms));
  EXPECT_GT(a.max, 0.5f);  // the box's corners are far from the unit sphere
}

TEST(SurfaceDistance, RefusesQueriesBeforeASurface) {
  SurfaceDistance d;
  SurfaceError e;
  const float p[3] = {0, 0, 0};
  EXPECT_FALSE(d.from_points(p, 1, nullptr, e));
}

}  // namespace
}  // namespace lod
