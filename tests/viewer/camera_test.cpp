// Fly and orbit cameras: taking over from another camera keeps the picture, and moving
// goes where the controls say.
#include <gtest/gtest.h>

#include <glm/glm.hpp>

#include "viewer/fly_camera.h"
#include "viewer/orbit_camera.h"

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
