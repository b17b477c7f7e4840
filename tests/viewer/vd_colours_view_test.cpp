// lod-viewer --screenshot of a view-dependent glTF sphere with vertex colours (COLOR_0): the
// front publishes them (Frame::vd_colors) and the shader multiplies them into the base colour,
// so red vertex colours show red; the same sphere with white ones does not.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "preprocess/gltf_write.h"
#include "textured_fixture.h"
#include "viewer/picture_checks.h"
#include "viewer/viewer_harness.h"

namespace {

const char* kRun = "[run]\nframes = 1\nthreads = 1\n[budget]\ntriangles = 1000000\n";

const char* kModel = R"([[model]]
name = "painted"
file = "painted/ball.gltf"
ratios = [1.0, 0.5]
view_dependent = true
)";

const char* kInstance = R"([[instances]]
model = "painted"
count = 1
placement = "grid"
box_min = [0.0, 0.0, 0.0]
box_max = [0.0, 0.0, 0.0]
scale = 9.0
)";

// The textured fixture's sphere, faces outward, every vertex coloured `rgba`.
bool write_ball(const std::filesystem::path& dir, const float (&rgba)[4]) {
  lod::MeshData m = lod::test::two_material_sphere(24, 48);
  lod::test::turn_faces_outward(m);
  for (size_t v = 0; v < m.vertex_count(); ++v) m.colors.insert(m.colors.end(), rgba, rgba + 4);
  std::filesystem::create_directories(dir);
  lod::GltfMeshView view;
  view.name = "ball";
  view.positions = m.positions.data();
  view.vertex_count = m.vertex_count();
  view.colors = m.colors.data();
  view.indices = m.indices.data();
  view.index_count = m.indices.size();
  return lod::save_gltf(dir / "ball.gltf", view).ok;
}

// Pixels whose red clearly dominates (bright enough for the hue to be read).
int red_pixels(const lod::test::Image& img) {
  int n = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* px = img.at(x, y);
      n += px[0] >= 60 && px[1] * 4 < px[0] && px[2] * 4 < px[0];
    }
  return n;
}

int shoot(const std::string& tag, const float (&rgba)[4]) {
  const auto scene =
      lod::test::write_viewer_scene(tag, kRun, lod::test::front_camera(400, 300), kInstance, kModel);
  EXPECT_TRUE(write_ball(scene.dir / "painted", rgba));
  const auto png = scene.dir / "shot.png";
  const auto stats = scene.dir / "shot.csv";
  const auto r = lod::test::run_viewer(scene, "--screenshot '" + png.string() +
                                                  "' --frames 3 --width 400 --height 300 --stats '" +
                                                  stats.string() + "'");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  lod::test::CsvTable t;
  EXPECT_TRUE(lod::test::load_csv(stats, t));
  if (!t.rows.empty()) EXPECT_EQ(t.get(t.rows.size() - 1, "vd_objects"), 1) << "drawn from its active front";
  lod::test::Image img;
  EXPECT_TRUE(lod::test::load_png(png, img));
  return red_pixels(img);
}

TEST(ViewerVdColours, RedVertexColoursShowRed) {
  LOD_REQUIRE_XVFB();
  const int red = shoot("vd-red", {1, 0, 0, 1});
  const int white = shoot("vd-white", {1, 1, 1, 1});
  EXPECT_GE(red, 2000) << "the red-coloured ball shows red";
  EXPECT_LT(white, 200) << "the white-coloured one does not";
}

}  // namespace
