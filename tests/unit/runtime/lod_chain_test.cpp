#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "runtime/importance.h"
#include "runtime/lod_chain.h"
#include "runtime/model_table.h"
#include "runtime/object_set.h"
#include "unit/runtime/runtime_fixtures.h"

namespace lod {
namespace {

TEST(LevelOfTriangles, RoundsLog2ToTheNearestInteger) {
  EXPECT_EQ(level_of_triangles(5000), 12);  // Yu, Liang and Chen's examples
  EXPECT_EQ(level_of_triangles(2000), 11);
  EXPECT_EQ(level_of_triangles(0), 0);
  EXPECT_EQ(level_of_triangles(1), 0);
  EXPECT_EQ(level_of_triangles(3), 2);  // log2 3 = 1.58
  EXPECT_EQ(level_of_triangles(5), 2);  // 2.32
  EXPECT_EQ(level_of_triangles(1u << 20), 20);
  // 2^13.5 = 11585.24: the rounding boundary falls between these two.
  EXPECT_EQ(level_of_triangles(11585), 13);
  EXPECT_EQ(level_of_triangles(11586), 14);
  EXPECT_EQ(level_of_triangles(uint64_t{1} << 40), 40);
}

TEST(SpanOfLevelChanged, RegeneratesThePapersTableIForHappyBuddha) {
  // The happy buddha's 1,087,716 triangles at 50 % .. 0.37 % give levels 19 .. 12.
  const double ratios[] = {0.5, 0.25, 0.12, 0.06, 0.03, 0.015, 0.0075, 0.0037};
  int32_t levels[8];
  for (int k = 0; k < 8; ++k) {
    levels[k] = level_of_triangles(static_cast<uint64_t>(std::llround(1087716 * ratios[k])));
    EXPECT_EQ(levels[k], 19 - k);
  }
  // Table I as printed: rows are the target level 18..12, columns the source level 19..13.
  const int table[7][7] = {
      {19, 0, 0, 0, 0, 0, 0},          {38, 18, 0, 0, 0, 0, 0},       {57, 36, 17, 0, 0, 0, 0},
      {76, 54, 34, 16, 0, 0, 0},       {95, 72, 51, 32, 15, 0, 0},    {114, 90, 68, 48, 30, 14, 0},
      {133, 108, 85, 64, 45, 28, 13},
  };
  for (int row = 0; row < 7; ++row) {
    for (int col = 0; col <= row; ++col) {
      const int32_t from = levels[col], to = levels[row + 1];
      EXPECT_EQ(span_of_level_changed(from, to), table[row][col]) << from << " -> " << to;
    }
  }
}

TEST(SpanOfLevelChanged, IsSymmetricAndZeroWithoutChange) {
  EXPECT_EQ(span_of_level_changed(12, 12), 0);
  EXPECT_EQ(span_of_level_changed(11, 14), span_of_level_changed(14, 11));
  EXPECT_EQ(span_of_level_changed(0, 3), 9);
}

TEST(ValidateChain, AcceptsWellFormedChain) {
  std::string msg;
  EXPECT_TRUE(validate_chain(test::fan_chain("fan", {40, 20, 10, 3}), &msg)) << msg;
  EXPECT_TRUE(validate_chain(test::fan_chain("one", {1}), nullptr));
}

TEST(ValidateChain, RefusesIndexBeyondLevelVertexCountNamingIt) {
  LodChain c = test::fan_chain("fan", {6, 3});
  c.indices[c.levels[1].first_index + 4] = 9;  // level 1 has 5 vertices
  std::string msg;
  EXPECT_FALSE(validate_chain(c, &msg));
  EXPECT_EQ(msg, "level 1 index 4 references vertex 9 of 5");
}

TEST(ValidateChain, RefusesRangesOutsideBuffers) {
  LodChain c = test::fan_chain("fan", {6, 3});
  c.levels[1].index_count += 3;
  std::string msg;
  EXPECT_FALSE(validate_chain(c, &msg));
  EXPECT_NE(msg.find("level 1 indices"), std::string::npos) << msg;

  c = test::fan_chain("fan", {6, 3});
  c.levels[0].first_vertex = 0xffffffffu;  // must not wrap around
  EXPECT_FALSE(validate_chain(c, &msg));
  EXPECT_NE(msg.find("level 0 vertices"), std::string::npos) << msg;

  c = test::fan_chain("fan", {6, 3});
  c.levels[0].index_count = 16;
  EXPECT_FALSE(validate_chain(c, &msg));
  EXPECT_NE(msg.find("not a multiple of 3"), std::string::npos) << msg;
}

TEST(ValidateChain, RefusesIncreasingTrianglesAndDecreasingErrors) {
  LodChain c = test::fan_chain("fan", {6, 3, 4});
  std::string msg;
  EXPECT_FALSE(validate_chain(c, &msg));
  EXPECT_NE(msg.find("level 2 has 4 triangles, more than level 1"), std::string::npos) << msg;

  c = test::fan_chain("fan", {6, 3, 2});
  c.levels[2].error = c.levels[1].error * 0.5f;
  EXPECT_FALSE(validate_chain(c, &msg));
  EXPECT_NE(msg.find("level 2 error"), std::string::npos) << msg;
}

TEST(ValidateChain, RefusesNonFiniteValues) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  LodChain c = test::fan_chain("fan", {6, 3});
  c.positions[7] = nan;
  std::string msg;
  EXPECT_FALSE(validate_chain(c, &msg));
  EXPECT_EQ(msg, "vertex 2 has a non-finite position");

  c = test::fan_chain("fan", {6, 3});
  c.normals[0] = std::numeric_limits<float>::infinity();
  EXPECT_FALSE(validate_chain(c, &msg));

  c = test::fan_chain("fan", {6, 3});
  c.levels[1].error = nan;
  EXPECT_FALSE(validate_chain(c, &msg));

  c = test::fan_chain("fan", {6, 3});
  c.levels[0].bounds.radius = -1;
  EXPECT_FALSE(validate_chain(c, &msg));
}

TEST(ValidateChain, RefusesStructuralNonsense) {
  std::string msg;
  EXPECT_FALSE(validate_chain(LodChain{}, &msg));
  EXPECT_EQ(msg, "chain has no levels");

  LodChain c = test::fan_chain("fan", {6, 3});
  c.levels[1].level = 7;
  EXPECT_FALSE(validate_chain(c, &msg));
  EXPECT_NE(msg.find("l = 7"), std::string::npos) << msg;

  c = test::fan_chain("fan", {6, 3});
  c.normals.pop_back();
  EXPECT_FALSE(validate_chain(c, &msg));

  std::vector<uint32_t> many(kMaxLevels + 1, 1);
  EXPECT_FALSE(validate_chain(test::fan_chain("long", many), &msg));
  EXPECT_NE(msg.find("at most 16"), std::string::npos) << msg;
}

TEST(ModelTable, FlattensChainsBackToBack) {
  const std::vector<LodChain> chains = {test::fan_chain("a", {8, 4, 2}), test::fan_chain("b", {5000, 2000})};
  const ModelTable t = build_model_table(chains);
  ASSERT_EQ(t.model_count(), 2u);
  EXPECT_EQ(t.first_level, (std::vector<uint32_t>{0, 3}));
  EXPECT_EQ(t.level_count, (std::vector<uint8_t>{3, 2}));
  EXPECT_EQ(t.triangles, (std::vector<uint32_t>{8, 4, 2, 5000, 2000}));
  EXPECT_EQ(t.level_l, (std::vector<int32_t>{3, 2, 1, 12, 11}));
  EXPECT_FLOAT_EQ(t.error[4], 0.125f);
  EXPECT_FLOAT_EQ(t.radius[1], 1.75f);
}

TEST(ObjectColumns, ResizeKeepsEveryColumnTheSameLength) {
  ObjectSet o;
  o.resize(7);
  for (size_t s : {o.model.size(), o.x.size(), o.y.size(), o.z.size(), o.scale.size(), o.yaw.size(), o.cx.size(),
                   o.cy.size(), o.cz.size(), o.radius.size()})
    EXPECT_EQ(s, 7u);
  EXPECT_EQ(o.size(), 7u);
  ObjectState st;
  st.resize(5);
  for (size_t s : {st.visible.size(), st.distance.size(), st.area.size(), st.weight.size(), st.level.size(),
                   st.prev_level.size(), st.was_visible.size()})
    EXPECT_EQ(s, 5u);
}

}  // namespace
}  // namespace lod

namespace lod {
namespace {

// Fan chains: vertex v of level k morphs into vertex min(v, last) of level k + 1.
LodChain fan_with_targets(const std::vector<uint32_t>& triangles) {
  LodChain c = test::fan_chain("fan", triangles);
  for (size_t k = 0; k + 1 < c.levels.size(); ++k)
    for (uint32_t v = 0; v < c.levels[k].vertex_count; ++v)
      c.morph_targets.push_back(std::min(v, c.levels[k + 1].vertex_count - 1));
  return c;
}

TEST(ValidateChain, AcceptsMorphTargetsOnePerVertexButTheLastLevel) {
  const LodChain c = fan_with_targets({6, 3, 1});
  EXPECT_EQ(c.morph_targets.size(), 8u + 5u);
  EXPECT_EQ(morph_target_count(c), 13u);
  std::string msg;
  EXPECT_TRUE(validate_chain(c, &msg)) << msg;
}

TEST(ValidateChain, RefusesMorphTargetsOfTheWrongSizeOrRange) {
  LodChain c = fan_with_targets({6, 3, 1});
  c.morph_targets.pop_back();
  std::string msg;
  EXPECT_FALSE(validate_chain(c, &msg));
  EXPECT_EQ(msg, "morph targets hold 12 entries, the levels but the last have 13 vertices");
  c = fan_with_targets({6, 3, 1});
  c.morph_targets[8 + 4] = 3;  // level 2 has 3 vertices
  EXPECT_FALSE(validate_chain(c, &msg));
  EXPECT_EQ(msg, "level 1 vertex 4 morphs into vertex 3 of level 2's 3");
}

TEST(ComposeMorphTargets, FollowsEveryLevelInBetween) {
  LodChain c = fan_with_targets({6, 3, 1});
  c.morph_targets[0 + 7] = 2;  // level 0 vertex 7 -> level 1 vertex 2
  c.morph_targets[8 + 2] = 0;  // level 1 vertex 2 -> level 2 vertex 0
  std::vector<uint32_t> out(8);
  compose_morph_targets(out, c, 0, 2);
  EXPECT_EQ(out, (std::vector<uint32_t>{0, 1, 0, 2, 2, 2, 2, 0}));
  compose_morph_targets(out, c, 0, 0);
  EXPECT_EQ(out, (std::vector<uint32_t>{0, 1, 2, 3, 4, 5, 6, 7}));
  std::vector<uint32_t> one(5);
  compose_morph_targets(one, c, 1, 2);
  EXPECT_EQ(one, (std::vector<uint32_t>{0, 1, 0, 2, 2}));
}

}  // namespace
}  // namespace lod
