// The terrain in lod-viewer: drawn from the frame's ROAM mesh, coloured by height and lit, and
// counted in the drawn triangles so that drawn == selected still holds.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "test_support.h"
#include "viewer/picture_checks.h"
#include "viewer/terrain_palette.h"
#include "viewer/viewer_harness.h"

namespace {

using lod::test::CsvTable;
using lod::test::Image;

const char* kRun = "[run]\nframes = 20\nthreads = 2\nrate_hz = 60\n[budget]\ntriangles = 60000\n";

// Above the terrain's centre, looking (nearly) straight down: x runs left to right.
const char* kAbove = R"([camera]
fov_deg = 60
width = 1280
height = 720
path = "keyframes"
near = 0.5
far = 2000.0
[[camera.keyframe]]
frame = 0
position = [0.0, 140.0, 1.0]
look_at = [0.0, 0.0, 0.0]
)";

// One small box above the terrain, and the terrain: a 65 x 65 field 128 m across, rising from
// 0 m in the west to 40 m in the east, with bumps.
const char* kBoxAndTerrain = R"([[instances]]
model = "box"
count = 1
placement = "grid"
box_min = [0.0, 60.0, -50.0]
box_max = [0.0, 60.0, -50.0]
scale = 2.0
[[terrain]]
file = "ramp.txt"
pixel_error = 0.5
)";

void write_ramp(const std::filesystem::path& file) {
  std::string text;
  for (int y = 0; y < 65; ++y)
    for (int x = 0; x < 65; ++x)
      text += std::to_string(2 * x) + " " + std::to_string(2 * y) + " " +
              std::to_string(40.0 * x / 64 + 2.0 * std::sin(0.6 * x) * std::cos(0.5 * y)) + "\n";
  lod::test::write_text(file, text);
}

// Mean colour of the 12 x 12 pixel box whose top-left corner is (x, y); no background in it.
glm::vec3 mean_colour(const Image& img, int x0, int y0) {
  glm::vec3 sum(0);
  for (int y = y0; y < y0 + 12; ++y)
    for (int x = x0; x < x0 + 12; ++x) {
      const uint8_t* px = img.at(x, y);
      EXPECT_FALSE(lod::test::is_background(px)) << "(" << x << ", " << y << ") is not terrain";
      sum += glm::vec3(px[0], px[1], px[2]);
    }
  return sum / float(12 * 12);
}

TEST(ViewerTerrain, HeightColourRampGoesFromGreenToWhite) {
  const glm::vec3 low = lod::viewer::terrain_height_colour(0), high = lod::viewer::terrain_height_colour(1);
  EXPECT_GT(low.y, low.x);
  EXPECT_GT(low.y, low.z);
  EXPECT_GT(high.x + high.y + high.z, 2.7f);
  EXPECT_EQ(lod::viewer::terrain_height_colour(-1), low) << "clamped";
}

TEST(ViewerTerrain, DrawnColouredByHeightAndCountedAsSelected) {
  LOD_REQUIRE_XVFB();
  const auto scene = lod::test::write_viewer_scene("terrain", kRun, kAbove, kBoxAndTerrain);
  write_ramp(scene.dir / "ramp.txt");
  const auto png = scene.dir / "terrain.png";
  const auto stats = scene.dir / "terrain.csv";
  const auto r = lod::test::run_viewer(scene, "--screenshot '" + png.string() +
                                                  "' --frames 20 --width 320 --height 200 --stats '" + stats.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;

  CsvTable t;
  ASSERT_TRUE(lod::test::load_csv(stats, t));
  ASSERT_EQ(t.rows.size(), 20u);
  for (size_t i = 0; i < t.rows.size(); ++i) {
    SCOPED_TRACE("viewer frame " + std::to_string(i));
    EXPECT_EQ(t.get(i, "whole"), 1);
    EXPECT_EQ(t.get(i, "rejected"), 0);
    EXPECT_EQ(t.get(i, "drawn"), t.get(i, "tris_selected") + t.get(i, "morph_extra"));
    EXPECT_EQ(t.get(i, "gpu_primitives"), t.get(i, "drawn"));
    EXPECT_GT(t.get(i, "drawn"), 1000) << "the terrain's triangles are drawn";
  }

  Image img;
  ASSERT_TRUE(lod::test::load_png(png, img)) << png;
  // The terrain spans the middle half of the picture's width; its low west side is green, its high east side
  // brighter (towards white): averages over boxes, so the bumps' shading evens out.
  const glm::vec3 west = mean_colour(img, img.width * 28 / 100, img.height / 2);
  const glm::vec3 east = mean_colour(img, img.width * 66 / 100, img.height / 2);
  EXPECT_GT(west.y, west.x + 10) << "west is green: " << west.x << " " << west.y << " " << west.z;
  EXPECT_GT(west.y, west.z + 10);
  EXPECT_GT(east.x + east.y + east.z, west.x + west.y + west.z + 60) << "colour follows height";
  EXPECT_GT(east.z, west.z + 30) << "towards white: " << east.x << " " << east.y << " " << east.z;
}

TEST(ViewerTerrain, BadTerrainFileIsRefusedBeforeAnyWindow) {
  const auto scene = lod::test::write_viewer_scene("terrain-bad", kRun, kAbove, kBoxAndTerrain);
  lod::test::write_text(scene.dir / "ramp.txt", "0 0 1\n1 0 2\n");  // one row: under 2 x 2
  const auto r = lod::test::run_viewer(scene, "--screenshot '" + (scene.dir / "x.png").string() + "'", false);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("ramp.txt"), std::string::npos) << r.output;
}

}  // namespace
