#include "runtime/vertex_front.h"

#include <gtest/gtest.h>

#include <cmath>

#include "vd_fixture.h"

namespace lod {
namespace {

std::vector<uint32_t> tri(const VertexFront& f, uint32_t s) {
  return {f.tri_indices[3 * s], f.tri_indices[3 * s + 1], f.tri_indices[3 * s + 2]};
}

// Camera on the square's front side (+z), `distance` away from its middle.
FrontView facing_view(float distance) {
  View v;
  v.eye = {0.5f, 0.5f, distance};
  v.target = {0.5f, 0.5f, 0};
  v.near_plane = 0.01f;
  v.far_plane = 1000;
  const float origin[3] = {0, 0, 0};
  return front_view_of(v, origin, 1.f, 0.f);
}

TEST(VertexTree, HandBuiltSquareValidatesAndBrokenOnesDoNot) {
  VertexTree t = test::square_tree();
  std::string msg;
  EXPECT_TRUE(validate_vertex_tree(t, &msg)) << msg;
  VertexTree bad = t;
  bad.parent[1] = 2;  // a leaf as parent
  EXPECT_FALSE(validate_vertex_tree(bad, &msg));
  EXPECT_NE(msg.find("node 1"), std::string::npos) << msg;
  bad = t;
  bad.deps[0] = 4;  // depends on itself
  EXPECT_FALSE(validate_vertex_tree(bad, &msg));
  bad = t;
  bad.face_leaves[5] = 17;
  EXPECT_FALSE(validate_vertex_tree(bad, &msg));
  EXPECT_NE(msg.find("face 1 references vertex 17 of 4"), std::string::npos) << msg;
  bad = t;
  bad.radius[4] = std::nanf("");
  EXPECT_FALSE(validate_vertex_tree(bad, &msg));
}

TEST(VertexFront, InitShowsTheBaseMesh) {
  const VertexTree t = test::square_tree();
  VertexFront f;
  front_init(f, t, 1);
  ASSERT_EQ(f.tri_count, 1u);
  EXPECT_EQ(tri(f, 0), (std::vector<uint32_t>{4, 2, 3}));
  EXPECT_EQ(f.active_count, 3u);
  std::string msg;
  EXPECT_TRUE(check_front(f, t, EdgeCheck::oriented, &msg)) << msg;
}

TEST(VertexFront, RefineAllGivesTheInputAndCoarsenAllTheBase) {
  const VertexTree t = test::square_tree();
  VertexFront f;
  front_init(f, t, 1);
  front_refine_all(f, t);
  ASSERT_EQ(f.tri_count, 2u);
  EXPECT_EQ(tri(f, f.face_slot[0]), (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_EQ(tri(f, f.face_slot[1]), (std::vector<uint32_t>{0, 2, 3}));
  std::string msg;
  EXPECT_TRUE(check_front(f, t, EdgeCheck::oriented, &msg)) << msg;
  front_coarsen_all(f, t);
  ASSERT_EQ(f.tri_count, 1u);
  EXPECT_EQ(tri(f, 0), (std::vector<uint32_t>{4, 2, 3}));
  EXPECT_TRUE(check_front(f, t, EdgeCheck::oriented, &msg)) << msg;
}

TEST(VertexFront, CheckCatchesBrokenFronts) {
  const VertexTree t = test::square_tree();
  VertexFront f;
  front_init(f, t, 1);
  front_refine_all(f, t);
  std::string msg;
  // An open square is not closed: its border edges have one face.
  EXPECT_FALSE(check_front(f, t, EdgeCheck::closed, &msg));
  EXPECT_NE(msg.find("closed"), std::string::npos) << msg;

  VertexFront g = f;
  g.tri_indices[3 * g.face_slot[1] + 1] = 3;  // (0, 3, 3): degenerate and wrong corner
  EXPECT_FALSE(check_front(g, t, EdgeCheck::oriented, &msg));
  g = f;
  std::swap(g.tri_indices[3 * g.face_slot[1] + 1], g.tri_indices[3 * g.face_slot[1] + 2]);  // flipped
  EXPECT_FALSE(check_front(g, t, EdgeCheck::oriented, &msg));
  g = f;
  g.tri_indices[0] = 4;  // an inactive vertex
  EXPECT_FALSE(check_front(g, t, EdgeCheck::oriented, &msg));
  EXPECT_NE(msg.find("inactive vertex 4"), std::string::npos) << msg;
  g = f;
  g.tri_count = 1;  // a face with three distinct corners goes missing
  EXPECT_FALSE(check_front(g, t, EdgeCheck::oriented, &msg));
  g = f;
  g.state[4] = VertexFront::kActive;  // two active nodes above one leaf
  EXPECT_FALSE(check_front(g, t, EdgeCheck::oriented, &msg));
}

TEST(VertexFront, SplitsWhenCloseAndMergesWhenFar) {
  const VertexTree t = test::square_tree();
  VertexFront f;
  front_init(f, t, 1);
  // Error 0.1 at distance ~2 is ~30 pixels at 720p: split.
  FrontStats s = front_update(f, t, facing_view(2), FrontParams{});
  EXPECT_EQ(s.splits, 1u);
  EXPECT_EQ(f.tri_count, 2u);
  ASSERT_EQ(f.frame_events().size(), 1u);
  EXPECT_EQ(f.frame_events()[0].node, 4u);
  EXPECT_EQ(f.frame_events()[0].kind, FrontEventKind::split);
  // At distance 500 it is well under a pixel: merge back.
  s = front_update(f, t, facing_view(500), FrontParams{});
  EXPECT_EQ(s.collapses, 1u);
  EXPECT_EQ(f.tri_count, 1u);
  std::string msg;
  EXPECT_TRUE(check_front(f, t, EdgeCheck::oriented, &msg)) << msg;
}

TEST(VertexFront, BackFacingAndOutsideStayCoarse) {
  const VertexTree t = test::square_tree();
  VertexFront f;
  front_init(f, t, 1);
  // Behind the square (normals point +z, the eye is at -z): nothing to refine.
  View v;
  v.eye = {0.5f, 0.5f, -2};
  v.target = {0.5f, 0.5f, 0};
  const float origin[3] = {0, 0, 0};
  EXPECT_EQ(front_update(f, t, front_view_of(v, origin, 1.f, 0.f), FrontParams{}).splits, 0u);
  // In front but looking away.
  v.eye = {0.5f, 0.5f, 2};
  v.target = {0.5f, 0.5f, 4};
  EXPECT_EQ(front_update(f, t, front_view_of(v, origin, 1.f, 0.f), FrontParams{}).splits, 0u);
  EXPECT_EQ(f.tri_count, 1u);
}

TEST(VertexFront, TriangleCapBlocksASplit) {
  const VertexTree t = test::square_tree();
  VertexFront f;
  front_init(f, t, 1);
  FrontParams p;
  p.max_triangles = 1;
  const FrontStats s = front_update(f, t, facing_view(2), p);
  EXPECT_EQ(s.splits, 0u);
  EXPECT_EQ(s.blocked, 1u);
  EXPECT_EQ(f.tri_count, 1u);
}

TEST(VertexFront, DeferredCollapseWaitsItsDelay) {
  const VertexTree t = test::square_tree();
  VertexFront f;
  front_init(f, t, 1);
  FrontParams p;
  p.collapse_delay = 0.5f;
  front_update(f, t, facing_view(2), p);
  ASSERT_EQ(f.tri_count, 2u);
  p.time = 1;
  FrontStats s = front_update(f, t, facing_view(500), p);
  EXPECT_EQ(s.collapses, 0u);
  ASSERT_EQ(f.frame_events().size(), 1u);
  EXPECT_EQ(f.frame_events()[0].kind, FrontEventKind::collapse_begin);
  EXPECT_EQ(f.tri_count, 2u);
  p.time = 1.3;
  EXPECT_EQ(front_update(f, t, facing_view(500), p).collapses, 0u);
  p.time = 1.6;
  s = front_update(f, t, facing_view(500), p);
  EXPECT_EQ(s.collapses, 1u);
  EXPECT_EQ(f.tri_count, 1u);
}

TEST(VertexFront, DeferredCollapseIsCancelledWhenDetailIsWantedAgain) {
  const VertexTree t = test::square_tree();
  VertexFront f;
  front_init(f, t, 1);
  FrontParams p;
  p.collapse_delay = 0.5f;
  front_update(f, t, facing_view(2), p);
  p.time = 1;
  front_update(f, t, facing_view(500), p);
  p.time = 1.6;
  front_update(f, t, facing_view(2), p);  // close again before it merged
  EXPECT_EQ(f.tri_count, 2u);
  EXPECT_LT(f.pending_until[0], 0);
  bool cancelled = false;
  for (const FrontEvent& e : f.frame_events()) cancelled |= e.kind == FrontEventKind::collapse_cancel;
  EXPECT_TRUE(cancelled);
}

TEST(VertexFront, FrontViewUndoesTheObjectTransform) {
  View v;
  v.eye = {10, 0, 4};
  v.target = {10, 0, 0};
  const float pos[3] = {10, 0, 0};
  const FrontView fv = front_view_of(v, pos, 2, float(M_PI / 2));
  // World offset (0, 0, 4) -> R_y(-90 deg) -> (-4, 0, 0) -> / 2.
  EXPECT_NEAR(fv.eye[0], -2, 1e-5);
  EXPECT_NEAR(fv.eye[1], 0, 1e-5);
  EXPECT_NEAR(fv.eye[2], 0, 1e-5);
  // The object's origin is in front of the camera: inside every plane.
  for (const auto& pl : fv.planes) EXPECT_GT(pl[3], 0);
  // Object-space error over object-space distance is already scale free.
  EXPECT_NEAR(fv.focal_pixels, focal_pixels(v), 1e-3);
}

// The object-space planes are built from the camera's basis, not extracted from the clip
// matrix: they must still be the culling frustum's planes, scaled into object units.
TEST(VertexFront, FrontViewPlanesAreTheFrustumPlanesInObjectSpace) {
  View v;
  v.eye = {3, 2, 9};
  v.target = {-1, 0.5f, 1};
  v.width = 1600;
  v.height = 900;
  v.fov_y_deg = 50;
  v.near_plane = 0.1f;
  v.far_plane = 400;
  const Frustum world = frustum_of(v);
  const float pos[3] = {1, -2, 0.5f};
  const float scale = 2.5f, yaw = 0.7f;
  const FrontView fv = front_view_of(v, pos, scale, yaw);
  const float c = std::cos(yaw), s = std::sin(yaw);
  for (int i = 0; i < 50; ++i) {
    const glm::vec3 po(std::sin(1.3f * i) * 3, std::cos(0.7f * i) * 2, std::sin(0.31f * i + 1) * 4);
    // world = R_y(yaw) (scale p) + position; R_y(t) maps (x, z) to (c x + s z, -s x + c z).
    const glm::vec3 ps = scale * po;
    const glm::vec3 pw(c * ps.x + s * ps.z + pos[0], ps.y + pos[1], -s * ps.x + c * ps.z + pos[2]);
    for (int k = 0; k < 6; ++k) {
      const glm::vec4& pl = world.planes[k];
      const float dw = pl.x * pw.x + pl.y * pw.y + pl.z * pw.z + pl.w;
      const float* q = fv.planes[k];
      const float dobj = q[0] * po.x + q[1] * po.y + q[2] * po.z + q[3];
      EXPECT_NEAR(dobj * scale, dw, 2e-3f * (1 + std::abs(dw))) << "plane " << k << " point " << i;
    }
  }
}

}  // namespace
}  // namespace lod

namespace lod {
namespace {

TEST(VertexFront, CompactMeshIndexesActiveVerticesOnly) {
  const VertexTree t = test::square_tree();
  VertexFront f;
  front_init(f, t, 1);
  std::vector<float> pos(3 * 5);
  std::vector<uint32_t> idx(3 * 2);
  ASSERT_EQ(front_compact_mesh(pos, idx, f, t, {}), 1u);
  std::string msg;
  EXPECT_TRUE(check_triangles(std::span(idx.data(), 3), f.active_count, EdgeCheck::oriented, &msg)) << msg;
  // The base triangle (4, 2, 3) through the compact vertex list gives the node positions.
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(pos[3 * idx[j] + k], t.positions[3 * f.tri_indices[j] + k]);
  front_refine_all(f, t);
  ASSERT_EQ(front_compact_mesh(pos, idx, f, t, {}), 2u);
  EXPECT_TRUE(check_triangles(idx, 4, EdgeCheck::oriented, &msg)) << msg;
  EXPECT_FALSE(triangles_closed(idx));
  EXPECT_EQ(edge_check_of(idx), EdgeCheck::oriented);
}

TEST(VertexFront, CheckTrianglesCatchesBadLists) {
  std::string msg;
  const std::vector<uint32_t> tetra = {0, 1, 2, 0, 3, 1, 1, 3, 2, 2, 3, 0};
  EXPECT_TRUE(check_triangles(tetra, 4, EdgeCheck::closed, &msg)) << msg;
  EXPECT_TRUE(triangles_closed(tetra));
  EXPECT_EQ(edge_check_of(tetra), EdgeCheck::closed);
  EXPECT_FALSE(check_triangles(tetra, 3, EdgeCheck::closed, &msg));  // index 3 out of range
  EXPECT_NE(msg.find("references vertex 3 of 3"), std::string::npos) << msg;
  std::vector<uint32_t> open(tetra.begin(), tetra.end() - 3);
  EXPECT_FALSE(check_triangles(open, 4, EdgeCheck::closed, &msg));  // a hole: crack
  EXPECT_TRUE(check_triangles(open, 4, EdgeCheck::oriented, &msg));
  std::vector<uint32_t> flipped = tetra;
  std::swap(flipped[1], flipped[2]);
  EXPECT_FALSE(check_triangles(flipped, 4, EdgeCheck::oriented, &msg));
  EXPECT_TRUE(check_triangles(flipped, 4, EdgeCheck::corners, &msg)) << msg;  // only corners checked
  EXPECT_EQ(edge_check_of(flipped), EdgeCheck::corners);
  const std::vector<uint32_t> degenerate = {0, 1, 1};
  EXPECT_FALSE(check_triangles(degenerate, 4, EdgeCheck::oriented, &msg));
}

}  // namespace
}  // namespace lod
