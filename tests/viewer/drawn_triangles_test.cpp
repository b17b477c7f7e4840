// Drawn triangles equal the frame's tris_selected, counted three ways per viewer frame:
// the frame's own figure, the indices the viewer submitted, and the GL's
// GL_PRIMITIVES_GENERATED query; in driven (screenshot) and free-running (live) modes.
#include <gtest/gtest.h>

#include <algorithm>
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

// Every row: a whole frame, nothing refused, and what the frame says is drawn == submitted ==
// GL-counted: the selected triangles plus, for objects blending two levels, what drawing their
// finer level adds (exactly the selected triangles on frames where nothing morphs). Returns the
// rows where something morphed.
size_t expect_rows_consistent(const CsvTable& t) {
  size_t morphing_rows = 0;
  for (size_t i = 0; i < t.rows.size(); ++i) {
    SCOPED_TRACE("viewer frame " + std::to_string(i));
    EXPECT_EQ(t.get(i, "whole"), 1);
    EXPECT_EQ(t.get(i, "rejected"), 0);
    const double expected = t.get(i, "tris_selected") + t.get(i, "morph_extra");
    EXPECT_EQ(t.get(i, "drawn"), expected);
    EXPECT_EQ(t.get(i, "gpu_primitives"), expected);
    if (t.get(i, "morphing") == 0) {
      EXPECT_EQ(t.get(i, "morph_extra"), 0);
      EXPECT_EQ(t.get(i, "morph_draws"), 0);
      EXPECT_EQ(t.get(i, "drawn"), t.get(i, "tris_selected"));
    } else {
      ++morphing_rows;
      EXPECT_GT(t.get(i, "morph_draws"), 0) << "objects morph but no batch blended";
    }
  }
  return morphing_rows;
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

// The camera backs out of a field of spheres: levels coarsen on the way, and each change blends
// over geomorph_seconds (0.25 s = 15 driven frames), drawn at the finer level (the old one).
const char* kApproach = R"([camera]
fov_deg = 60
width = 1280
height = 720
path = "keyframes"
near = 0.5
far = 1000.0
[[camera.keyframe]]
frame = 0
position = [0.0, 2.0, 4.0]
look_at = [0.0, 0.0, -20.0]
[[camera.keyframe]]
frame = 40
position = [0.0, 10.0, 120.0]
look_at = [0.0, 0.0, 0.0]
)";

const char* kSpheres = R"([[instances]]
model = "sphere"
count = 30
box_min = [-20.0, 0.0, -20.0]
box_max = [20.0, 0.0, 20.0]
scale_range = [1.0, 2.0]
seed = 5
)";

TEST(ViewerDrawnTriangles, MorphingObjectsDrawTheirFinerLevelAndSayWhatItAdds) {
  LOD_REQUIRE_XVFB();
  const auto scene = lod::test::write_viewer_scene("approach", "[run]\nframes = 40\nthreads = 2\nrate_hz = 60\n"
                                                               "[budget]\ntriangles = 10000000\n",
                                                   kApproach, kSpheres);
  const auto stats = scene.dir / "approach.csv";
  const auto r = lod::test::run_viewer(scene, "--screenshot '" + (scene.dir / "approach.png").string() +
                                                  "' --frames 40 --width 320 --height 180 --stats '" +
                                                  stats.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  CsvTable t;
  ASSERT_TRUE(lod::test::load_csv(stats, t));
  ASSERT_EQ(t.rows.size(), 40u);
  const size_t morphing_rows = expect_rows_consistent(t);
  EXPECT_GT(morphing_rows, 0u) << "no level change blended on the way out";
  double extra = 0;
  for (size_t i = 0; i < t.rows.size(); ++i) extra = std::max(extra, t.get(i, "morph_extra"));
  EXPECT_GT(extra, 0) << "coarsening objects are drawn at the finer level they leave";
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

// The same with every sphere wandering: the interactive viewer stages and commits their
// transforms every viewer frame (wall time) while the LOD thread publishes; every frame drawn
// is still whole and drawn exactly as selected, in both modes.
TEST(ViewerDrawnTriangles, FramesWithMovingInstancesAreWholeLiveAndDriven) {
  LOD_REQUIRE_XVFB();
  std::string moving = kField;
  moving.replace(moving.find("seed = 3\n"), 9, "seed = 3\nmotion = \"wander\"\nspeed = 25.0\n");
  const auto scene = lod::test::write_viewer_scene("live-moving", kRun, kOrbit, moving);
  const std::string live = "--frames 60 --lod-rate 1000 --no-vsync";
  const std::string driven = "--frames 20 --screenshot '" + (scene.dir / "moving.png").string() + "'";
  for (const std::string& mode : {live, driven}) {
    SCOPED_TRACE(mode);
    const auto stats = scene.dir / "live-moving.csv";
    const auto r =
        lod::test::run_viewer(scene, mode + " --width 320 --height 180 --stats '" + stats.string() + "'");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    CsvTable t;
    ASSERT_TRUE(lod::test::load_csv(stats, t));
    ASSERT_FALSE(t.rows.empty());
    expect_rows_consistent(t);
  }
}

}  // namespace
