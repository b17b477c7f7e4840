// Fly and orbit cameras: taking over from another camera keeps the picture, and moving
// goes where the controls say.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/glm.hpp>

#include "viewer/fly_camera.h"
#include "viewer/orbit_camera.h"
#include "viewer/overhead_camera.h"

namespace {

using namespace lod;
using namespace lod::viewer;

View view_from(glm::vec3 eye, glm::vec3 target) {
  View v;
  v.eye = eye;
  v.target = target;
  return v;
}

void expect_near(glm::vec3 a, glm::vec3 b, float tol = 1e-4f) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

TEST(FlyCamera, LookLikeKeepsEyeAndDirection) {
  const View v = view_from({10, 5, -3}, {4, 2, 7});
  FlyCamera fly;
  fly.look_like(v);
  const View w = fly.view(v);
  expect_near(w.eye, v.eye);
  expect_near(glm::normalize(w.target - w.eye), glm::normalize(v.target - v.eye));
}

TEST(FlyCamera, MovesForwardAndStrafesRight) {
  FlyCamera fly;
  fly.look_like(view_from({0, 0, 0}, {0, 0, -1}));  // looking down -z
  fly.speed = 2;
  fly.update({.forward = 1}, 0.5f);
  expect_near(fly.position, {0, 0, -1});
  fly.update({.right = 1}, 1.f);
  expect_near(fly.position, {2, 0, -1});
}

TEST(FlyCamera, PitchStopsShortOfThePoles) {
  FlyCamera fly;
  fly.update({.look_dy = -1e6f}, 0.f);  // mouse far up
  EXPECT_LT(fly.pitch, 1.5708f);
  const View v = fly.view(View{});
  EXPECT_GT(glm::length(glm::cross(v.target - v.eye, v.up)), 0.01f) << "view direction parallel to up";
}

TEST(FlyCamera, DegenerateViewKeepsTheOldDirection) {
  FlyCamera fly;
  fly.yaw = 0.7f;
  fly.look_like(view_from({1, 1, 1}, {1, 1, 1}));
  EXPECT_EQ(fly.yaw, 0.7f);
  expect_near(fly.position, {1, 1, 1});
}

TEST(OrbitCamera, LookLikeKeepsEyeAndTarget) {
  const View v = view_from({30, 12, -40}, {5, 0, 5});
  OrbitCamera orbit;
  orbit.look_like(v);
  const View w = orbit.view(v);
  expect_near(w.eye, v.eye, 1e-3f);
  expect_near(w.target, v.target);
}

TEST(OrbitCamera, RotateKeepsDistanceAndZoomShrinksIt) {
  OrbitCamera orbit;
  orbit.look_like(view_from({0, 0, 100}, {0, 0, 0}));
  orbit.rotate(200, 50);
  EXPECT_NEAR(glm::length(orbit.eye() - orbit.target), 100.f, 1e-3f);
  orbit.zoom(3);
  EXPECT_LT(orbit.distance, 100.f);
  orbit.zoom(-1e4f);
  EXPECT_TRUE(std::isfinite(orbit.distance));
  orbit.zoom(1e4f);
  EXPECT_GT(orbit.distance, 0.f);
}

}  // namespace

namespace {

TEST(OverheadCamera, FramesEveryObjectFromAbove) {
  lod::ObjectSet objects;
  objects.resize(3);
  const float cx[3] = {-500, 700, 20}, cz[3] = {-100, 300, 900}, r[3] = {10, 25, 5};
  for (size_t i = 0; i < 3; ++i) {
    objects.cx[i] = cx[i];
    objects.cy[i] = 2;
    objects.cz[i] = cz[i];
    objects.radius[i] = r[i];
  }
  lod::View lens;
  lens.width = 640;
  lens.height = 360;
  const lod::View v = lod::viewer::overhead_view(objects, lens);
  EXPECT_GT(v.eye.y, 2.f);
  const glm::mat4 m = lod::projection_matrix(v) * lod::view_matrix(v);
  for (size_t i = 0; i < 3; ++i) {
    for (glm::vec3 edge : {glm::vec3(-r[i], 0, 0), glm::vec3(r[i], 0, 0), glm::vec3(0, 0, -r[i]), glm::vec3(0, 0, r[i])}) {
      const glm::vec4 clip = m * glm::vec4(glm::vec3(cx[i], 2, cz[i]) + edge, 1);
      EXPECT_LE(std::abs(clip.x / clip.w), 1.f) << "object " << i;
      EXPECT_LE(std::abs(clip.y / clip.w), 1.f) << "object " << i;
      EXPECT_LE(std::abs(clip.z / clip.w), 1.f) << "object " << i << " clipped by near/far";
    }
  }
  // North (-z) is up in the picture.
  const glm::vec4 north = m * glm::vec4(20, 2, -100, 1), south = m * glm::vec4(20, 2, 900, 1);
  EXPECT_GT(north.y / north.w, south.y / south.w);
}

TEST(OverheadCamera, EmptySceneGivesAFiniteView) {
  const lod::View v = lod::viewer::overhead_view(lod::ObjectSet{}, lod::View{});
  EXPECT_TRUE(std::isfinite(v.eye.y));
  EXPECT_GT(glm::length(v.eye - v.target), 0.f);
}

}  // namespace

namespace {

// The bird's-eye camera also frames where the frame puts its entries (the frame's models and
// transforms, not the scene's start placements), so moving objects stay in the picture.
TEST(OverheadCamera, FramesTheFramesEntriesWhereTheFrameSaysTheyAre) {
  lod::ObjectSet placed;
  placed.resize(1);
  placed.cx[0] = 0;
  placed.cz[0] = 0;
  placed.radius[0] = 1;
  // Model 1's sphere sits off its origin: +x by 2, radius 0.5.
  std::vector<lod::viewer::ModelSphere> models(2);
  models[1].center = {2, 0, 0};
  models[1].radius = 0.5f;
  lod::Frame frame;
  frame.models = {1};
  lod::Transform t;
  t.position[0] = 300;
  t.position[2] = -40;
  const float h = std::sqrt(0.5f);  // 90 degrees about +y: model +x turns to world -z
  t.rotation[1] = h;
  t.rotation[3] = h;
  t.scale = 10;
  frame.transforms = {t};
  lod::View lens;
  lens.width = 640;
  lens.height = 360;
  const lod::View v = lod::viewer::overhead_view(placed, frame, models, lens);
  const glm::mat4 m = lod::projection_matrix(v) * lod::view_matrix(v);
  // The entry's world sphere: (300, 0, -40) + 10 * (0, 0, -2), radius 5.
  for (glm::vec3 p :
       {glm::vec3(305, 0, -60), glm::vec3(295, 0, -60), glm::vec3(300, 0, -65), glm::vec3(-1, 0, 1)}) {
    const glm::vec4 clip = m * glm::vec4(p, 1);
    EXPECT_LE(std::abs(clip.x / clip.w), 1.f) << p.x << " " << p.z;
    EXPECT_LE(std::abs(clip.y / clip.w), 1.f) << p.x << " " << p.z;
  }
  // Only that far: the view is centred between the placement and the entry.
  EXPECT_NEAR(v.target.x, 0.5f * (-1 + 305), 1e-3f);
  EXPECT_NEAR(v.target.z, 0.5f * (1 + -65), 1e-3f);
}

TEST(OverheadCamera, ModelSpheresHoldEveryLevel) {
  lod::LodChain c;
  c.levels.resize(2);
  c.levels[0].bounds = {{1, 0, 0}, 2};
  c.levels[1].bounds = {{2, 0, 0}, 2};  // bulges 1 past level 0's sphere
  const auto s = lod::viewer::model_spheres(std::vector<lod::LodChain>{c});
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].center, glm::vec3(1, 0, 0));
  EXPECT_FLOAT_EQ(s[0].radius, 3.f);
}

}  // namespace
