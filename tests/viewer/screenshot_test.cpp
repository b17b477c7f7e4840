// lod-viewer --screenshot under xvfb-run: the picture has the requested size, shows objects
// where the camera looks at them and background elsewhere, and colour-by-level shows levels.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <utility>

#include "runtime/view.h"
#include "viewer/level_palette.h"
#include "viewer/picture_checks.h"
#include "viewer/viewer_harness.h"

namespace {

using lod::test::CsvTable;
using lod::test::Image;

const char* kRun = R"([run]
frames = 1
threads = 1
rate_hz = 60
[budget]
triangles = 1000000
)";

// Camera at z = 30 looking at the origin; sphere at x = -8, box at x = +8, nothing between.
const std::string kFrontCamera = lod::test::front_camera(1280, 720);

const char* kTwoObjects = R"([[instances]]
model = "sphere"
count = 1
placement = "grid"
box_min = [-8.0, 0.0, 0.0]
box_max = [-8.0, 0.0, 0.0]
scale = 4.0
[[instances]]
model = "box"
count = 1
placement = "grid"
box_min = [8.0, 0.0, 0.0]
box_max = [8.0, 0.0, 0.0]
scale = 3.0
)";

using lod::test::is_background;
using lod::test::project;

// Index of the palette colour this pixel is a shade of, or -1. Shading scales all channels
// alike, so colours are compared after dividing by their largest channel.
int palette_entry(const uint8_t* px) {
  const int top = std::max({px[0], px[1], px[2]});
  if (top < 40) return -1;  // too dark to tell
  int best = -1;
  float best_d = 0.1f;
  for (size_t i = 0; i < lod::viewer::kLevelPalette.size(); ++i) {
    const auto& col = lod::viewer::kLevelPalette[i];
    const float ctop = std::max({col[0], col[1], col[2]});
    float d = 0;
    for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(float(px[c]) / float(top) - col[size_t(c)] / ctop));
    if (d < best_d) best_d = d, best = int(i);
  }
  return best;
}

std::map<int, int> palette_histogram(const Image& img) {
  std::map<int, int> counts;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      if (int e = palette_entry(img.at(x, y)); e >= 0) ++counts[e];
  return counts;
}

TEST(ViewerScreenshot, HasRequestedSizeObjectsWhereLookedAtAndBackgroundElsewhere) {
  LOD_REQUIRE_XVFB();
  const auto scene = lod::test::write_viewer_scene("placement", kRun, kFrontCamera, kTwoObjects);
  const auto png = scene.dir / "shot.png";
  const auto r = lod::test::run_viewer(scene, "--screenshot '" + png.string() + "' --width 320 --height 200");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  Image img;
  ASSERT_TRUE(lod::test::load_png(png, img)) << png;
  EXPECT_EQ(img.width, 320);
  EXPECT_EQ(img.height, 200);

  size_t drawn = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) drawn += is_background(img.at(x, y)) ? 0 : 1;
  const size_t total = size_t(img.width) * size_t(img.height);
  EXPECT_GT(drawn, total / 50) << "picture is (nearly) blank";
  EXPECT_LT(drawn, total / 2) << "the two small objects cannot cover half the picture";

  for (glm::vec3 object : {glm::vec3(-8, 0, 0), glm::vec3(8, 0, 0)}) {
    const auto [x, y] = project(object, img.width, img.height);
    EXPECT_FALSE(is_background(img.at(x, y))) << "no object drawn at (" << x << ", " << y << ")";
  }
  for (glm::vec3 empty : {glm::vec3(0, 0, 0), glm::vec3(0, 10, 0), glm::vec3(-8, -10, 0), glm::vec3(8, 10, 0)}) {
    const auto [x, y] = project(empty, img.width, img.height);
    EXPECT_TRUE(is_background(img.at(x, y))) << "something drawn at empty (" << x << ", " << y << ")";
  }
  // The picture is upright: the sphere (at -x) is in the left half, the box to the right.
  const auto [sx, sy] = project({-8, 0, 0}, img.width, img.height);
  EXPECT_LT(sx, img.width / 2);
  EXPECT_EQ(sy, img.height / 2);
}

// Sixty objects receding from the camera under a tight budget: near ones fine, far ones coarse.
const char* kDepthCamera = R"([camera]
fov_deg = 60
width = 1280
height = 720
path = "keyframes"
near = 0.5
far = 1000.0
[[camera.keyframe]]
frame = 0
position = [0.0, 6.0, 12.0]
look_at = [0.0, 0.0, -60.0]
)";

const char* kReceding = R"([[instances]]
model = "sphere"
count = 30
box_min = [-20.0, 0.0, -150.0]
box_max = [20.0, 0.0, -5.0]
scale = 2.0
seed = 11
[[instances]]
model = "box"
count = 30
box_min = [-20.0, 0.0, -150.0]
box_max = [20.0, 0.0, -5.0]
scale = 1.5
seed = 12
)";

TEST(ViewerScreenshot, ColourByLevelShowsAtLeastTwoLevelColours) {
  LOD_REQUIRE_XVFB();
  // A strict pixel error asks for fine levels everywhere, so the budget decides: near objects
  // keep detail and far ones are lowered, whatever the simplifier's measured errors are.
  const std::string run = "[run]\nframes = 1\nthreads = 1\n[budget]\ntriangles = 30000\n[lod]\npixel_error = 0.05\n";
  const auto scene = lod::test::write_viewer_scene("levels", run, kDepthCamera, kReceding);
  const auto coloured = scene.dir / "levels.png";
  const auto plain = scene.dir / "plain.png";
  const auto stats = scene.dir / "levels.csv";
  auto r = lod::test::run_viewer(scene, "--screenshot '" + coloured.string() + "' --color-by-level --frames 3 " +
                                            "--width 400 --height 240 --stats '" + stats.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = lod::test::run_viewer(scene, "--screenshot '" + plain.string() + "' --frames 3 --width 400 --height 240");
  ASSERT_EQ(r.exit_code, 0) << r.output;

  Image img;
  ASSERT_TRUE(lod::test::load_png(coloured, img));
  const auto counts = palette_histogram(img);
  int levels_seen = 0;
  for (auto [entry, pixels] : counts) levels_seen += pixels >= 20 ? 1 : 0;
  EXPECT_GE(levels_seen, 2) << "level colours in the picture: " << counts.size();

  CsvTable table;
  ASSERT_TRUE(lod::test::load_csv(stats, table));
  EXPECT_GE(table.get(table.rows.size() - 1, "levels_drawn"), 2);

  // Without the mode no pixel is a level colour: the colours come from the mode.
  Image grey;
  ASSERT_TRUE(lod::test::load_png(plain, grey));
  EXPECT_TRUE(palette_histogram(grey).empty());
}

}  // namespace

namespace {

bool near_colour(const uint8_t* px, std::array<float, 3> c, int tol) {
  for (int k = 0; k < 3; ++k)
    if (std::abs(int(px[k]) - int(std::lround(c[size_t(k)] * 255))) > tol) return false;
  return true;
}

// From above: the objects the LOD camera culled are drawn dark, the visible ones in level
// colours, and the LOD camera's frustum as yellow lines.
TEST(ViewerScreenshot, BirdEyeShowsCulledObjectsAndTheLodFrustum) {
  LOD_REQUIRE_XVFB();
  const std::string behind = std::string(kTwoObjects) + R"([[instances]]
model = "box"
count = 1
placement = "grid"
box_min = [0.0, 0.0, 80.0]
box_max = [0.0, 0.0, 80.0]
scale = 4.0
)";
  const auto scene = lod::test::write_viewer_scene("birdeye", kRun, kFrontCamera, behind);
  const auto png = scene.dir / "bird.png";
  const auto r = lod::test::run_viewer(scene, "--screenshot '" + png.string() +
                                                  "' --bird-eye --color-by-level --width 320 --height 240");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  Image img;
  ASSERT_TRUE(lod::test::load_png(png, img));
  size_t culled = 0, frustum = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* px = img.at(x, y);
      // Culled objects: a shade of the dark grey (lit between 25 % and 100 %).
      const int top = std::max({px[0], px[1], px[2]});
      if (top > 25 && top <= 90 && std::abs(int(px[0]) - int(px[1])) <= 3 && px[2] >= px[0] && px[2] - px[0] <= 8 &&
          !near_colour(px, lod::viewer::kBackground, 2))
        ++culled;
      if (near_colour(px, {1.0f, 0.9f, 0.2f}, 2)) ++frustum;
    }
  EXPECT_GT(culled, 10u) << "the box behind the LOD camera is not drawn as culled";
  EXPECT_GT(frustum, 20u) << "no frustum lines";
  EXPECT_FALSE(palette_histogram(img).empty()) << "the visible objects lost their level colours";
}

}  // namespace

namespace {

// Driven mode makes the picture a function of the config and N: two runs, same pixels.
TEST(ViewerScreenshot, SameConfigAndFrameCountGiveTheSamePicture) {
  LOD_REQUIRE_XVFB();
  const std::string run = "[run]\nframes = 1\nthreads = 2\n[budget]\ntriangles = 30000\n";
  const auto scene = lod::test::write_viewer_scene("determinism", run, kDepthCamera, kReceding);
  Image a, b;
  for (Image* img : {&a, &b}) {
    const auto png = scene.dir / (img == &a ? "a.png" : "b.png");
    const auto r = lod::test::run_viewer(scene, "--screenshot '" + png.string() +
                                                    "' --frames 4 --color-by-level --width 256 --height 160");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    ASSERT_TRUE(lod::test::load_png(png, *img));
  }
  ASSERT_EQ(a.rgb.size(), b.rgb.size());
  size_t differing = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) differing += a.rgb[i] != b.rgb[i] ? 1 : 0;
  EXPECT_EQ(differing, 0u);
}

}  // namespace

namespace {

// Two spheres orbiting (-8, 0, 0) at radius 2 (20 units/s: 10 rad/s), the box standing still.
const char* kOrbitingSpheres = R"([[instances]]
model = "sphere"
count = 2
placement = "grid"
box_min = [-12.0, 0.0, 0.0]
box_max = [-4.0, 0.0, 0.0]
scale = 1.5
motion = "orbit"
speed = 20.0
[[instances]]
model = "box"
count = 1
placement = "grid"
box_min = [8.0, 0.0, 0.0]
box_max = [8.0, 0.0, 0.0]
scale = 3.0
)";

// Where the orbit puts a sphere that started at angle a0 (radians, in x-z about (-8, 0, 0))
// after `frames` driven frames at 60 Hz: frame n is staged at (n + 1) / 60 s.
glm::vec3 orbit_position(float a0, int frames) {
  const float a = a0 + 10.f * float(frames) / 60.f;
  return {-8.f + 2.f * std::cos(a), 0.f, 2.f * std::sin(a)};
}

// Moving instances are drawn from the frame's transforms: after a different number of frames
// the spheres are somewhere else, drawn where their motion puts them.
TEST(ViewerScreenshot, MovingInstancesAreDrawnWhereTheFrameSaysTheyAre) {
  LOD_REQUIRE_XVFB();
  const auto scene = lod::test::write_viewer_scene("moving", kRun, kFrontCamera, kOrbitingSpheres);
  Image early, late;
  for (auto [img, frames] : {std::pair{&early, 1}, std::pair{&late, 8}}) {
    const auto png = scene.dir / ("moving-" + std::to_string(frames) + ".png");
    const auto csv = scene.dir / ("moving-" + std::to_string(frames) + ".csv");
    const auto r = lod::test::run_viewer(
        scene, "--screenshot '" + png.string() + "' --frames " + std::to_string(frames) +
                   " --width 400 --height 250 --stats '" + csv.string() + "'");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    ASSERT_TRUE(lod::test::load_png(png, *img));
    CsvTable t;
    ASSERT_TRUE(lod::test::load_csv(csv, t));
    for (size_t i = 0; i < t.rows.size(); ++i) {
      EXPECT_EQ(t.get(i, "whole"), 1) << "frame " << i;
      EXPECT_EQ(t.get(i, "rejected"), 0) << "frame " << i;
    }
    // Both spheres' centres, at this frame's time, are drawn.
    for (float a0 : {std::numbers::pi_v<float>, 0.f}) {
      const auto [x, y] = project(orbit_position(a0, frames), img->width, img->height);
      EXPECT_FALSE(is_background(img->at(x, y)))
          << frames << " frames: no sphere at (" << x << ", " << y << ")";
    }
  }
  ASSERT_EQ(early.rgb.size(), late.rgb.size());
  // The drawn region itself moved: pixels drawn in one picture and background in the other.
  size_t drawn_early = 0, drawn_late = 0, moved = 0;
  for (int y = 0; y < early.height; ++y)
    for (int x = 0; x < early.width; ++x) {
      const bool a = !is_background(early.at(x, y)), b = !is_background(late.at(x, y));
      drawn_early += a;
      drawn_late += b;
      moved += a != b;
    }
  EXPECT_GT(drawn_early, 200u) << "first picture (nearly) blank";
  EXPECT_GT(drawn_late, 200u) << "second picture (nearly) blank";
  EXPECT_GT(moved, 100u) << "the orbiting spheres were drawn in the same place after 1 and 8 frames";
}

}  // namespace
