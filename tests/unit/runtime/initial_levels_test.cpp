#include <gtest/gtest.h>

#include "runtime/initial_levels.h"
#include "unit/runtime/runtime_fixtures.h"

namespace lod {
namespace {

// One model: level k's object-space error; at focal 1000 and scale 1 its projected error at
// distance D is error * 1000 / D pixels.
const ModelTable kTable =
    test::table_of({{{1000, 0.f}, {500, 0.1f}, {250, 0.2f}, {120, 0.4f}, {60, 0.8f}}, {{64, 0.f}, {32, 1.f}}});

struct One {
  float distance;
  uint8_t prev = 0;
  uint8_t was_visible = 0;
  float scale = 1;
  uint32_t model = 0;
};

uint8_t choose(const One& o, float hysteresis = 0.25f) {
  std::vector<uint8_t> level = {0xee}, visible = {1}, prev = {o.prev}, was = {o.was_visible};
  const std::vector<float> distance = {o.distance}, scale = {o.scale};
  const std::vector<uint32_t> model = {o.model};
  InitialLevelParams p;
  p.focal_px = 1000;
  p.pixel_error = 1;
  p.hysteresis = hysteresis;
  EXPECT_EQ(choose_initial_levels(level, visible, prev, was, distance, scale, model, kTable, p), 1u);
  return level[0];
}

TEST(InitialLevels, NewlyVisibleTakesCoarsestLevelWithinPixelError) {
  EXPECT_EQ(choose({300}), 2);   // 0.667 px fits, 1.333 px does not
  EXPECT_EQ(choose({400}), 3);   // exactly 1 px fits
  EXPECT_EQ(choose({1e5f}), 4);  // far: coarsest
  EXPECT_EQ(choose({0.01f}), 0);  // level 0 always qualifies
  EXPECT_EQ(choose({300, 0, 0, 2.f}), 1);  // twice the scale looks like half the distance
  EXPECT_EQ(choose({999, 0, 0, 1, 1}), 0);
  EXPECT_EQ(choose({1000, 0, 0, 1, 1}), 1);
}

TEST(InitialLevels, HysteresisKeepsPreviousLevelInsideTheBand) {
  // At D = 350 level 2 projects 0.571 px and level 3 1.143 px: both are inside [1, 1.25].
  EXPECT_EQ(choose({350, 3, 1}), 3);
  EXPECT_EQ(choose({350, 2, 1}), 2);
  // Jittering around the level-3 threshold (D = 400) never changes the level either way.
  for (float d : {385.f, 395.f, 405.f, 415.f, 390.f}) {
    EXPECT_EQ(choose({d, 3, 1}), 3) << d;
  }
  for (float d : {405.f, 415.f, 450.f}) {
    EXPECT_EQ(choose({d, 3, 1}), 3) << d;
  }
}

TEST(InitialLevels, HysteresisChangesLevelOutsideTheBand) {
  EXPECT_EQ(choose({300, 3, 1}), 2);  // level 3 projects 1.33 px > 1.25: refine
  EXPECT_EQ(choose({350, 1, 1}), 2);  // level 2 fits: coarsen at once
  EXPECT_EQ(choose({350, 9, 1}), 3);  // a stale level beyond the chain lands in the band
  EXPECT_EQ(choose({350, 3, 0}), 2);  // not visible last frame: no band
  EXPECT_EQ(choose({350, 3, 1}, 0.f), 2);  // no hysteresis, no band
}

TEST(InitialLevels, TouchesOnlyVisibleObjectsAndSubRangesAgree) {
  const ObjectSet o = test::random_spheres(1000, 500, 3, 2, 9);
  std::vector<uint8_t> visible(o.size()), prev(o.size()), was(o.size());
  std::vector<float> distance(o.size());
  for (size_t i = 0; i < o.size(); ++i) {
    visible[i] = i % 5 != 0;
    was[i] = i % 3 != 0;
    prev[i] = static_cast<uint8_t>(i % 6);
    distance[i] = 10.f + std::abs(o.cx[i]) * 2.f;
  }
  InitialLevelParams p;
  std::vector<uint8_t> whole(o.size(), 0xee), parts(o.size(), 0xee);
  const size_t written = choose_initial_levels(whole, visible, prev, was, distance, o.scale, o.model, kTable, p);
  size_t sum = 0;
  for (size_t b = 0; b < o.size(); b += 128) {
    const size_t n = std::min<size_t>(128, o.size() - b);
    sum += choose_initial_levels(std::span(parts).subspan(b, n), std::span(visible).subspan(b, n),
                                 std::span(prev).subspan(b, n), std::span(was).subspan(b, n),
                                 std::span(distance).subspan(b, n), std::span(o.scale).subspan(b, n),
                                 std::span(o.model).subspan(b, n), kTable, p);
  }
  EXPECT_EQ(whole, parts);
  EXPECT_EQ(sum, written);
  for (size_t i = 0; i < o.size(); ++i) {
    if (!visible[i]) EXPECT_EQ(whole[i], 0xee);
    else EXPECT_LT(whole[i], kTable.level_count[o.model[i]]);
  }
}

}  // namespace
}  // namespace lod
