#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "runtime/visibility.h"
#include "unit/runtime/runtime_fixtures.h"

namespace lod {
namespace {

// Signed distances of a point to the six frustum planes, built geometrically in double from
// the camera basis: nothing shared with frustum_of but the View.
struct ReferenceFrustum {
  glm::dvec3 eye, right, up, forward;
  double tan_x, tan_y, near_plane, far_plane;

  explicit ReferenceFrustum(const View& v) {
    eye = glm::dvec3(v.eye);
    forward = glm::normalize(glm::dvec3(v.target) - eye);
    right = glm::normalize(glm::cross(forward, glm::dvec3(v.up)));
    up = glm::cross(right, forward);
    tan_y = std::tan(0.5 * glm::radians(static_cast<double>(v.fov_y_deg)));
    tan_x = tan_y * v.width / v.height;
    near_plane = v.near_plane;
    far_plane = v.far_plane;
  }
  void distances(const glm::dvec3& p, double out[6]) const {
    const glm::dvec3 q = p - eye;
    const double x = glm::dot(q, right), y = glm::dot(q, up), z = glm::dot(q, forward);
    const double nx = std::sqrt(1 + tan_x * tan_x), ny = std::sqrt(1 + tan_y * tan_y);
    out[0] = (x + z * tan_x) / nx;
    out[1] = (-x + z * tan_x) / nx;
    out[2] = (y + z * tan_y) / ny;
    out[3] = (-y + z * tan_y) / ny;
    out[4] = z - near_plane;
    out[5] = far_plane - z;
  }
};

View random_view(std::mt19937& rng) {
  std::uniform_real_distribution<float> pos(-150, 150), fov(30, 100), nearp(0.1f, 5.f), farp(50, 400);
  View v;
  v.eye = {pos(rng), pos(rng), pos(rng)};
  do {
    v.target = {pos(rng), pos(rng), pos(rng)};
  } while (glm::length(v.target - v.eye) < 1 ||
           std::abs(glm::normalize(v.target - v.eye).y) > 0.99f);  // keep up and forward apart
  v.fov_y_deg = fov(rng);
  v.width = 1280;
  v.height = 720;
  v.near_plane = nearp(rng);
  v.far_plane = farp(rng);
  return v;
}

TEST(CullSpheres, EqualsDoublePrecisionReferenceOnRandomScenes) {
  std::mt19937 rng(7);
  size_t compared = 0, seen = 0;
  for (int scene = 0; scene < 40; ++scene) {
    const View v = random_view(rng);
    const ObjectSet o = test::random_spheres(2000, 200, 8, 1, 100 + scene);
    std::vector<uint8_t> visible(o.size(), 0xcd);
    const size_t count = cull_spheres(visible, o.cx, o.cy, o.cz, o.radius, frustum_of(v));
    const ReferenceFrustum ref(v);
    size_t counted = 0;
    for (size_t i = 0; i < o.size(); ++i) {
      ASSERT_LE(visible[i], 1);
      counted += visible[i];
      double d[6];
      ref.distances({o.cx[i], o.cy[i], o.cz[i]}, d);
      bool inside = true, marginal = false;
      for (double di : d) {
        inside = inside && di >= -o.radius[i];
        marginal = marginal || std::abs(di + o.radius[i]) < 1e-3;
      }
      if (marginal) continue;  // float vs double may disagree this close to a plane
      ++compared;
      seen += inside;
      EXPECT_EQ(visible[i], inside ? 1 : 0) << "scene " << scene << " object " << i;
    }
    EXPECT_EQ(count, counted);
  }
  EXPECT_GT(compared, 70000u);
  EXPECT_GT(seen, 1000u);  // the scenes really exercise both outcomes
}

TEST(CullSpheres, SubRangesGiveTheWholeRangeResult) {
  std::mt19937 rng(3);
  const View v = random_view(rng);
  const ObjectSet o = test::random_spheres(1001, 200, 8, 1, 5);
  const Frustum f = frustum_of(v);
  std::vector<uint8_t> whole(o.size()), parts(o.size());
  const size_t total = cull_spheres(whole, o.cx, o.cy, o.cz, o.radius, f);
  size_t sum = 0;
  for (size_t begin = 0; begin < o.size(); begin += 97) {
    const size_t n = std::min<size_t>(97, o.size() - begin);
    sum += cull_spheres(std::span(parts).subspan(begin, n), std::span(o.cx).subspan(begin, n),
                        std::span(o.cy).subspan(begin, n), std::span(o.cz).subspan(begin, n),
                        std::span(o.radius).subspan(begin, n), f);
  }
  EXPECT_EQ(whole, parts);
  EXPECT_EQ(sum, total);
}

TEST(CullSpheres, SphereStraddlingAPlaneIsVisibleAndBehindIsNot) {
  View v;  // at the origin looking down -z, near 0.5
  const Frustum f = frustum_of(v);
  const std::vector<float> cx = {0, 0, 0, 0}, cy = {0, 0, 0, 0}, cz = {-10, 2, 0.9f, 1.1f}, r = {1, 1, 1.5f, 1.5f};
  std::vector<uint8_t> vis(4);
  EXPECT_EQ(cull_spheres(vis, cx, cy, cz, r, f), 2u);
  EXPECT_EQ(vis, (std::vector<uint8_t>{1, 0, 1, 0}));  // 0.9 + 1.5 reaches past the near plane
  std::vector<uint8_t> none;
  EXPECT_EQ(cull_spheres(none, {}, {}, {}, {}, f), 0u);
}

}  // namespace
}  // namespace lod
