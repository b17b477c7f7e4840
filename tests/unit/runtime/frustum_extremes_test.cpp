// Frustum culling over the whole accepted camera range: fields of view from kMinFovYDeg to
// kMaxFovYDeg and far planes up to 1e9, checked point by point against a reference that
// classifies by depth and by the tangents of the half-angles (not by the planes culling uses).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "runtime/view.h"
#include "runtime/visibility.h"

namespace lod {
namespace {

struct Sample {
  glm::vec3 world;
  bool inside;
};

// Points spread in view space (depth log-uniform from near / 4 to 4 far, a few behind the eye;
// x and y up to 2.5 times the half-extent at that depth), rounded to the float world position
// culling sees, then classified from that position by exact signed distances in double. A
// point closer to a boundary than float rounding of the planes can resolve is skipped.
std::vector<Sample> samples(const View& v, uint32_t seed) {
  using V = glm::dvec3;
  const V eye(v.eye);
  const V fwd = glm::normalize(V(v.target) - eye);
  const V right = glm::normalize(glm::cross(fwd, V(v.up)));
  const V up = glm::cross(right, fwd);
  const double ty = std::tan(0.5 * glm::radians(double(v.fov_y_deg)));
  const double tx = ty * double(v.width) / double(v.height);
  const double cy = std::cos(std::atan(ty)), cx = std::cos(std::atan(tx));
  const double near_plane = v.near_plane, far_plane = v.far_plane;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-2.5, 2.5);
  std::uniform_real_distribution<double> log_depth(std::log(near_plane / 4), std::log(far_plane * 4));
  std::vector<Sample> out;
  while (out.size() < 4000) {
    const double d = (out.size() % 8 == 0 ? -1 : 1) * std::exp(log_depth(rng));
    const double ad = std::abs(d);  // behind the eye, spread like the points in front
    const glm::vec3 world(eye + d * fwd + unit(rng) * ad * tx * right + unit(rng) * ad * ty * up);
    const V rel = V(world) - eye;
    const double depth = glm::dot(rel, fwd), x = glm::dot(rel, right), y = glm::dot(rel, up);
    // Signed distances to the six planes, positive inside.
    const double margin[6] = {cx * (depth * tx - std::abs(x)), cx * (depth * tx - std::abs(x)),
                              cy * (depth * ty - std::abs(y)), cy * (depth * ty - std::abs(y)),
                              depth - near_plane,              far_plane - depth};
    const double tol = 1e-6 * (glm::length(eye) + glm::length(V(world)));
    bool inside = true, outside = false, clear = true;
    for (int k = 0; k < 6; ++k) {
      const double t = k == 5 ? tol + 1e-6 * far_plane : tol;
      inside = inside && margin[k] > t;
      outside = outside || margin[k] < -t;
    }
    clear = inside || outside;
    if (clear) out.push_back({world, inside});
  }
  return out;
}

// How many samples cull_spheres (radius 0) puts on the wrong side.
size_t misclassified(const View& v, uint32_t seed) {
  const std::vector<Sample> s = samples(v, seed);
  std::vector<float> x, y, z, r(s.size(), 0.f);
  for (const Sample& p : s) x.push_back(p.world.x), y.push_back(p.world.y), z.push_back(p.world.z);
  std::vector<uint8_t> visible(s.size());
  cull_spheres(visible, x, y, z, r, frustum_of(v));
  size_t wrong = 0;
  for (size_t i = 0; i < s.size(); ++i) wrong += (visible[i] != 0) != s[i].inside;
  return wrong;
}

View tilted(float fov, float far_plane) {
  View v;
  v.eye = {10, 5, -3};
  v.target = v.eye + glm::vec3(1, -0.3f, -2);
  v.fov_y_deg = fov;
  v.width = 1280;
  v.height = 720;
  v.near_plane = 0.1f;
  v.far_plane = far_plane;
  return v;
}

TEST(FrustumExtremes, CullingMatchesTheReferenceAcrossFieldsOfViewAndFarPlanes) {
  size_t total = 0;
  for (float fov : {kMinFovYDeg, 0.01f, 1.0f, 60.0f, 120.0f, kMaxFovYDeg}) {
    for (float far_plane : {1000.0f, 1e6f, 1e9f}) {
      const size_t wrong = misclassified(tilted(fov, far_plane), 17);
      EXPECT_EQ(wrong, 0u) << "fov " << fov << ", far " << far_plane << ": " << wrong << " of 4000 points";
      total += wrong;
    }
  }
  RecordProperty("misclassified", static_cast<int>(total));
}

TEST(FrustumExtremes, PlanesStayFiniteAndNormalized) {
  for (float fov : {kMinFovYDeg, kMaxFovYDeg})
    for (float far_plane : {1.0f, 1e9f, 3e38f}) {
      const Frustum f = frustum_of(tilted(fov, far_plane));
      for (const glm::vec4& p : f.planes) {
        for (int k = 0; k < 4; ++k) ASSERT_TRUE(std::isfinite(p[k])) << fov << " " << far_plane;
        EXPECT_NEAR(glm::length(glm::vec3(p)), 1.0f, 1e-5f);
      }
    }
}

}  // namespace
}  // namespace lod
