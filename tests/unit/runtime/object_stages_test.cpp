// The per-object stages of dynamic scenes: world spheres from full rotations, level caps,
// object controls, several views folded into one decision, closed-form motion.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/quaternion.hpp>
#include <numbers>

#include "runtime/level_caps.h"
#include "runtime/motion_path.h"
#include "runtime/object_controls.h"
#include "runtime/view_masks.h"
#include "runtime/world_bounds.h"
#include "unit/runtime/runtime_fixtures.h"

namespace lod {
namespace {

TEST(WorldBounds, QuaternionRotationMatchesGlm) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1, 1);
  for (int k = 0; k < 100; ++k) {
    glm::quat q = glm::normalize(glm::quat(u(rng), u(rng), u(rng), u(rng)));  // w x y z
    const glm::vec3 v(u(rng) * 5, u(rng) * 5, u(rng) * 5);
    const glm::vec3 want = q * v;
    const float qq[4] = {q.x, q.y, q.z, q.w}, vv[3] = {v.x, v.y, v.z};
    float got[3];
    rotate_by_quaternion(qq, vv, got);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(got[a], want[a], 1e-4f);
  }
}

TEST(WorldBounds, SphereFollowsPositionRotationAndScale) {
  Sphere model;
  model.center[0] = 1, model.center[1] = 2, model.center[2] = 0;
  model.radius = 3;
  Transform t;
  t.position[0] = 10, t.position[1] = 20, t.position[2] = 30;
  // 90 degrees about +z, given unnormalised (x2): (1, 2, 0) -> (-2, 1, 0).
  const float s = std::sin(std::numbers::pi_v<float> / 4), c = std::cos(std::numbers::pi_v<float> / 4);
  t.rotation[0] = 0, t.rotation[1] = 0, t.rotation[2] = 2 * s, t.rotation[3] = 2 * c;
  t.scale = 2;
  const Sphere w = world_sphere(t, model);
  EXPECT_NEAR(w.center[0], 10 - 4, 1e-5f);
  EXPECT_NEAR(w.center[1], 20 + 2, 1e-5f);
  EXPECT_NEAR(w.center[2], 30, 1e-5f);
  EXPECT_FLOAT_EQ(w.radius, 6);
  t.rotation[0] = t.rotation[1] = t.rotation[2] = t.rotation[3] = 0;  // no rotation, not NaN
  const Sphere z = world_sphere(t, model);
  EXPECT_FLOAT_EQ(z.center[0], 12);
  EXPECT_FLOAT_EQ(z.center[1], 24);
}

TEST(LevelCaps, RowsArePrefixesOfTheirModel) {
  const ModelTable m = test::table_of({{{1000, 0}, {500, 1}, {250, 2}}, {{80, 0}, {40, 1}}});
  const LevelCaps caps = build_level_caps(m);
  EXPECT_EQ(caps.row(0, 2), 0u);
  EXPECT_EQ(caps.row(0, 9), 0u) << "a cap past the last level is the model itself";
  EXPECT_EQ(caps.row(1, 1), 1u);
  for (uint32_t model : {0u, 1u}) {
    for (uint32_t cap = 0; cap < m.level_count[model]; ++cap) {
      const uint32_t r = caps.row(model, cap);
      EXPECT_EQ(caps.model_of[r], model);
      ASSERT_EQ(caps.rows.level_count[r], cap + 1);
      for (uint32_t k = 0; k <= cap; ++k) {
        EXPECT_EQ(caps.rows.triangles[caps.rows.first_level[r] + k], m.triangles[m.first_level[model] + k]);
        EXPECT_EQ(caps.rows.error[caps.rows.first_level[r] + k], m.error[m.first_level[model] + k]);
      }
    }
  }
}

TEST(ObjectControls, OptionsBecomeClampedColumns) {
  const ModelTable m = test::table_of({{{1000, 0}, {500, 1}, {250, 2}, {125, 4}}});
  const LevelCaps caps = build_level_caps(m);
  ObjectOptions o;
  ObjectControl c = control_of(o, 2.f, 0, caps);
  EXPECT_EQ(c.row, 0u);
  EXPECT_EQ(c.min_level, 0);
  EXPECT_EQ(c.error_scale, 2.f);
  EXPECT_EQ(c.inv_priority, 1.f);
  o.min_level = 1, o.max_level = 2, o.lod_bias = 1, o.priority = 4, o.never_cull = true;
  c = control_of(o, 2.f, 0, caps);
  EXPECT_EQ(caps.rows.level_count[c.row], 3) << "coarsest allowed level 2";
  EXPECT_EQ(c.min_level, 1);
  EXPECT_FLOAT_EQ(c.error_scale, 1.f) << "bias 1 halves the error seen";
  EXPECT_FLOAT_EQ(c.inv_priority, 0.25f);
  EXPECT_EQ(c.never_cull, 1);
  o = ObjectOptions{};
  o.forced_level = 9;  // clamped to the last level
  c = control_of(o, 1.f, 0, caps);
  EXPECT_EQ(c.min_level, 3);
  EXPECT_EQ(caps.rows.level_count[c.row], 4);
  o = ObjectOptions{};
  o.min_level = 3, o.max_level = 1;  // min above max: min wins, the row is at least as long
  c = control_of(o, 1.f, 0, caps);
  EXPECT_EQ(c.min_level, 3);
  EXPECT_GE(caps.rows.level_count[c.row], 4);
  EXPECT_FALSE(options_valid(ObjectOptions{.priority = 0}));
  EXPECT_FALSE(options_valid(ObjectOptions{.lod_bias = NAN}));
}

TEST(ViewMasks, AnyViewMakesAnObjectVisibleAndTheFinestLevelWins) {
  std::vector<uint8_t> v0 = {1, 0, 0, 1}, v1 = {0, 1, 0, 1}, cull = {0, 0, 1, 0}, mask(4);
  std::span<uint8_t> views[2] = {v0, v1};
  EXPECT_EQ(combine_view_masks(mask, views, cull), 4u);
  EXPECT_EQ(mask, (std::vector<uint8_t>{1, 2, 3, 3}));
  EXPECT_EQ(v0[2], 1) << "never_cull objects count as seen by every view";
  std::vector<uint8_t> level = {3, 0, 2, 4}, other_level = {0, 1, 1, 2};
  std::vector<float> weight = {1, 0, 5, 2}, other_weight = {0, 3, 1, 7};
  combine_view_choice(level, weight, v0, other_level, other_weight, v1);
  EXPECT_EQ(level, (std::vector<uint8_t>{3, 1, 1, 2}));
  EXPECT_EQ(weight, (std::vector<float>{1, 3, 1, 2}));
  EXPECT_EQ(v0, (std::vector<uint8_t>{1, 1, 1, 1}));
}

TEST(MotionPath, WanderStaysInItsBoxAndMovesAtItsSpeed) {
  const float lo[3] = {-10, 0, -20}, hi[3] = {10, 5, 20};
  Transform start;
  start.position[0] = 3, start.position[1] = 1, start.position[2] = -4;
  const MotionSpec m{MotionKind::wander, 7.f};
  for (uint64_t seed = 0; seed < 20; ++seed) {
    Transform prev = motion_at(m, start, lo, hi, seed, 0);
    EXPECT_FLOAT_EQ(prev.position[0], 3);
    for (int k = 1; k < 400; ++k) {
      const Transform t = motion_at(m, start, lo, hi, seed, k * 0.05);
      ASSERT_GE(t.position[0], lo[0] - 1e-3f);
      ASSERT_LE(t.position[0], hi[0] + 1e-3f);
      ASSERT_GE(t.position[2], lo[2] - 1e-3f);
      ASSERT_LE(t.position[2], hi[2] + 1e-3f);
      EXPECT_EQ(t.position[1], 1.f);
      const float dx = t.position[0] - prev.position[0], dz = t.position[2] - prev.position[2];
      EXPECT_LE(std::sqrt(dx * dx + dz * dz), 7.f * 0.05f + 1e-3f);
      prev = t;
    }
  }
}

TEST(MotionPath, OrbitKeepsItsRadius) {
  const float lo[3] = {-10, 0, -10}, hi[3] = {10, 0, 10};
  Transform start;
  start.position[0] = 6;
  const MotionSpec m{MotionKind::orbit, 3.f};
  for (int k = 0; k < 50; ++k) {
    const Transform t = motion_at(m, start, lo, hi, 1, k * 0.3);
    EXPECT_NEAR(std::hypot(t.position[0], t.position[2]), 6.f, 1e-4f);
  }
  const Transform later = motion_at(m, start, lo, hi, 1, 1.0);
  EXPECT_NEAR(std::atan2(later.position[2], later.position[0]), 3.f / 6.f, 1e-4f) << "speed 3 along radius 6";
  EXPECT_EQ(motion_at(MotionSpec{}, start, lo, hi, 1, 5.0).position[0], 6.f) << "no motion stays put";
}

}  // namespace
}  // namespace lod
