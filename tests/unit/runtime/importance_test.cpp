#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "runtime/importance.h"
#include "unit/runtime/runtime_fixtures.h"

namespace lod {
namespace {

struct Measured {
  std::vector<float> distance, area, weight;
  ViewMinima minima;
};

Measured measure_all(const ObjectSet& o, const std::vector<uint8_t>& visible, glm::vec3 eye, float focal) {
  Measured m;
  m.distance.assign(o.size(), -1.f);
  m.area.assign(o.size(), -1.f);
  m.weight.assign(o.size(), -1.f);
  m.minima = measure_objects(m.distance, m.area, visible, o.cx, o.cy, o.cz, o.radius, eye, focal);
  importance_weights(m.weight, visible, m.distance, m.area, m.minima);
  return m;
}

TEST(MeasureObjects, ComputesDistanceAndProjectedAreaOfVisibleOnly) {
  ObjectSet o;
  o.resize(3);
  o.cx = {0, 30, 0};
  o.cz = {-10, 0, 0};
  o.radius = {2, 1, 5};  // the third sphere contains the eye
  const std::vector<uint8_t> visible = {1, 0, 1};
  const Measured m = measure_all(o, visible, {0, 0, 0}, 500.f);
  EXPECT_FLOAT_EQ(m.distance[0], 10.f);
  EXPECT_NEAR(m.area[0], std::numbers::pi * 100.0 * 100.0, 0.5);  // pi (2 * 500 / 10)^2
  EXPECT_EQ(m.distance[1], -1.f);  // invisible: untouched
  EXPECT_EQ(m.area[1], -1.f);
  EXPECT_EQ(m.weight[1], -1.f);
  EXPECT_FLOAT_EQ(m.distance[2], 5.f);  // clamped to the radius
  EXPECT_NEAR(m.area[2], std::numbers::pi * 500.0 * 500.0, 1.0);
  EXPECT_EQ(m.minima.visible, 2u);
  EXPECT_FLOAT_EQ(m.minima.nearest_distance, 5.f);
  EXPECT_FLOAT_EQ(m.minima.smallest_area, m.area[0]);
}

TEST(MeasureObjects, ZeroRadiusAtTheEyeStaysFinite) {
  ObjectSet o;
  o.resize(2);
  o.cz = {0, -20};
  o.radius = {0, 1};
  const Measured m = measure_all(o, {1, 1}, {0, 0, 0}, 1000.f);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_TRUE(std::isfinite(m.distance[i]) && m.distance[i] > 0);
    EXPECT_TRUE(std::isfinite(m.area[i]) && m.area[i] > 0);
    EXPECT_TRUE(std::isfinite(m.weight[i]));
  }
}

TEST(ImportanceWeights, EqualsRelativeDistanceOverRelativeArea) {
  const ObjectSet o = test::random_spheres(500, 300, 6, 1, 11);
  std::vector<uint8_t> visible(o.size());
  for (size_t i = 0; i < o.size(); ++i) visible[i] = (i % 3) != 0;
  const glm::vec3 eye(1, 2, 3);
  const Measured m = measure_all(o, visible, eye, 800.f);
  for (size_t i = 0; i < o.size(); ++i) {
    if (!visible[i]) continue;
    const double d = double(m.minima.nearest_distance) / m.distance[i];
    const double s = double(m.area[i]) / m.minima.smallest_area;
    EXPECT_NEAR(m.weight[i], d / s, 1e-5 * (d / s)) << i;
    EXPECT_LE(d, 1.0);
    EXPECT_GE(s, 1.0);
  }
}

TEST(ImportanceWeights, FarAndSmallObjectsOutweighNearAndLarge) {
  ObjectSet o;
  o.resize(4);
  o.cz = {-10, -100, -50, -50};
  o.radius = {1, 1, 4, 0.5f};
  const Measured m = measure_all(o, {1, 1, 1, 1}, {0, 0, 0}, 1000.f);
  EXPECT_GT(m.weight[1], m.weight[0]);  // same size, farther
  EXPECT_GT(m.weight[3], m.weight[2]);  // same distance, smaller
}

TEST(ImportanceStages, SubRangesEqualTheWholeRange) {
  const ObjectSet o = test::random_spheres(3001, 400, 10, 1, 21);
  std::vector<uint8_t> visible(o.size());
  std::mt19937 rng(4);
  for (auto& v : visible) v = (rng() % 4) != 0;
  const glm::vec3 eye(-7, 3, 11);
  const float focal = 623.5f;
  const Measured whole = measure_all(o, visible, eye, focal);

  std::vector<float> distance(o.size(), -1.f), area(o.size(), -1.f), weight(o.size(), -1.f);
  ViewMinima merged = empty_minima();
  const size_t chunk = 256;
  for (size_t b = 0; b < o.size(); b += chunk) {
    const size_t n = std::min(chunk, o.size() - b);
    merged = merge_minima(merged, measure_objects(std::span(distance).subspan(b, n), std::span(area).subspan(b, n),
                                                  std::span(visible).subspan(b, n), std::span(o.cx).subspan(b, n),
                                                  std::span(o.cy).subspan(b, n), std::span(o.cz).subspan(b, n),
                                                  std::span(o.radius).subspan(b, n), eye, focal));
  }
  EXPECT_EQ(merged.nearest_distance, whole.minima.nearest_distance);
  EXPECT_EQ(merged.smallest_area, whole.minima.smallest_area);
  EXPECT_EQ(merged.visible, whole.minima.visible);
  size_t weighted = 0;
  for (size_t b = 0; b < o.size(); b += chunk) {
    const size_t n = std::min(chunk, o.size() - b);
    weighted += importance_weights(std::span(weight).subspan(b, n), std::span(visible).subspan(b, n),
                                   std::span(distance).subspan(b, n), std::span(area).subspan(b, n), merged);
  }
  EXPECT_EQ(weighted, whole.minima.visible);
  EXPECT_EQ(distance, whole.distance);
  EXPECT_EQ(area, whole.area);
  EXPECT_EQ(weight, whole.weight);
}

TEST(ViewMinimaMerge, EmptyIsTheIdentity) {
  const ViewMinima a{3.f, 0.25f, 7};
  const ViewMinima e = empty_minima();
  EXPECT_EQ(e.visible, 0u);
  const ViewMinima m = merge_minima(e, a);
  EXPECT_EQ(m.nearest_distance, 3.f);
  EXPECT_EQ(m.smallest_area, 0.25f);
  EXPECT_EQ(m.visible, 7u);
  const ViewMinima both = merge_minima(a, ViewMinima{5.f, 0.125f, 2});
  EXPECT_EQ(both.nearest_distance, 3.f);
  EXPECT_EQ(both.smallest_area, 0.125f);
  EXPECT_EQ(both.visible, 9u);
}

}  // namespace
}  // namespace lod
