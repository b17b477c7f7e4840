// View-dependent objects in lod-viewer: drawn from the active, geomorphed mesh the frame
// publishes (with the object's transform), instead of their discrete level, and counted in
// the drawn triangles so that drawn == selected still holds.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "runtime/view.h"
#include "viewer/level_palette.h"
#include "viewer/picture_checks.h"
#include "viewer/viewer_harness.h"

namespace {

using lod::test::CsvTable;
using lod::test::Image;

const char* kRun = R"([run]
frames = 30
threads = 2
rate_hz = 60
[budget]
triangles = 1000000
)";

// Camera at z = 30 looking at the origin.
const std::string kFrontCamera = lod::test::front_camera(1280, 720);

// The generated sphere again, as a view-dependent model.
const char* kVdModel = R"([[model]]
name = "ball"
file = "sphere.off"
ratios = [1.0, 0.5, 0.25, 0.12, 0.06]
view_dependent = true
)";

// A view-dependent ball (radius 4) at x = -8, an ordinary box at x = +8.
const char* kBallAndBox = R"([[instances]]
model = "ball"
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

// A lit shade of the view-dependent colour (near-white grey): channels equal and bright.
bool is_vd_colour(const uint8_t* px) {
  const int lo = std::min({px[0], px[1], px[2]}), hi = std::max({px[0], px[1], px[2]});
  return hi - lo <= 6 && lo >= 120;
}

TEST(ViewerVdObjects, DrawnFromTheirActiveMeshAndCountedAsSelected) {
  LOD_REQUIRE_XVFB();
  const auto scene = lod::test::write_viewer_scene("vd", kRun, kFrontCamera, kBallAndBox, kVdModel);
  const auto png = scene.dir / "vd.png";
  const auto stats = scene.dir / "vd.csv";
  const auto r = lod::test::run_viewer(scene, "--screenshot '" + png.string() +
                                                  "' --frames 30 --colour-by-level --width 320 --height 200 "
                                                  "--stats '" + stats.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;

  CsvTable t;
  ASSERT_TRUE(lod::test::load_csv(stats, t));
  ASSERT_EQ(t.rows.size(), 30u);
  for (size_t i = 0; i < t.rows.size(); ++i) {
    SCOPED_TRACE("viewer frame " + std::to_string(i));
    EXPECT_EQ(t.get(i, "whole"), 1);
    EXPECT_EQ(t.get(i, "rejected"), 0);
    EXPECT_EQ(t.get(i, "visible"), 2);
    EXPECT_EQ(t.get(i, "drawn"), t.get(i, "tris_selected"));
    EXPECT_EQ(t.get(i, "gpu_primitives"), t.get(i, "drawn"));
    EXPECT_EQ(t.get(i, "vd_objects"), 1);
    EXPECT_GT(t.get(i, "vd_drawn"), 0);
    EXPECT_LT(t.get(i, "vd_drawn"), t.get(i, "drawn")) << "the box is drawn too";
    // One instanced draw for the box, one for the ball's active mesh: the ball is not also
    // drawn at its discrete level.
    EXPECT_EQ(t.get(i, "draws"), 2);
    EXPECT_EQ(t.get(i, "levels_drawn"), 1);
  }

  Image img;
  ASSERT_TRUE(lod::test::load_png(png, img)) << png;
  ASSERT_EQ(img.width, 320);
  ASSERT_EQ(img.height, 200);
  // After 30 frames (0.5 s, twice the geomorph time) the ball's split vertices have moved out
  // to their places. The ball sits where its object transform puts it (x = -8, radius 4 = scale): its centre
  // and points well inside its outline in the vd colour, outside it the background.
  for (glm::vec3 inside : {glm::vec3(-8, 0, 0), glm::vec3(-5, 0, 0), glm::vec3(-11, 0, 0), glm::vec3(-8, 3, 0),
                           glm::vec3(-8, -3, 0)}) {
    const auto [x, y] = project(inside, img.width, img.height);
    const uint8_t* px = img.at(x, y);
    EXPECT_TRUE(is_vd_colour(px)) << "ball pixel (" << x << ", " << y << ") is " << int(px[0]) << " " << int(px[1])
                                  << " " << int(px[2]);
  }
  for (glm::vec3 outside : {glm::vec3(-8, 6, 0), glm::vec3(-8, -6, 0), glm::vec3(-14, 0, 0), glm::vec3(0, 0, 0)}) {
    const auto [x, y] = project(outside, img.width, img.height);
    EXPECT_TRUE(is_background(img.at(x, y))) << "something drawn outside the ball at (" << x << ", " << y << ")";
  }
  // The discrete box is still drawn, in a level colour (not the vd one).
  const auto [bx, by] = project({8, 0, 0}, img.width, img.height);
  EXPECT_FALSE(is_background(img.at(bx, by)));
  EXPECT_FALSE(is_vd_colour(img.at(bx, by)));
}

}  // namespace
