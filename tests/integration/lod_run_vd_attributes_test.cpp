// End to end with a view-dependent glTF that has COLOR_0, TEXCOORD_1 and smooth NORMALs:
// `lod bake` says nothing is dropped, `lod run --validate` builds the hierarchy with all three
// and checks every frame's vd_uvs1 / vd_colors / vd_normals, and `lod inspect` lists them on
// the cached asset's hierarchy.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "preprocess/gltf_write.h"
#include "run_cli.h"
#include "test_support.h"
#include "textured_fixture.h"

namespace {

namespace fs = std::filesystem;

// coloured_sphere (red north, blue south, TEXCOORD_1) with radial normals, as ball.gltf.
fs::path write_ball(const fs::path& dir) {
  lod::MeshData m = lod::test::coloured_sphere(24, 48);
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    const float* p = &m.positions[3 * v];
    const float len = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    m.normals.insert(m.normals.end(), {p[0] / len, p[1] / len, p[2] / len});
  }
  fs::create_directories(dir);
  lod::GltfMeshView view;
  view.name = "ball";
  view.positions = m.positions.data();
  view.normals = m.normals.data();
  view.vertex_count = m.vertex_count();
  view.uvs = m.uvs.data();
  view.uvs1 = m.uvs1.data();
  view.colors = m.colors.data();
  view.indices = m.indices.data();
  view.index_count = m.indices.size();
  const fs::path file = dir / "ball.gltf";
  EXPECT_TRUE(lod::save_gltf(file, view).ok);
  return file;
}

TEST(LodRunVdAttributes, ColoursAndSecondUvsReachEveryFrameAndTheCachedHierarchy) {
  const fs::path dir = lod::test::temp_dir("run_vd_attributes");
  const fs::path ball = write_ball(dir);
  // lod bake: the smooth normals are kept (no note says they are not); nothing is dropped.
  const lod::test::CliResult baked =
      lod::test::run_lod("bake " + ball.string() + " -o " + (dir / "out").string());
  ASSERT_EQ(baked.code, 0) << baked.out;
  EXPECT_EQ(baked.out.find("authored normals of"), std::string::npos) << baked.out;
  EXPECT_EQ(baked.out.find("not kept"), std::string::npos) << baked.out;

  using namespace lod::test;
  const fs::path cfg = dir / "scene.toml";
  write_text(cfg, run_block(30) + budget_block(30000) +
                      orbit_camera_block({.radius = 60, .period_frames = 60}) +
                      model_block("ball", ball.string(), "[1.0, 0.5, 0.25]", "view_dependent = true\n") +
                      single_block("ball", "[0, 0, 0]", 20));
  const CliResult run = run_lod("run --config " + cfg.string() + " --cache " + (dir / "cache").string() +
                                " --validate --json " + (dir / "run.json").string());
  ASSERT_EQ(run.code, 0) << run.out;
  EXPECT_NE(run.out.find("with uvs, TEXCOORD_1, colours, normals"), std::string::npos) << run.out;
  EXPECT_EQ(run.out.find("kept in the levels only"), std::string::npos) << run.out;
  const nlohmann::json j = read_json(dir / "run.json");
  ASSERT_EQ(j["frames"].size(), 30u);
  uint64_t tris = 0;
  for (const auto& fr : j["frames"]) tris += fr["vd_active_tris"].get<uint64_t>();
  EXPECT_GT(tris, 0u);

  // The cached asset's hierarchy carries them.
  fs::path asset;
  for (const auto& e : fs::directory_iterator(dir / "cache"))
    if (e.path().extension() == ".lod") asset = e.path();
  ASSERT_FALSE(asset.empty());
  const CliResult inspected = run_lod("inspect " + asset.string() + " --json");
  ASSERT_EQ(inspected.code, 0) << inspected.out;
  const nlohmann::json a = nlohmann::json::parse(inspected.out);
  EXPECT_TRUE(a["hierarchy_uvs"].get<bool>());
  EXPECT_TRUE(a["hierarchy_uvs1"].get<bool>());
  EXPECT_TRUE(a["hierarchy_colors"].get<bool>());
  EXPECT_TRUE(a["hierarchy_normals"].get<bool>());
  const CliResult text = run_lod("inspect " + asset.string());
  EXPECT_NE(text.out.find("TEXCOORD_1 per node, colours per node, authored normals per node"),
            std::string::npos)
      << text.out;
}

}  // namespace
