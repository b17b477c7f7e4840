// End to end with a terrain: `lod run --validate --json` on configs/terrain.toml (the deal.II
// step-53 topography, fetched by scripts/fetch-topography.sh) and on a generated height field.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "run_cli.h"
#include "test_support.h"

namespace {

namespace fs = std::filesystem;
using lod::test::run_lod;

// The fetched topography: in this build's data directory, or in build/data of the source tree.
fs::path topography() {
  for (const fs::path& p : {fs::path(LOD_DATA_DIR) / "topography.txt",
                            fs::path(LOD_SOURCE_DIR) / "build" / "data" / "topography.txt"})
    if (fs::is_regular_file(p)) return p;
  return {};
}

std::string read_text(const fs::path& p) {
  std::ifstream f(p);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

// Every frame: terrain drawn, the budget held, and the frame keys there; with `merging`, merges
// behind the flying camera.
void expect_terrain_frames(const fs::path& json, size_t frames, bool merging = true) {
  std::ifstream f(json);
  const nlohmann::json j = nlohmann::json::parse(f);
  ASSERT_EQ(j["frames"].size(), frames);
  uint64_t splits = 0, merges = 0;
  for (const auto& fr : j["frames"]) {
    ASSERT_TRUE(fr.contains("terrain_tris") && fr.contains("terrain_splits") && fr.contains("terrain_merges"));
    EXPECT_GT(fr["terrain_tris"].get<uint64_t>(), 0u);
    EXPECT_FALSE(fr["over_budget"].get<bool>()) << "frame " << fr["frame"];
    EXPECT_LE(fr["tris_selected"].get<uint64_t>(), fr["budget"].get<uint64_t>()) << "frame " << fr["frame"];
    EXPECT_TRUE(fr["ms"].contains("terrain"));
    splits += fr["terrain_splits"].get<uint64_t>();
    merges += fr["terrain_merges"].get<uint64_t>();
  }
  EXPECT_GT(splits, 0u);
  if (merging) {
    EXPECT_GT(merges, 0u) << "the flying camera leaves detail behind";
  }
  EXPECT_EQ(j["summary"]["terrain_failures"].get<uint64_t>(), 0u);
  EXPECT_GT(j["summary"]["mean_terrain_tris"].get<double>(), 0.0);
}

TEST(LodRunTerrain, ShippedTerrainConfigValidatesOnTheRealTopography) {
  const fs::path topo = topography();
  if (topo.empty()) GTEST_SKIP() << "topography.txt absent: run scripts/fetch-topography.sh (into " << LOD_DATA_DIR << ")";
  if (lod::test::data_dir().empty()) GTEST_SKIP() << "needs Debian's CGAL meshes extracted into " << LOD_DATA_DIR;
  // The shipped config, pointed at wherever the topography was fetched.
  const fs::path dir = lod::test::temp_dir("run_terrain");
  std::string text = read_text(fs::path(LOD_SOURCE_DIR) / "configs" / "terrain.toml");
  const std::string key = "file = \"topography.txt\"";
  const size_t at = text.find(key);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, key.size(), "file = \"" + topo.string() + "\"");
  lod::test::write_text(dir / "terrain.toml", text);
  const auto r = run_lod("run --config " + (dir / "terrain.toml").string() + " --frames 120 --validate --quiet --cache " +
                         (fs::path(LOD_BINARY_DIR) / "test-cache").string() + " --json " + (dir / "run.json").string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("0 frames failed the crack check"), std::string::npos) << r.out;
  expect_terrain_frames(dir / "run.json", 120);
}

// A generated 65 x 65 field in metres under 30 spheres; `terrain` = the [[terrain]] keys.
fs::path generated_terrain_scene(const fs::path& dir, const std::string& terrain) {
  std::string grid;
  for (int y = 0; y < 65; ++y)
    for (int x = 0; x < 65; ++x)
      grid += std::to_string(4 * x) + " " + std::to_string(4 * y) + " " +
              std::to_string(8 * std::sin(0.2 * x) * std::cos(0.15 * y) - 10) + "\n";
  using namespace lod::test;
  write_text(dir / "hills.txt", grid);
  write_text(dir / "ball.off", sphere_off(30, 60));
  write_text(dir / "scene.toml", run_block(60) + budget_block(12000) +
                                     orbit_camera_block({.radius = 80, .height_above = 12, .period_frames = 60}) +
                                     "[[terrain]]\nfile = \"hills.txt\"\n" + terrain + "\n" +
                                     model_block("ball", "ball.off") + scattered_block("ball", 30, 100, "scale = 3.0\n"));
  return dir / "scene.toml";
}

// No downloaded data needed.
TEST(LodRunTerrain, GeneratedTerrainValidatesWithinTheBudget) {
  const fs::path dir = lod::test::temp_dir("run_terrain_gen");
  const auto r = lod::test::run_scene(generated_terrain_scene(dir, "pixel_error = 0.5\n"), dir, "--validate");
  ASSERT_EQ(r.code, 0) << r.out;
  expect_terrain_frames(dir / "run.json", 60);
}

// The time target: crack-free and within M every frame, whatever the clock cut; the frames say
// whether it did. (A clock this short keeps it growing towards its share: no merges needed.)
TEST(LodRunTerrain, TimeTargetValidatesAndReportsTheClock) {
  const fs::path dir = lod::test::temp_dir("run_terrain_time");
  const auto r =
      lod::test::run_scene(generated_terrain_scene(dir, "target = \"time\"\nmax_ms = 0.02\n"), dir, "--validate");
  ASSERT_EQ(r.code, 0) << r.out;
  expect_terrain_frames(dir / "run.json", 60, false);
  const auto j = lod::test::read_json(dir / "run.json");
  for (const auto& fr : j["frames"]) {
    ASSERT_TRUE(fr.contains("terrain_time_bound"));
    EXPECT_LE(fr["terrain_time_bound"].get<uint64_t>(), 1u);
  }
}

TEST(LodRunTerrain, BadTerrainKeyIsRefusedNamingIt) {
  const fs::path dir = lod::test::temp_dir("run_terrain_bad");
  lod::test::write_text(dir / "ball.off", lod::test::sphere_off(4, 8));
  lod::test::write_text(dir / "scene.toml",
                        "[[terrain]]\nfile = \"ball.off\"\nsamples = 100\n[[model]]\nname = \"ball\"\nfile = \"ball.off\"\n"
                        "[[instances]]\nmodel = \"ball\"\ncount = 1\n");
  const auto r = run_lod("run --config " + (dir / "scene.toml").string() + " --quiet --cache " + (dir / "cache").string());
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("terrain[0].samples"), std::string::npos) << r.out;
}

}  // namespace
