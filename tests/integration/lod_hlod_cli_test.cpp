// `lod bake --hlod` and `lod inspect FILE.hlod [--json]` end to end: the file is written with
// progress, the JSON has exactly the keys outside programs read, bad files are refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "run_cli.h"
#include "test_support.h"
#include "textured_fixture.h"

namespace {

namespace fs = std::filesystem;
using lod::test::run_lod;

TEST(LodHlodCli, BakesWithProgressAndInspectsAsJson) {
  const fs::path dir = lod::test::temp_dir("hlod_cli");
  const fs::path mesh = dir / "ball.off";
  lod::test::write_text(mesh, lod::test::sphere_off(60, 80));
  const auto baked = run_lod("bake " + mesh.string() + " -o " + (dir / "out").string() + " --hlod --min-verts 300");
  ASSERT_EQ(baked.code, 0) << baked.out;
  EXPECT_NE(baked.out.find("hlod ball 100%"), std::string::npos) << baked.out;
  const fs::path file = dir / "out" / "ball.hlod";
  ASSERT_TRUE(fs::exists(file)) << baked.out;

  const auto shown = run_lod("inspect " + file.string());
  ASSERT_EQ(shown.code, 0) << shown.out;
  EXPECT_NE(shown.out.find("model 'ball'"), std::string::npos) << shown.out;

  const auto json = run_lod("inspect " + file.string() + " --json");
  ASSERT_EQ(json.code, 0) << json.out;
  const nlohmann::json j = nlohmann::json::parse(json.out);
  ASSERT_TRUE(j["nodes"].is_array());
  ASSERT_GT(j["nodes"].size(), 8u);
  const std::set<std::string> keys = {"id", "parent", "depth", "leaf", "boundary_triangles", "layers", "material_runs"};
  for (size_t i = 0; i < j["nodes"].size(); ++i) {
    const auto& n = j["nodes"][i];
    std::set<std::string> got;
    for (const auto& [k, v] : n.items()) got.insert(k);
    EXPECT_EQ(got, keys) << "node " << i;
    EXPECT_EQ(n["id"], i);
    EXPECT_EQ(n["parent"].get<int>() < 0, i == 0) << "-1 at the root only";
    ASSERT_FALSE(n["layers"].empty());
    for (const auto& l : n["layers"]) {
      std::set<std::string> lk;
      for (const auto& [k, v] : l.items()) lk.insert(k);
      EXPECT_EQ(lk, (std::set<std::string>{"triangles", "error", "uv_error"}));
    }
  }
}

// Subtrees run as tbb tasks: the file must not depend on how many threads ran them.
TEST(LodHlodCli, SameFileAtOneAndTwoThreads) {
  const fs::path dir = lod::test::temp_dir("hlod_cli_threads");
  const fs::path mesh = dir / "ball.off";
  lod::test::write_text(mesh, lod::test::sphere_off(90, 120));
  for (const char* threads : {"1", "2"})
    ASSERT_EQ(run_lod("bake " + mesh.string() + " -o " + (dir / threads).string() + " --hlod --min-verts 200 --quiet --threads " +
                      threads)
                  .code,
              0);
  const auto one = lod::test::read_bytes(dir / "1" / "ball.hlod");
  ASSERT_GT(one.size(), 100000u);
  EXPECT_TRUE(one == lod::test::read_bytes(dir / "2" / "ball.hlod"));
  // A textured, two-material model too (uvs through QEM, layers grouped by material).
  const fs::path gltf = lod::test::write_two_material_gltf(dir / "src", "globe", 48, 96);
  ASSERT_FALSE(gltf.empty());
  for (const char* threads : {"1", "2"})
    ASSERT_EQ(run_lod("bake " + gltf.string() + " -o " + (dir / threads).string() + " --hlod --min-verts 200 --quiet --threads " +
                      threads)
                  .code,
              0);
  const auto globe = lod::test::read_bytes(dir / "1" / "globe.hlod");
  ASSERT_GT(globe.size(), 100000u);
  EXPECT_TRUE(globe == lod::test::read_bytes(dir / "2" / "globe.hlod")) << "the textured model at 1 and 2 threads";
  // Vertex colours and a second uv set: kept, nothing said dropped, the same file.
  const fs::path painted = lod::test::write_coloured_gltf(dir / "src", "painted", 48, 96);
  ASSERT_FALSE(painted.empty());
  for (const char* threads : {"1", "2"}) {
    const auto r = run_lod("bake " + painted.string() + " -o " + (dir / threads).string() +
                           " --hlod --min-verts 200 --threads " + threads);
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_EQ(r.out.find("not kept"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("does not keep"), std::string::npos) << r.out;
  }
  const auto coloured = lod::test::read_bytes(dir / "1" / "painted.hlod");
  EXPECT_TRUE(coloured == lod::test::read_bytes(dir / "2" / "painted.hlod")) << "the coloured model at 1 and 2 threads";
  const auto json = run_lod("inspect " + (dir / "1" / "painted.hlod").string() + " --json");
  ASSERT_EQ(json.code, 0) << json.out;
  const nlohmann::json j = nlohmann::json::parse(json.out);
  EXPECT_EQ(j["version"], 3);
  EXPECT_EQ(j["texcoords"], true);
  EXPECT_EQ(j["texcoords1"], true);
  EXPECT_EQ(j["colors"], true);
  ASSERT_EQ(j["materials"].size(), 1u);
  EXPECT_TRUE(j["materials"][0]["textures"].contains("occlusion")) << "the texture reading TEXCOORD_1 is kept";
  float worst = 0;
  for (const auto& n : j["nodes"])
    for (const auto& l : n["layers"]) {
      ASSERT_TRUE(l.contains("uv1_error") && l.contains("color_error"));
      worst = std::max(worst, l["color_error"].get<float>());
    }
  EXPECT_GT(worst, 0.0f);
}

TEST(LodHlodCli, RefusesACorruptedFileNamingIt) {
  const fs::path dir = lod::test::temp_dir("hlod_cli_bad");
  const fs::path mesh = dir / "ball.off";
  lod::test::write_text(mesh, lod::test::sphere_off(30, 40));
  ASSERT_EQ(run_lod("bake " + mesh.string() + " -o " + dir.string() + " --hlod --quiet").code, 0);
  std::vector<uint8_t> bytes = lod::test::read_bytes(dir / "ball.hlod");
  bytes[40] ^= 0x10;
  lod::test::write_bytes(dir / "ball.hlod", bytes);
  const auto r = run_lod("inspect " + (dir / "ball.hlod").string());
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("ball.hlod: head checksum mismatch"), std::string::npos) << r.out;
}

}  // namespace
