// lod-viewer draws HLOD models through their cut: the draw list built from the frame's drawn
// layers and opened boundary patches (CPU), and whole flights under xvfb where what is drawn
// equals what the frame selected, node by node, with the nodes read by the viewer itself.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

#include "test_support.h"
#include "viewer/picture_checks.h"
#include "viewer/hlod_draw_list.h"
#include "viewer/viewer_harness.h"

namespace {

using lod::HlodNode;
using lod::viewer::HlodDrawList;
using lod::viewer::kHlodBoundary;

HlodNode node(int parent, uint8_t depth, uint32_t first_child, uint8_t children, uint32_t tris) {
  HlodNode n;
  n.parent = parent;
  n.depth = depth;
  n.first_child = first_child;
  n.child_count = children;
  n.layer_count = 3;
  for (uint32_t l = 0; l < 3; ++l) n.layers[l].triangles = tris >> l;
  n.boundary_triangles = children ? 10 : 0;
  return n;
}

lod::HlodModels two_leaf_model() {
  lod::HlodModels m;
  lod::HlodTree t;
  t.nodes = {node(-1, 0, 1, 2, 400), node(0, 1, 0, 0, 200), node(0, 1, 0, 0, 100)};
  t.nodes[1].bounds.center[1] = -1.5f;
  m.trees.push_back(t);
  lod::Transform tr;
  tr.position[0] = 1;
  tr.position[1] = 2;
  tr.position[2] = 3;
  tr.scale = 2;
  m.transforms.push_back(tr);
  m.files.emplace_back("unused.hlod");
  return m;
}

TEST(ViewerHlodDrawList, DrawsLayersAndOpenedPatchesAndRefusesWhatTheTreesDoNotHave) {
  const lod::HlodModels models = two_leaf_model();
  lod::Frame f;
  f.hlod_drawn = {{0, 1, 0}, {0, 2, 2}, {1, 0, 0}, {0, 5, 0}, {0, 1, 3}};
  f.hlod_opened = {{0, 0}, {0, 1}};
  HlodDrawList list;
  lod::viewer::build_hlod_draw_list(f, models, list);
  ASSERT_EQ(list.draws.size(), 3u);
  EXPECT_EQ(list.rejected, 4u) << "unknown model, unknown node, layer past layer_count, an opened leaf";
  EXPECT_EQ(list.draws[0].node, 1u);
  EXPECT_EQ(list.draws[0].layer, 0u);
  EXPECT_EQ(list.draws[0].triangles, 200u);
  EXPECT_EQ(list.draws[0].depth, 1u);
  EXPECT_EQ(list.draws[1].triangles, 25u);  // layer 2 of a 100-triangle leaf
  EXPECT_EQ(list.draws[2].layer, kHlodBoundary);
  EXPECT_EQ(list.draws[2].triangles, 10u);
  EXPECT_EQ(list.draws[2].depth, 0u);
  EXPECT_EQ(list.triangles, 235u);
  EXPECT_FLOAT_EQ(list.draws[0].transform.position_scale[0], 1.f);
  EXPECT_FLOAT_EQ(list.draws[0].transform.position_scale[3], 2.f);
  EXPECT_FLOAT_EQ(list.draws[0].center[1], -1.5f) << "the node's bounding sphere centre, for the blend order";

  f.hlod_drawn.clear();  // reused: nothing of the last frame stays
  f.hlod_opened.clear();
  lod::viewer::build_hlod_draw_list(f, models, list);
  EXPECT_TRUE(list.draws.empty());
  EXPECT_EQ(list.triangles, 0u);
  EXPECT_EQ(list.rejected, 0u);
}

TEST(ViewerHlodDrawList, AnUndrawableTransformIsRefused) {
  lod::HlodModels models = two_leaf_model();
  models.transforms[0].scale = 0;
  lod::Frame f;
  f.hlod_drawn = {{0, 1, 0}};
  HlodDrawList list;
  lod::viewer::build_hlod_draw_list(f, models, list);
  EXPECT_TRUE(list.draws.empty());
  EXPECT_EQ(list.rejected, 1u);
}

// A 14,400-triangle ball baked to a .hlod of leaves of <= 400 vertices, flown at from far
// away to close by (and held there while the pager loads the finer nodes) under a stream budget smaller than the tree.
const char* kRun = "[run]\nframes = 40\nthreads = 2\nrate_hz = 60\n[budget]\ntriangles = 1000000\n"
                   "[lod]\npixel_error = 1.0\n[stream]\nbudget_mb = 1\nloader_threads = 2\n";
const char* kFlight = R"([camera]
fov_deg = 60
width = 1280
height = 720
path = "keyframes"
near = 0.1
far = 2000.0
[[camera.keyframe]]
frame = 0
position = [0.0, 0.0, 600.0]
look_at = [0.0, 0.0, 0.0]
[[camera.keyframe]]
frame = 20
position = [0.0, 0.0, 14.0]
look_at = [0.0, 0.0, 0.0]
[[camera.keyframe]]
frame = 39
position = [2.0, 0.0, 14.0]
look_at = [0.0, 0.0, 0.0]
)";
const char* kBallModel = R"([[model]]
name = "ball"
file = "ball.off"
hlod = true
min_verts = 400
)";

TEST(ViewerHlod, DrawsEveryFramesCutAndRefinesItOnTheWayIn) {
  LOD_REQUIRE_XVFB();
  const auto scene = lod::test::write_viewer_scene("hlod", kRun, kFlight, lod::test::one_object_at_origin("ball", 10),
                                                   kBallModel);
  std::ofstream(scene.dir / "ball.off") << lod::test::sphere_off(60, 120);
  const auto shot = lod::test::take_screenshot(scene, "hlod", "--frames 40 --width 320 --height 180 --colour-by-level");
  ASSERT_EQ(shot.run.exit_code, 0) << shot.run.output;
  ASSERT_TRUE(shot.stats_read);
  const lod::test::CsvTable& t = shot.stats;
  ASSERT_EQ(t.rows.size(), 40u);
  double most_draws = 0;
  for (size_t i = 0; i < t.rows.size(); ++i) {
    SCOPED_TRACE("viewer frame " + std::to_string(i));
    EXPECT_EQ(t.get(i, "whole"), 1);
    EXPECT_GT(t.get(i, "hlod_nodes"), 0) << "the ball is in view on every frame";
    EXPECT_EQ(t.get(i, "hlod_missing"), 0);
    EXPECT_EQ(t.get(i, "drawn"), t.get(i, "tris_selected")) << "the cut is all that is selected";
    EXPECT_EQ(t.get(i, "hlod_drawn"), t.get(i, "drawn"));
    EXPECT_EQ(t.get(i, "gpu_primitives"), t.get(i, "drawn"));
    EXPECT_LE(t.get(i, "resident_bytes"), 1 << 20);
    EXPECT_GT(t.get(i, "gpu_node_bytes"), 0);
    most_draws = std::max(most_draws, t.get(i, "hlod_draws"));
  }
  EXPECT_GT(t.get(39, "drawn"), t.get(0, "drawn")) << "close by, the cut is finer";
  EXPECT_GT(most_draws, 1) << "the root alone was drawn all the way in";

  ASSERT_TRUE(shot.image_read);
  EXPECT_FALSE(lod::test::is_background(shot.image.at(shot.image.width / 2, shot.image.height / 2))) << "the ball is drawn";
}

}  // namespace
