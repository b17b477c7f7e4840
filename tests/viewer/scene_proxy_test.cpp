// lod-viewer draws the scene HLOD's proxies the frame names, so what is drawn (and what the GL
// counts) still equals what the frame selected, proxies included.
#include <gtest/gtest.h>

#include <algorithm>

#include "viewer/proxy_draw_list.h"
#include "viewer/viewer_harness.h"

namespace {

TEST(ViewerProxyDrawList, DrawsTheNamedProxiesAndRefusesUnknownOnes) {
  lod::SceneHlodTree t;
  t.nodes.resize(3);
  t.nodes[1].depth = 1;
  t.nodes[1].first_index = 30, t.nodes[1].index_count = 12, t.nodes[1].first_vertex = 7;
  t.nodes[2].index_count = 6;
  lod::Frame f;
  f.scene_proxies = {1, 9, 2};
  lod::viewer::ProxyDrawList list;
  lod::viewer::build_proxy_draw_list(f, t, list);
  ASSERT_EQ(list.draws.size(), 2u);
  EXPECT_EQ(list.rejected, 1u);
  EXPECT_EQ(list.triangles, 6u);
  EXPECT_EQ(list.draws[0].first_index, 30u);
  EXPECT_EQ(list.draws[0].first_vertex, 7u);
  EXPECT_EQ(list.draws[0].depth, 1u);
}

const char* kRun = "[run]\nframes = 12\nthreads = 2\nrate_hz = 60\n[budget]\ntriangles = 10000000\n"
                   "[scene_hlod]\nenabled = true\n";
const char* kFar = R"([camera]
fov_deg = 60
width = 1280
height = 720
path = "keyframes"
near = 0.5
far = 100000.0
[[camera.keyframe]]
frame = 0
position = [0.0, 1500.0, 3000.0]
look_at = [0.0, 0.0, 0.0]
[[camera.keyframe]]
frame = 11
position = [0.0, 40.0, 200.0]
look_at = [0.0, 0.0, 0.0]
)";
const char* kField = R"([[instances]]
model = "sphere"
count = 150
box_min = [-200.0, 0.0, -200.0]
box_max = [200.0, 0.0, 200.0]
scale_range = [2.0, 4.0]
seed = 3
[[instances]]
model = "box"
count = 150
box_min = [-200.0, 0.0, -200.0]
box_max = [200.0, 0.0, 200.0]
scale_range = [2.0, 3.0]
seed = 4
)";

TEST(ViewerSceneProxies, DrawnProxiesAreCountedLikeEverythingElse) {
  LOD_REQUIRE_XVFB();
  const auto scene = lod::test::write_viewer_scene("proxies", kRun, kFar, kField);
  const auto stats = scene.dir / "proxies.csv";
  const auto r = lod::test::run_viewer(scene, "--screenshot '" + (scene.dir / "proxies.png").string() +
                                                  "' --frames 12 --width 320 --height 180 --stats '" +
                                                  stats.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  lod::test::CsvTable t;
  ASSERT_TRUE(lod::test::load_csv(stats, t));
  ASSERT_EQ(t.rows.size(), 12u);
  for (size_t i = 0; i < t.rows.size(); ++i) {
    SCOPED_TRACE("viewer frame " + std::to_string(i));
    EXPECT_EQ(t.get(i, "whole"), 1);
    EXPECT_EQ(t.get(i, "rejected"), 0);
    EXPECT_EQ(t.get(i, "drawn"), t.get(i, "tris_selected") + t.get(i, "morph_extra"));
    EXPECT_EQ(t.get(i, "gpu_primitives"), t.get(i, "drawn"));
  }
  EXPECT_GT(t.get(0, "proxies"), 0) << "far away, proxies stand for the field";
  EXPECT_GT(t.get(0, "proxy_drawn"), 0);
  EXPECT_GT(t.get(0, "proxy_objects"), t.get(0, "proxies")) << "a proxy stands for several objects";
  EXPECT_LT(t.get(11, "proxy_objects"), t.get(0, "proxy_objects")) << "close by, objects are their own";
}

}  // namespace
