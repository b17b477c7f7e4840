// The vertex hierarchy's second uvs, colours and authored normals travel with the positions as
// its uvs do (a split child starts at its parent's shown value, a collapse ends at the
// parent's), and published normals are renormalised.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "runtime/geomorph.h"
#include "runtime/vertex_normals.h"
#include "vd_fixture.h"

namespace lod {
namespace {

VertexTree attributed_square() {
  VertexTree t = test::square_tree();
  t.uvs1 = {0, 0, 1, 0, 1, 1, 0, 1, 0.5f, 0};
  t.colors = {1, 0, 0, 1, 0, 0, 1, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0.5f, 0, 0.5f, 1};  // node 4: red + blue
  const float s = std::sqrt(0.5f);
  t.normals = {s, 0, s, -s, 0, s, 0, 0, 1, 0, 0, 1, 0, 0, 1};  // node 4: its children's sum renormalised
  return t;
}

TEST(GeomorphAttributes, SecondUvsColoursAndNormalsMorphWithThePositions) {
  const VertexTree t = attributed_square();
  std::string msg;
  ASSERT_TRUE(validate_vertex_tree(t, &msg)) << msg;
  VertexMorph m;
  vertex_morph_init(m, t, 1.f);
  ASSERT_EQ(m.uv1.width, 2u);
  ASSERT_EQ(m.color.width, 4u);
  ASSERT_EQ(m.normal.width, 3u);
  const FrontEvent split[] = {{4, FrontEventKind::split}};
  vertex_morph_apply(m, t, split, 10.0);
  const uint32_t nodes[] = {0, 1, 2, 3};
  std::vector<float> uv1(2 * 5, -1.f), color(4 * 5, -1.f), normal(3 * 5, -1.f);
  vertex_morph_column(color, m, m.color, nodes, 10.0);
  EXPECT_EQ(color[0], 0.5f);  // child 0 at its parent's colour
  EXPECT_EQ(color[2], 0.5f);
  EXPECT_EQ(color[4], 0.5f);  // child 1 too
  EXPECT_EQ(color[8], 0.f);   // untouched node 2 shows its own (green)
  EXPECT_EQ(color[9], 1.f);
  vertex_morph_column(color, m, m.color, nodes, 10.5);
  EXPECT_FLOAT_EQ(color[0], 0.75f);  // halfway from 0.5 to 1
  EXPECT_FLOAT_EQ(color[6], 0.75f);  // child 1's blue, halfway from 0.5
  vertex_morph_column(color, m, m.color, nodes, 11.0);
  EXPECT_EQ(color[0], 1.f);  // arrived exactly
  EXPECT_EQ(color[2], 0.f);
  vertex_morph_column(uv1, m, m.uv1, nodes, 10.5);
  EXPECT_FLOAT_EQ(uv1[0], 0.25f);
  EXPECT_FLOAT_EQ(uv1[2], 0.75f);
  vertex_morph_column(normal, m, m.normal, nodes, 10.5);
  // A blend of two unit normals is shorter; renormalise makes it unit again.
  const std::span n0(normal.data(), 3);
  EXPECT_LT(n0[0] * n0[0] + n0[1] * n0[1] + n0[2] * n0[2], 1.f);
  EXPECT_EQ(renormalise(std::span(normal.data(), 12)), 4u);
  for (int v = 0; v < 4; ++v) {
    const float* q = &normal[3 * size_t(v)];
    EXPECT_NEAR(q[0] * q[0] + q[1] * q[1] + q[2] * q[2], 1.f, 1e-6f) << "vertex " << v;
  }
  EXPECT_GT(normal[0], 0.f);  // child 0 on its way to (s, 0, s)
  // A collapse ends both children at the parent's values and settles it there.
  const FrontEvent begin[] = {{4, FrontEventKind::collapse_begin}};
  vertex_morph_apply(m, t, begin, 20.0);
  vertex_morph_column(color, m, m.color, nodes, 21.0);
  EXPECT_EQ(color[0], 0.5f);
  EXPECT_EQ(color[4], 0.5f);
  const FrontEvent collapse[] = {{4, FrontEventKind::collapse}};
  vertex_morph_apply(m, t, collapse, 21.0);
  const uint32_t parent[] = {4};
  vertex_morph_column(normal, m, m.normal, parent, 21.0);
  EXPECT_EQ(normal[12], 0.f);
  EXPECT_EQ(normal[14], 1.f);
}

// The compact form writes the same values as the per-node one, in the order of the nodes given.
TEST(GeomorphAttributes, CompactMorphEqualsThePerNodeValuesInNodeOrder) {
  const VertexTree t = attributed_square();
  VertexMorph m;
  vertex_morph_init(m, t, 1.f);
  const FrontEvent split[] = {{4, FrontEventKind::split}};
  vertex_morph_apply(m, t, split, 10.0);
  const uint32_t nodes[] = {3, 1, 0, 2};
  std::vector<float> color(4 * 5), normal(3 * 5);
  vertex_morph_column(color, m, m.color, nodes, 10.25);
  vertex_morph_column(normal, m, m.normal, nodes, 10.25);
  std::vector<float> compact_color(4 * 4), compact_normal(3 * 4);
  const MorphOutput outputs[] = {{&m.color, compact_color}, {&m.normal, compact_normal}};
  vertex_morph_compact(outputs, m, nodes, 10.25);
  for (size_t k = 0; k < 4; ++k) {
    for (size_t c = 0; c < 4; ++c) EXPECT_EQ(compact_color[4 * k + c], color[4 * nodes[k] + c]) << k;
    for (size_t c = 0; c < 3; ++c) EXPECT_EQ(compact_normal[3 * k + c], normal[3 * nodes[k] + c]) << k;
  }
  EXPECT_FLOAT_EQ(compact_color[4 * 2], 0.625f);  // node 0's red a quarter of the way from 0.5 to 1
}

TEST(GeomorphAttributes, RenormaliseZeroesWhatHasNoDirection) {
  std::vector<float> n = {0, 0, 0, 3, 0, 4, NAN, 0, 1};
  EXPECT_EQ(renormalise(n), 1u);
  EXPECT_EQ(n, (std::vector<float>{0, 0, 0, 0.6f, 0, 0.8f, 0, 0, 0}));
}

TEST(GeomorphAttributes, TreeValidationRefusesBadColumnsByNode) {
  VertexTree t = attributed_square();
  std::string msg;
  t.colors[16] = 2.f;  // node 4's red outside its children's [0, 1]
  EXPECT_FALSE(validate_vertex_tree(t, &msg));
  EXPECT_NE(msg.find("node 4 colour lies outside its children's"), std::string::npos) << msg;
  t = attributed_square();
  t.normals[6] = 0.5f;  // node 2: length 1.118
  EXPECT_FALSE(validate_vertex_tree(t, &msg));
  EXPECT_NE(msg.find("node 2 normal has length"), std::string::npos) << msg;
  t = attributed_square();
  t.uvs1.pop_back();
  EXPECT_FALSE(validate_vertex_tree(t, &msg));
  EXPECT_NE(msg.find("hierarchy uv1s hold 9 values, expected 10"), std::string::npos) << msg;
  t = attributed_square();
  t.normals[6] = t.normals[7] = t.normals[8] = 0;  // zero: "unknown", allowed
  EXPECT_TRUE(validate_vertex_tree(t, &msg)) << msg;
}

}  // namespace
}  // namespace lod
