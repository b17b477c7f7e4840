// Which faces and in what order lod-viewer draws materials: a single-sided material culls back
// faces (glTF's doubleSided false), a double-sided one draws both; blended runs are drawn
// farthest first, whatever order the scene lists their models in. Quads written as glTF at test
// time, seen by the tests' front camera (eye at z = 30 looking at the origin); plus the CPU
// order of viewer/blend_order.h.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <string>

#include "preprocess/gltf_write.h"
#include "viewer/blend_order.h"
#include "viewer/picture_checks.h"
#include "viewer/viewer_harness.h"

namespace {

namespace fs = std::filesystem;
using lod::test::Image;

const char* kRun = "[run]\nframes = 1\nthreads = 1\n[budget]\ntriangles = 1000000\n";

// The quad [-1, 1]^2 at z = 0, facing +z (counter-clockwise seen from the camera) or -z.
void write_quad(const fs::path& file, const lod::GltfMaterialView& material, bool faces_camera) {
  const std::vector<float> positions = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  const float nz = faces_camera ? 1.f : -1.f;
  const std::vector<float> normals = {0, 0, nz, 0, 0, nz, 0, 0, nz, 0, 0, nz};
  const std::vector<uint32_t> front = {0, 1, 2, 0, 2, 3}, back = {0, 2, 1, 0, 3, 2};
  const std::vector<uint32_t>& indices = faces_camera ? front : back;
  lod::GltfMeshView view;
  view.name = file.stem().string();
  view.positions = positions.data();
  view.normals = normals.data();
  view.vertex_count = 4;
  view.indices = indices.data();
  view.index_count = indices.size();
  view.materials = {material};
  view.submeshes = {{0, indices.size(), 0}};
  const lod::Status saved = lod::save_gltf(file, view);
  EXPECT_TRUE(saved.ok) << saved.message;
}

lod::GltfMaterialView plain(float r, float g, float b, float a = 1.f) {
  lod::GltfMaterialView m;
  m.name = "plain";
  m.base_color[0] = r, m.base_color[1] = g, m.base_color[2] = b, m.base_color[3] = a;
  m.metallic = 0;
  m.roughness = 1;
  return m;
}

std::string model(const std::string& name) {
  return "[[model]]\nname = \"" + name + "\"\nfile = \"quads/" + name + ".gltf\"\nratios = [1.0]\n\n";
}

// One object at (0, 0, z). Every placement turns its objects by a yaw drawn from the block's
// seed; seed 1061's first draw is -0.1 degrees, so the quads face the camera squarely.
std::string instance(const std::string& name, float z, float scale) {
  const std::string at = "[0.0, 0.0, " + std::to_string(z) + "]";
  return "[[instances]]\nmodel = \"" + name + "\"\ncount = 1\nplacement = \"grid\"\nbox_min = " + at +
         "\nbox_max = " + at + "\nscale = " + std::to_string(scale) + "\nseed = 1061\n";
}

// The centre pixel of the scene's picture (empty when the viewer failed).
std::array<int, 3> centre_pixel(const lod::test::ViewerScene& scene, bool* background = nullptr) {
  const fs::path png = scene.dir / "quads.png";
  const auto r = lod::test::run_viewer(scene, "--screenshot '" + png.string() + "' --width 320 --height 240");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  Image img;
  std::array<int, 3> c{-1, -1, -1};
  if (!lod::test::load_png(png, img)) return c;
  const uint8_t* px = img.at(img.width / 2, img.height / 2);
  for (int k = 0; k < 3; ++k) c[size_t(k)] = px[k];
  if (background) *background = lod::test::is_background(px);
  return c;
}

// A quad turned away from the camera: single-sided, nothing is drawn (the background shows);
// double-sided, it is drawn; turned towards the camera, single-sided is drawn too.
TEST(ViewerMaterialSides, ASingleSidedQuadSeenFromBehindDrawsNothingADoubleSidedOneDraws) {
  LOD_REQUIRE_XVFB();
  auto centre = [](const std::string& tag, bool double_sided, bool faces_camera, bool& background) {
    const auto scene = lod::test::write_viewer_scene("sides-" + tag, kRun, lod::test::front_camera(320, 240),
                                                     instance("quad", 0, 8), model("quad"));
    fs::create_directories(scene.dir / "quads");
    lod::GltfMaterialView m = plain(0.9f, 0.6f, 0.1f);
    m.double_sided = double_sided;
    write_quad(scene.dir / "quads" / "quad.gltf", m, faces_camera);
    return centre_pixel(scene, &background);
  };
  bool back_single = false, back_double = false, front_single = false;
  const auto a = centre("back-single", false, false, back_single);
  const auto b = centre("back-double", true, false, back_double);
  const auto c = centre("front-single", false, true, front_single);
  std::printf(
      "centre pixel: single-sided from behind %d %d %d, double-sided from behind %d %d %d, single-sided "
      "from the front %d %d %d\n",
      a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2]);
  ASSERT_GE(a[0], 0);
  EXPECT_TRUE(back_single) << "a single-sided quad seen from behind is culled";
  EXPECT_FALSE(back_double) << "a double-sided quad is drawn from behind";
  EXPECT_FALSE(front_single) << "a single-sided quad is drawn from the front";
  EXPECT_GT(b[0], b[2] + 40) << "in its own orange";
}

// Two half-transparent quads, blue at z = 5 in front of red at z = -5, the blue one listed (and
// batched) first: drawn farthest first, the nearer blue weighs 0.5 in the centre pixel and the
// red 0.25, so blue wins; in list order it would be the other way round.
TEST(ViewerMaterialSides, OverlappingBlendedQuadsComposeFarthestFirst) {
  LOD_REQUIRE_XVFB();
  auto centre = [](const std::string& tag, float blue_z, float red_z) {
    const auto scene = lod::test::write_viewer_scene(
        "blend-order-" + tag, kRun, lod::test::front_camera(320, 240),
        instance("blue", blue_z, 6) + instance("red", red_z, 6), model("blue") + model("red"));
    fs::create_directories(scene.dir / "quads");
    lod::GltfMaterialView blue = plain(0.05f, 0.05f, 0.9f, 0.5f), red = plain(0.9f, 0.05f, 0.05f, 0.5f);
    blue.alpha_mode = red.alpha_mode = lod::AlphaMode::blend;
    write_quad(scene.dir / "quads" / "blue.gltf", blue, true);
    write_quad(scene.dir / "quads" / "red.gltf", red, true);
    return centre_pixel(scene);
  };
  const auto blue_near = centre("blue-near", 5, -5);
  const auto red_near = centre("red-near", -5, 5);
  std::printf("centre pixel: blue in front %d %d %d, red in front %d %d %d\n", blue_near[0], blue_near[1],
              blue_near[2], red_near[0], red_near[1], red_near[2]);
  ASSERT_GE(blue_near[0], 0);
  EXPECT_GT(blue_near[2], blue_near[0] + 20) << "the nearer blue quad is composited last";
  EXPECT_GT(red_near[0], red_near[2] + 20) << "the nearer red quad is composited last";
}

// The CPU order: every instance of a batch with blended runs and every view-dependent object
// with one, farthest first by its level's centre placed by its transform; the others left out.
TEST(BlendOrder, SortsInstancesAndViewDependentObjectsFarthestFirstByTheirCentre) {
  lod::viewer::MeshLayout layout;
  layout.ranges.resize(2);
  layout.ranges[0].center[2] = 2;  // model-space centre off the origin
  lod::viewer::DrawList list;
  auto at = [](float z, float scale) {
    lod::viewer::InstanceData d{};
    d.position_scale[2] = z, d.position_scale[3] = scale;
    d.rotation[3] = 1;
    return d;
  };
  list.instances = {at(0, 1), at(-3, 1), at(-1, 4), at(-50, 1)};
  list.batches = {{0, 0, 0, 0, 0, 3}, {1, 1, 0, 0, 3, 1}};
  const std::vector<uint8_t> blends = {1, 0};
  lod::viewer::VdDraw far_vd, plain_vd;  // a view-dependent object with a blended run, and one without
  far_vd.transform = at(-10, 1);
  far_vd.center[2] = 1;  // centre z = -9: 39 away
  plain_vd.transform = at(-100, 1);
  list.vd = {plain_vd, far_vd};
  const std::vector<uint8_t> vd_blends = {0, 1};
  lod::View eye;
  eye.eye = {0, 0, 30};
  eye.target = {0, 0, 0};
  const glm::mat4 view = lod::view_matrix(eye);
  std::vector<lod::viewer::BlendDraw> order;
  lod::viewer::order_blended_draws(list, layout, blends, vd_blends, view, order);
  ASSERT_EQ(order.size(), 4u) << "batch 1 and view-dependent object 0 have no blended run";
  EXPECT_EQ(order[0].vd, 1u);
  EXPECT_FLOAT_EQ(order[0].depth, 39.f);
  EXPECT_EQ(order[1].instance, 1u);  // centre z = -1: 31 away
  EXPECT_EQ(order[2].instance, 0u);  // z = 2: 28
  EXPECT_EQ(order[3].instance, 2u);  // z = -1 + 4 * 2 = 7: 23
  for (size_t k = 1; k < 4; ++k) EXPECT_EQ(order[k].vd, lod::viewer::kNotViewDependent);
  EXPECT_FLOAT_EQ(order[1].depth, 31.f);
  EXPECT_FLOAT_EQ(order[3].depth, 23.f);
}

}  // namespace
