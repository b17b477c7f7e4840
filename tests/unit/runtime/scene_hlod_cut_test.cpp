// Scene HLOD cut: proxies drawn when their error projects under the threshold, opened
// otherwise, skipped outside the frustum, never drawn over an object that changed.
#include <gtest/gtest.h>

#include <cmath>

#include "runtime/scene_hlod_cut.h"

namespace lod {
namespace {

// Root (4 objects, error 8) with two children of 2 objects each (error 1), along x.
SceneHlodTree two_level_tree() {
  SceneHlodTree t;
  SceneHlodNode root;
  root.first_child = 1, root.child_count = 2, root.object_count = 4, root.error = 8;
  root.bounds = {{0, 0, 0}, 10};
  root.index_count = 30;
  SceneHlodNode a, b;
  a.depth = b.depth = 1;
  a.object_count = b.object_count = 2;
  b.first_object = 2;
  a.error = b.error = 1;
  a.bounds = {{-5, 0, 0}, 5};
  b.bounds = {{5, 0, 0}, 5};
  a.index_count = 36, b.index_count = 45;
  t.nodes = {root, a, b};
  t.objects.resize(4);
  return t;
}

View looking_from(float z) {
  View v;
  v.eye = {0, 0, z};
  v.target = {0, 0, 0};
  v.width = 1000, v.height = 1000;
  v.fov_y_deg = 90;  // focal = 500 px
  return v;
}

SceneHlodCut cut_from(const SceneHlodTree& t, const View& v, std::vector<uint8_t> ok = {1, 1, 1, 1}) {
  std::vector<uint32_t> bad(ok.size() + 1);
  scene_hlod_validity(bad, ok);
  SceneHlodCut c;
  select_scene_hlod_cut(c, t, frustum_of(v), v.eye, focal_pixels(v), 1.0f, bad);
  return c;
}

TEST(SceneHlodCut, FarDrawsTheRootNearerItsChildrenNearerStillNothing) {
  const SceneHlodTree t = two_level_tree();
  // Root: 8 * 500 / (d - 10) <= 1 from d = 4010.
  SceneHlodCut far = cut_from(t, looking_from(5000));
  ASSERT_EQ(far.drawn, std::vector<uint32_t>{0});
  EXPECT_EQ(far.triangles, 10u);
  EXPECT_EQ(far.objects, 4u);
  // Children: 1 * 500 / (d - 5) <= 1 from about d = 505.
  SceneHlodCut mid = cut_from(t, looking_from(1000));
  EXPECT_EQ(mid.drawn, (std::vector<uint32_t>{1, 2}));
  EXPECT_EQ(mid.triangles, 27u);
  EXPECT_TRUE(cut_from(t, looking_from(100)).drawn.empty()) << "close by, every object is its own";
}

TEST(SceneHlodCut, OutsideTheFrustumNothingIsDrawnOrOpened) {
  const SceneHlodTree t = two_level_tree();
  View v = looking_from(5000);
  v.target = {0, 0, 10000};  // looking away
  EXPECT_TRUE(cut_from(t, v).drawn.empty());
}

TEST(SceneHlodCut, AProxyOverAChangedObjectIsNeverDrawn) {
  const SceneHlodTree t = two_level_tree();
  const SceneHlodCut c = cut_from(t, looking_from(5000), {1, 1, 0, 1});  // object 2 moved
  EXPECT_EQ(c.drawn, std::vector<uint32_t>{1}) << "the root and the child holding object 2 are opened";
  EXPECT_EQ(c.stale, 2u);
  EXPECT_EQ(c.objects, 2u);
}

TEST(SceneHlodCut, AnEmptyTreeDrawsNothingAndTheEyeInsideANodeOpensIt) {
  SceneHlodCut c;
  std::vector<uint32_t> bad(1);
  select_scene_hlod_cut(c, SceneHlodTree{}, frustum_of(looking_from(10)), {0, 0, 10}, 500, 1, bad);
  EXPECT_TRUE(c.drawn.empty());
  const SceneHlodTree t = two_level_tree();
  EXPECT_TRUE(std::isinf(scene_proxy_pixels(t.nodes[0], {0, 0, 3}, 500)));
}

}  // namespace
}  // namespace lod
