// End to end with a view-dependent model: `lod run --validate --json` on a generated scene
// whose big sphere has view_dependent = true.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "run_cli.h"
#include "test_support.h"

namespace {

// `lod run` on the scene; its exit code, the output into `out`.
int run_lod_vd(const std::string& args, std::string* out) {
  const lod::test::CliResult r = lod::test::run_lod(args);
  *out += r.out;
  return r.code;
}

std::filesystem::path write_vd_scene(const std::filesystem::path& dir, const std::string& flag) {
  lod::test::write_text(dir / "ball.off", lod::test::sphere_off(60, 120));  // 14,160 triangles
  lod::test::write_text(dir / "pebble.off", lod::test::sphere_off(12, 24));
  const auto cfg = dir / "scene.toml";
  using namespace lod::test;
  write_text(cfg, run_block(40) + budget_block(30000) + orbit_camera_block({.radius = 60, .period_frames = 80}) +
                      model_block("ball", "ball.off", "[1.0, 0.5, 0.25, 0.12]", "view_dependent = " + flag + "\n") +
                      model_block("pebble", "pebble.off") + single_block("ball", "[0, 0, 0]", 20) +
                      scattered_block("pebble", 100, 100, "seed = 2\n"));
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
