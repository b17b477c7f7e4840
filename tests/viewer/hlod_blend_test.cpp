// Blended HLOD runs are a pass of their own, after all opaque geometry (viewer/blend_order.h):
// an HLOD model of a half-transparent blue pane in front of an opaque red quad, the pane's
// material numbered first (so its run comes first in the node, and drawn in the main pass it
// would write depth and hide the quad). Quads written as glTF at test time, seen by the tests'
// front camera (eye at z = 30 looking at the origin).
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "preprocess/gltf_write.h"
#include "viewer/blend_order.h"
#include "viewer/picture_checks.h"
#include "viewer/viewer_harness.h"

namespace {

namespace fs = std::filesystem;
using lod::test::Image;

// Model space: the pane [-2, 2]^2 at z = 1 (material 0, BLEND, alpha 0.5, blue) and the quad
// [-1, 1]^2 at z = -1 (material 1, opaque red), both facing the camera (+z).
void write_pane_over_quad(const fs::path& file) {
  const std::vector<float> positions = {-2, -2, 1, 2, -2, 1, 2, 2, 1, -2, 2, 1,
                                        -1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1};
  std::vector<float> normals;
  for (int v = 0; v < 8; ++v) normals.insert(normals.end(), {0, 0, 1});
  const std::vector<uint32_t> indices = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};
  lod::GltfMeshView view;
  view.name = "pane";
  view.positions = positions.data();
  view.normals = normals.data();
  view.vertex_count = 8;
  view.indices = indices.data();
  view.index_count = indices.size();
  lod::GltfMaterialView pane, quad;
  pane.name = "glass";
  pane.base_color[0] = 0.05f, pane.base_color[1] = 0.05f, pane.base_color[2] = 0.9f, pane.base_color[3] = 0.5f;
  pane.alpha_mode = lod::AlphaMode::blend;
  quad.name = "red";
  quad.base_color[0] = 0.9f, quad.base_color[1] = 0.05f, quad.base_color[2] = 0.05f;
  for (lod::GltfMaterialView* m : {&pane, &quad}) m->metallic = 0, m->roughness = 1, m->double_sided = true;
  view.materials = {pane, quad};
  view.submeshes = {{0, 6, 0}, {6, 6, 1}};
  fs::create_directories(file.parent_path());
  const lod::Status saved = lod::save_gltf(file, view);
  ASSERT_TRUE(saved.ok) << saved.message;
}

const char* kRun = "[run]\nframes = 3\nthreads = 1\n[budget]\ntriangles = 1000000\n[lod]\npixel_error = 1.0\n";
const char* kModel = "[[model]]\nname = \"pane\"\nfile = \"quads/pane.gltf\"\nhlod = true\n";

TEST(ViewerHlodBlend, ABlendedHlodPaneShowsTheOpaqueQuadBehindIt) {
  LOD_REQUIRE_XVFB();
  // The quads face the camera squarely (seed 1061).
  const auto scene = lod::test::write_viewer_scene("hlod-blend", kRun, lod::test::front_camera(320, 240),
                                                   lod::test::one_object_at_origin("pane", 4, 1061), kModel);
  write_pane_over_quad(scene.dir / "quads" / "pane.gltf");
  const auto shot = lod::test::take_screenshot(scene, "pane", "--frames 3 --width 320 --height 240");
  ASSERT_EQ(shot.run.exit_code, 0) << shot.run.output;
  ASSERT_TRUE(shot.stats_read);
  ASSERT_FALSE(shot.stats.rows.empty());
  EXPECT_GT(shot.stats.last("hlod_draws"), 0) << "drawn through its HLOD cut";
  ASSERT_TRUE(shot.image_read);
  const Image& img = shot.image;
  // World: the pane at z = 4 spans +-8, the quad at z = -4 spans +-4. The centre sees the
  // quad through the pane; (6, 0, 4) the pane over the background only.
  const auto centre = lod::test::project({0, 0, 4}, img.width, img.height);
  const auto side = lod::test::project({6, 0, 4}, img.width, img.height);
  const uint8_t* through = img.at(centre[0], centre[1]);
  const uint8_t* pane_only = img.at(side[0], side[1]);
  std::printf("pane over the quad %d %d %d, pane over the background %d %d %d\n", through[0], through[1], through[2],
              pane_only[0], pane_only[1], pane_only[2]);
  EXPECT_FALSE(lod::test::is_background(pane_only)) << "the pane is drawn";
  EXPECT_GT(pane_only[2], pane_only[0] + 20) << "in its own blue";
  EXPECT_GT(int(through[0]), int(pane_only[0]) + 40) << "the red quad shows through the blended pane";
  EXPECT_GT(through[2], 40) << "and the pane is blended over it, not left out";
}

// The CPU order: HLOD node draws with a blended run sorted in among the instances by their
// node's bounding sphere centre placed by the model's transform; those without left out.
TEST(BlendOrder, SortsHlodDrawsAmongInstancesByTheirNodeCentre) {
  auto at = [](float z, float scale) {
    lod::viewer::InstanceData d{};
    d.position_scale[2] = z, d.position_scale[3] = scale;
    d.rotation[3] = 1;
    return d;
  };
  lod::viewer::MeshLayout layout;
  layout.ranges.resize(1);
  lod::viewer::DrawList list;
  list.instances = {at(0, 1)};  // 30 away
  list.batches = {{0, 0, 0, 0, 0, 1}};
  lod::viewer::HlodDrawList hlod;
  hlod.draws.resize(3);
  hlod.draws[0].transform = at(-5, 2);  // centre z = -5 + 2 * 1 = -3: 33 away
  hlod.draws[0].center[2] = 1;
  hlod.draws[1].transform = at(10, 1);  // no blended run
  hlod.draws[2].transform = at(5, 1);   // 25 away
  lod::View eye;
  eye.eye = {0, 0, 30};
  eye.target = {0, 0, 0};
  std::vector<lod::viewer::BlendDraw> order;
  lod::viewer::order_blended_draws(list, layout, {1}, {}, hlod, {1, 0, 1}, lod::view_matrix(eye), order);
  ASSERT_EQ(order.size(), 3u) << "HLOD draw 1 has no blended run";
  EXPECT_EQ(order[0].hlod, 0u);
  EXPECT_FLOAT_EQ(order[0].depth, 33.f);
  EXPECT_EQ(order[1].hlod, lod::viewer::kNotHlod);
  EXPECT_EQ(order[1].vd, lod::viewer::kNotViewDependent);
  EXPECT_EQ(order[1].instance, 0u);
  EXPECT_EQ(order[2].hlod, 2u);
  EXPECT_FLOAT_EQ(order[2].depth, 25.f);
}

}  // namespace
