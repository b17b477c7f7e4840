// Level blends and the view-dependent budget share: the state machines the frame graph runs,
// tested as runtime stages on hand-made columns.
#include "runtime/level_blend.h"

#include <gtest/gtest.h>

#include "runtime/vd_share.h"
#include "unit/runtime/runtime_fixtures.h"

namespace lod {
namespace {

struct Blend {
  ModelTable models = test::table_of({{{1000, 0}, {500, 1}, {250, 2}, {125, 3}}});
  std::vector<uint8_t> blends = {1};
  std::vector<double> start = {-1e300};
  std::vector<uint8_t> from = {0}, prev = {0}, was = {0};
  std::vector<uint32_t> ids = {0}, model = {0};
  std::vector<uint8_t> level = {0}, from_level = {0};
  std::vector<float> morph = {0};

  BlendTotals run(uint8_t new_level, double now) {
    level[0] = new_level;
    const BlendTotals t = advance_level_blends(morph, from_level, ids, level, model, {start, from, prev, was}, blends,
                                               models, now, 1.0f);
    prev[0] = new_level;  // what publish does after the frame
    was[0] = 1;
    return t;
  }
};

TEST(LevelBlend, NewlyVisibleObjectsAppearSettled) {
  Blend b;
  b.prev[0] = 3;  // stale history of an object not visible last frame
  b.run(1, 5.0);
  EXPECT_EQ(b.morph[0], 1.f);
  EXPECT_EQ(b.from_level[0], 1);
}

TEST(LevelBlend, AChangeBlendsOverItsSecondsAndSettles) {
  Blend b;
  b.run(1, 0.0);
  BlendTotals t = b.run(2, 10.0);  // coarsens at t = 10
  EXPECT_EQ(b.morph[0], 0.f);
  EXPECT_EQ(b.from_level[0], 1);
  EXPECT_EQ(t.morphing, 1u);
  EXPECT_EQ(t.extra_tris, 250u) << "drawing level 1 instead of 2";
  b.run(2, 10.25);
  EXPECT_FLOAT_EQ(b.morph[0], 0.25f);
  t = b.run(2, 11.5);
  EXPECT_EQ(b.morph[0], 1.f);
  EXPECT_EQ(b.from_level[0], 2) << "settled: from = to";
  EXPECT_EQ(t.morphing, 0u);
}

TEST(LevelBlend, GoingBackMidBlendRunsTheSameBlendBackwards) {
  Blend b;
  b.run(1, 0.0);
  b.run(2, 10.0);
  b.run(2, 10.3);                 // 30 % of the way to level 2
  b.run(1, 10.4);                 // back to level 1 at 40 %
  EXPECT_NEAR(b.morph[0], 0.6f, 1e-5f) << "continues from the same shape";
  EXPECT_EQ(b.from_level[0], 2);
}

TEST(LevelBlend, ModelsWithoutMorphTargetsNeverBlend) {
  Blend b;
  b.blends[0] = 0;
  b.run(1, 0.0);
  const BlendTotals t = b.run(3, 1.0);
  EXPECT_EQ(b.from_level[0], 3);
  EXPECT_EQ(t.morphing, 0u);
}

TEST(VdShare, RegionsSplitTheCapAndNeverPassIt) {
  std::vector<uint32_t> caps(1), tris = {500};
  share_region_caps(caps, tris, 1000);
  EXPECT_EQ(caps[0], 1000u) << "one region gets the cap";
  caps.assign(4, 0);
  tris = {100, 200, 300, 0};
  share_region_caps(caps, tris, 1000);
  uint64_t sum = 0;
  for (uint32_t c : caps) sum += c;
  EXPECT_LE(sum, 1000u + 4);
  EXPECT_EQ(caps[1] - caps[0], 100u) << "each keeps what it has and grows by the same room";
  tris = {600, 600, 0, 0};  // already over the cap: nobody grows
  share_region_caps(caps, tris, 1000);
  EXPECT_EQ(caps[0], 600u);
  EXPECT_EQ(caps[2], 1u);
  EXPECT_EQ(vd_cap_of_share(1000), 1116u);
}

}  // namespace
}  // namespace lod
