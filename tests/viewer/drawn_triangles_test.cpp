// Drawn triangles equal the frame's tris_selected, counted three ways per viewer frame:
// the frame's own figure, the indices the viewer submitted, and the GL's
// GL_PRIMITIVES_GENERATED query; in driven (screenshot) and free-running (live) modes.
#include <gtest/gtest.h>

#include <set>

#include "viewer/viewer_harness.h"

namespace {

using lod::test::CsvTable;

const char* kRun = "[run]\nframes = 20\nthreads = 2\nrate_hz = 60\n[budget]\ntriangles = 40000\n";

const char* kOrbit = R"([camera]
fov_deg = 60
width = 1280
height = 720
path = "orbit"
center = [0.0, 0.0, 0.0]
radius = 45.0
height_above = 12.0
period_frames = 20
near = 0.5
far = 1000.0
)";

const char* kField = R"([[instances]]
model = "sphere"
count = 40
box_min = [-30.0, 0.0, -30.0]
box_max = [30.0, 0.0, 30.0]
scale_range = [1.0, 2.5]
seed = 3
[[instances]]
model = "box"
count = 40
box_min = [-30.0, 0.0, -30.0]
box_max = [30.0, 0.0, 30.0]
scale_range = [1.0, 2.0]
seed = 4
)";

// Every row: a whole frame, nothing refused, and selected == submitted == GL-counted.
void expect_rows_consistent(const CsvTable& t) {
  for (size_t i = 0; i < t.rows.size(); ++i) {
    SCOPED_TRACE("viewer frame " + std::to_string(i));
    EXPECT_EQ(t.get(i, "whole"), 1);
    EXPECT_EQ(t.get(i, "rejected"), 0);
    EXPECT_EQ(t.get(i, "drawn"), t.get(i, "tris_selected"));
    EXPECT_EQ(t.get(i, "gpu_primitives"), t.get(i, "tris_selected"));
  }
}

TEST(ViewerDrawnTriangles, EqualSelectedInEveryDrivenFrame) {
  LOD_REQUIRE_XVFB();
  const auto scene = lod::test::write_viewer_scene("driven", kRun, kOrbit, kField);
  const auto stats = scene.dir / "driven.csv";
  const auto r = lod::test::run_viewer(scene, "--screenshot '" + (scene.dir / "orbit.png").string() +
                                                  "' --frames 20 --width 320 --height 180 --stats '" +
                                                  stats.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  CsvTable t;
  ASSERT_TRUE(lod::test::load_csv(stats, t));
  ASSERT_EQ(t.rows.size(), 20u);
  expect_rows_consistent(t);
  double most = 0;
  for (size_t i = 0; i < t.rows.size(); ++i) {
    EXPECT_EQ(t.get(i, "lod_frame"), double(i + 1)) << "driven mode draws the frame it just stepped";
    most = std::max(most, t.get(i, "tris_selected"));
  }
  EXPECT_GT(most, 0) << "the orbit never saw an object";
  EXPECT_LE(most, 40000) << "selection kept the budget";
}

// The LOD thread publishes at up to 1 kHz while the viewer draws as fast as it can: every
// frame the viewer drew was one whole frame (counts agree), and frames changed under it.
TEST(ViewerDrawnTriangles, LiveFramesAreWholeWhileTheServicePublishes) {
  LOD_REQUIRE_XVFB();
  const auto scene = lod::test::write_viewer_scene("live", kRun, kOrbit, kField);
  const auto stats = scene.dir / "live.csv";
  const auto r = lod::test::run_viewer(scene, "--frames 60 --lod-rate 1000 --no-vsync --width 320 --height 180 "
                                              "--stats '" + stats.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  CsvTable t;
  ASSERT_TRUE(lod::test::load_csv(stats, t));
  ASSERT_EQ(t.rows.size(), 60u);
  expect_rows_consistent(t);
  std::set<double> lod_frames;
  for (size_t i = 0; i < t.rows.size(); ++i) {
    lod_frames.insert(t.get(i, "lod_frame"));
    if (i > 0) {
      EXPECT_GE(t.get(i, "lod_frame"), t.get(i - 1, "lod_frame")) << "an older frame came back";
    }
  }
  EXPECT_GE(lod_frames.size(), 2u) << "the service never published while the viewer drew";
}

}  // namespace
