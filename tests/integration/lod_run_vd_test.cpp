// End to end with a view-dependent model: `lod run --validate --json` on a generated scene
// whose big sphere has view_dependent = true.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "test_support.h"

namespace {

int run_lod_vd(const std::string& args, std::string* out) {
  const std::string cmd = std::string(LOD_CLI_PATH) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return -1;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out->append(buf, n);
  const int status = pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::filesystem::path write_vd_scene(const std::filesystem::path& dir, const std::string& flag) {
  lod::test::write_text(dir / "ball.off", lod::test::sphere_off(60, 120));  // 14,160 triangles
  lod::test::write_text(dir / "pebble.off", lod::test::sphere_off(12, 24));
  const auto cfg = dir / "scene.toml";
  lod::test::write_text(cfg, R"([run]
frames = 40
threads = 2

[budget]
triangles = 30000

[camera]
path = "orbit"
center = [0, 0, 0]
radius = 60.0
height_above = 10.0
period_frames = 80
width = 640
height = 360

[[model]]
name = "ball"
file = "ball.off"
ratios = [1.0, 0.5, 0.25, 0.12]
view_dependent = )" + flag + R"(

[[model]]
name = "pebble"
file = "pebble.off"

[[instances]]
model = "ball"
count = 1
placement = "grid"
box_min = [0, 0, 0]
box_max = [0, 0, 0]
scale = 20.0

[[instances]]
model = "pebble"
count = 100
box_min = [-100, 0, -100]
box_max = [100, 0, 100]
seed = 2
)");
  return cfg;
}

TEST(LodRunVd, ValidatesEveryViewDependentFrameAndReportsItsFigures) {
  const auto dir = lod::test::temp_dir("run_vd");
  const auto cfg = write_vd_scene(dir, "true");
  std::string out;
  const int code = run_lod_vd("run --config " + cfg.string() + " --cache " + (dir / "cache").string() +
                                  " --validate --quiet --json " + (dir / "run.json").string(),
                              &out);
  ASSERT_EQ(code, 0) << out;
  EXPECT_NE(out.find("vertex hierarchy"), std::string::npos) << out;
  std::ifstream f(dir / "run.json");
  const nlohmann::json j = nlohmann::json::parse(f);
  ASSERT_EQ(j["frames"].size(), 40u);
  uint64_t splits = 0;
  for (const auto& fr : j["frames"]) {
    ASSERT_TRUE(fr.contains("vd_active_tris"));
    ASSERT_TRUE(fr.contains("vd_collapses"));
    ASSERT_TRUE(fr["ms"].contains("vdlod"));
    ASSERT_TRUE(fr["ms"].contains("geomorph"));
    EXPECT_GT(fr["vd_active_tris"].get<uint64_t>(), 0u);
    splits += fr["vd_splits"].get<uint64_t>();
  }
  EXPECT_GT(splits, 0u);
  // A second run takes the hierarchy from the cache.
  out.clear();
  ASSERT_EQ(
      run_lod_vd("run --config " + cfg.string() + " --cache " + (dir / "cache").string() + " --quiet", &out),
      0)
      << out;
  EXPECT_EQ(out.find("vertex hierarchy"), std::string::npos) << out;
}

TEST(LodRunVd, RefusesANonBooleanViewDependentKey) {
  const auto dir = lod::test::temp_dir("run_vd_bad");
  const auto cfg = write_vd_scene(dir, "\"yes\"");
  std::string out;
  EXPECT_EQ(
      run_lod_vd("run --config " + cfg.string() + " --cache " + (dir / "cache").string() + " --quiet", &out),
      1);
  EXPECT_NE(out.find("model[0].view_dependent: must be true or false"), std::string::npos) << out;
}

}  // namespace
