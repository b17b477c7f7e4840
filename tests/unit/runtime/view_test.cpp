#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "runtime/camera_path.h"
#include "runtime/view.h"

namespace lod {
namespace {

float plane_distance(const glm::vec4& p, const glm::vec3& x) { return glm::dot(glm::vec3(p), x) + p.w; }

View test_view() {
  View v;
  v.eye = {10, 5, -3};
  v.target = {40, 0, 20};
  v.fov_y_deg = 50;
  v.width = 800;
  v.height = 600;
  v.near_plane = 0.5f;
  v.far_plane = 1000;
  return v;
}

TEST(Frustum, PlanesAreNormalizedAndFaceInwards) {
  const View v = test_view();
  const Frustum f = frustum_of(v);
  const glm::vec3 forward = glm::normalize(v.target - v.eye);
  const glm::vec3 inside = v.eye + forward * 100.f;
  for (const glm::vec4& p : f.planes) {
    EXPECT_NEAR(glm::length(glm::vec3(p)), 1.0f, 1e-5f);
    EXPECT_GT(plane_distance(p, inside), 0.f);
  }
  // Near and far planes sit at their distances along the view direction.
  EXPECT_NEAR(plane_distance(f.planes[4], v.eye), -v.near_plane, 1e-3f);
  EXPECT_NEAR(plane_distance(f.planes[5], v.eye), v.far_plane, 0.5f);
  // Behind the eye and beyond the far plane are outside.
  EXPECT_LT(plane_distance(f.planes[4], v.eye - forward * 5.f), 0.f);
  EXPECT_LT(plane_distance(f.planes[5], v.eye + forward * 1100.f), 0.f);
}

TEST(Frustum, SidePlanesMatchFieldOfView) {
  View v;  // looks down -z from the origin
  v.fov_y_deg = 90;
  v.width = v.height = 100;
  const Frustum f = frustum_of(v);
  // With a 90-degree vertical field, (0, 10, -10) lies on the top plane.
  EXPECT_NEAR(plane_distance(f.planes[3], {0, 10, -10}), 0.f, 1e-4f);
  EXPECT_NEAR(plane_distance(f.planes[2], {0, -10, -10}), 0.f, 1e-4f);
  EXPECT_NEAR(plane_distance(f.planes[0], {-10, 0, -10}), 0.f, 1e-4f);
  EXPECT_NEAR(plane_distance(f.planes[1], {10, 0, -10}), 0.f, 1e-4f);
}

TEST(Frustum, MatricesMapTargetToScreenCentre) {
  const View v = test_view();
  const glm::vec4 clip = projection_matrix(v) * view_matrix(v) * glm::vec4(v.target, 1.f);
  EXPECT_NEAR(clip.x / clip.w, 0.f, 1e-5f);
  EXPECT_NEAR(clip.y / clip.w, 0.f, 1e-5f);
}

TEST(FocalPixels, IsHalfHeightOverTanHalfFov) {
  View v;
  v.height = 720;
  v.fov_y_deg = 90;
  EXPECT_NEAR(focal_pixels(v), 360.f, 1e-3f);
  v.fov_y_deg = 60;
  EXPECT_NEAR(focal_pixels(v), 360.f / std::tan(glm::radians(30.f)), 1e-2f);
}

TEST(CameraPath, OrbitStaysAtRadiusAndHeightLookingAtCentre) {
  CameraPath p;
  p.kind = PathKind::orbit;
  p.center = {5, 2, -7};
  p.radius = 400;
  p.height_above = 60;
  p.period_frames = 600;
  for (uint32_t frame : {0u, 1u, 150u, 299u, 599u, 600u, 123457u}) {
    const View v = view_at(p, frame);
    const glm::vec2 flat(v.eye.x - p.center.x, v.eye.z - p.center.z);
    EXPECT_NEAR(glm::length(flat), 400.f, 1e-3f) << frame;
    EXPECT_FLOAT_EQ(v.eye.y, 62.f);
    EXPECT_EQ(v.target, p.center);
  }
  EXPECT_EQ(view_at(p, 0).eye, view_at(p, 600).eye);  // periodic
  EXPECT_NE(view_at(p, 0).eye, view_at(p, 1).eye);    // moving
}

TEST(CameraPath, FlythroughTracesAFigureEightLookingAlongIt) {
  CameraPath p;
  p.kind = PathKind::flythrough;
  p.radius = 100;
  p.height_above = 10;
  p.period_frames = 400;
  const View start = view_at(p, 0), half = view_at(p, 200), quarter = view_at(p, 100);
  EXPECT_NEAR(glm::length(start.eye - glm::vec3(0, 10, 0)), 0.f, 1e-4f);  // crosses the centre twice
  EXPECT_NEAR(glm::length(half.eye - glm::vec3(0, 10, 0)), 0.f, 1e-3f);
  EXPECT_NEAR(quarter.eye.x, 100.f, 1e-3f);  // widest point of one lobe
  for (uint32_t frame = 0; frame < 400; frame += 7) {
    const View a = view_at(p, frame), b = view_at(p, frame + 1);
    EXPECT_FLOAT_EQ(a.eye.y, 10.f);
    EXPECT_LE(std::abs(a.eye.x), 100.f + 1e-3f);
    const glm::vec3 look = glm::normalize(a.target - a.eye);
    const glm::vec3 step = b.eye - a.eye;
    EXPECT_GT(glm::dot(look, glm::normalize(step)), 0.9f) << frame;  // looks where it goes
  }
}

TEST(CameraPath, KeyframesHitKeysExactlyAndInterpolateBetween) {
  CameraPath p;
  p.kind = PathKind::keyframes;
  p.keyframes = {{10, {0.1f, 0.2f, 0.3f}, {1, 1, 1}}, {20, {10.7f, -3.3f, 5.9f}, {0, 0, 0}},
                 {40, {-2, 4, 8}, {3, 3, 3}}};
  for (const CameraKeyframe& k : p.keyframes) {
    const View v = view_at(p, k.frame);
    EXPECT_EQ(v.eye, k.position);
    EXPECT_EQ(v.target, k.look_at);
  }
  EXPECT_EQ(view_at(p, 0).eye, p.keyframes[0].position);  // held before the first key
  EXPECT_EQ(view_at(p, 1000).eye, p.keyframes[2].position);
  const View mid = view_at(p, 30);
  EXPECT_NEAR(mid.eye.x, 4.35f, 1e-5f);
  EXPECT_NEAR(mid.target.x, 1.5f, 1e-5f);
  EXPECT_EQ(view_at(p, 15).fov_y_deg, p.lens.fov_y_deg);
}

TEST(CameraPath, SingleKeyframeHoldsForever) {
  CameraPath p;
  p.kind = PathKind::keyframes;
  p.keyframes = {{5, {1, 2, 3}, {4, 5, 6}}};
  EXPECT_EQ(view_at(p, 0).eye, glm::vec3(1, 2, 3));
  EXPECT_EQ(view_at(p, 99).target, glm::vec3(4, 5, 6));
}


// A keyframe looking straight down (up = +y, parallel to the view direction): glm::lookAt gave
// NaN planes and every object was culled. The basis falls back to front_view_of's.
TEST(CameraPath, LookingStraightDownHasAStableFrustum) {
  CameraPath p;
  p.kind = PathKind::keyframes;
  p.keyframes = {{0, {0, 100, 0}, {0, 0, 0}}};
  const View v = view_at(p, 0);
  // The path gives an up vector the service accepts (perpendicular to the view direction).
  const char* why = nullptr;
  EXPECT_TRUE(camera_valid(camera_of(v), &why)) << why;
  EXPECT_NEAR(glm::dot(v.up, glm::normalize(v.target - v.eye)), 0.f, 1e-6f);
  View raw = v;
  raw.up = {0, 1, 0};  // and view_matrix itself copes with a parallel up
  for (const glm::vec4& pl : frustum_of(raw).planes) EXPECT_GT(plane_distance(pl, {0, 0, 0}), 0.f);
  const Frustum f = frustum_of(v);
  for (const glm::vec4& pl : f.planes)
    for (int k = 0; k < 4; ++k) ASSERT_TRUE(std::isfinite(pl[k]));
  for (const glm::vec3 x : {glm::vec3(0, 0, 0), glm::vec3(5, 0, 5), glm::vec3(-5, 10, 3)})
    for (const glm::vec4& pl : f.planes) EXPECT_GT(plane_distance(pl, x), 0.f) << x.x << " " << x.z;
  EXPECT_LT(plane_distance(f.planes[4], {0, 101, 0}), 0.f);  // behind the eye
  const glm::vec4 clip = projection_matrix(v) * view_matrix(v) * glm::vec4(v.target, 1.f);
  EXPECT_NEAR(clip.x / clip.w, 0.f, 1e-5f);
  EXPECT_NEAR(clip.y / clip.w, 0.f, 1e-5f);
  // Looking straight up too, and the ordinary case is glm::lookAt's matrix.
  View up = v;
  up.eye = {0, -100, 0};
  for (const glm::vec4& pl : frustum_of(up).planes) EXPECT_GT(plane_distance(pl, {0, 0, 0}), 0.f);
  const View t = test_view();
  const glm::mat4 a = view_matrix(t), b = glm::lookAt(t.eye, t.target, t.up);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) EXPECT_NEAR(a[c][r], b[c][r], 1e-4f);
}

}  // namespace
}  // namespace lod
