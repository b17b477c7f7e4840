// End to end: [scene_hlod] in `lod run`: far away, merged proxies draw the static objects with
// far fewer draws and triangles than the per-object path at the same pixel error, every frame
// passes --validate (no object both in a proxy and on its own, counts add up), and bad
// [scene_hlod] values are refused naming the key.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "run_cli.h"
#include "test_support.h"

namespace {

using lod::test::run_lod;

using lod::test::read_json;

// 600 static spheres of two sizes on a 600 x 600 field and 20 that wander; the camera comes
// in from 4 km to 30 m over the field.
std::filesystem::path write_field(const std::filesystem::path& dir, const std::string& scene_hlod) {
  lod::test::write_text(dir / "ball.off", lod::test::sphere_off(16, 32));
  lod::test::write_text(dir / "big.off", lod::test::sphere_off(24, 48));
  const auto cfg = dir / "scene.toml";
  using namespace lod::test;
  const std::string wander = "motion = \"wander\"\nspeed = 5.0\n";
  write_text(cfg, run_block(40) + budget_block(10000000) + "[lod]\npixel_error = 1.0\n\n" + scene_hlod + "\n" +
                      keyframe_camera_block(0.5, 100000, {{0, "[0.0, 2000.0, 4000.0]", "[0.0, 0.0, 0.0]"},
                                                          {39, "[0.0, 30.0, 330.0]", "[0.0, 10.0, 0.0]"}}) +
                      model_block("ball", "ball.off", "[1.0, 0.25, 0.08]") +
                      model_block("big", "big.off", "[1.0, 0.25, 0.08]") +
                      scattered_block("ball", 400, 300, "scale_range = [2.0, 4.0]\n") +
                      scattered_block("big", 200, 300, "scale_range = [3.0, 5.0]\n") + scattered_block("ball", 20, 300, wander));
  return cfg;
}

nlohmann::json run_field(const std::string& tag, const std::string& scene_hlod) {
  const auto dir = lod::test::temp_dir("lodrun-scene-hlod-" + tag);
  const auto cfg = write_field(dir, scene_hlod);
  const auto r = run_lod("run --config " + cfg.string() + " --validate --quiet --cache " + (dir / "cache").string() +
                         " --json " + (dir / "run.json").string());
  EXPECT_EQ(r.code, 0) << r.out;
  if (r.code != 0) return {};
  return read_json(dir / "run.json");
}

TEST(LodRunSceneHlod, FarAwayProxiesCutDrawsAndTrianglesAtTheSamePixelError) {
  const auto on = run_field("on", "[scene_hlod]\nenabled = true\n");
  const auto off = run_field("off", "");
  ASSERT_EQ(on["frames"].size(), 40u);
  ASSERT_EQ(off["frames"].size(), 40u);
  EXPECT_GT(on["summary"]["scene_hlod_nodes"].get<uint64_t>(), 10u);
  EXPECT_EQ(off["summary"]["scene_hlod_nodes"].get<uint64_t>(), 0u);
  for (size_t i = 0; i < 40; ++i) {
    const auto& a = on["frames"][i];
    const auto& b = off["frames"][i];
    for (const char* key : {"scene_proxies", "proxy_objects", "proxy_tris", "draws"}) ASSERT_TRUE(a.contains(key)) << key;
    EXPECT_LE(a["draws"].get<uint64_t>(), b["draws"].get<uint64_t>()) << "frame " << i;
    EXPECT_LE(a["tris_selected"].get<uint64_t>(), b["tris_selected"].get<uint64_t>()) << "frame " << i;
    EXPECT_EQ(b["scene_proxies"].get<uint64_t>(), 0u);
  }
  // Far field: the first frames, 4 km out.
  for (size_t i = 0; i < 5; ++i) {
    const auto& a = on["frames"][i];
    const auto& b = off["frames"][i];
    EXPECT_GE(b["draws"].get<double>(), 3 * a["draws"].get<double>()) << "frame " << i;
    EXPECT_LT(a["tris_selected"].get<uint64_t>(), b["tris_selected"].get<uint64_t>()) << "frame " << i;
    EXPECT_GT(a["proxy_objects"].get<uint64_t>(), 0u);
    EXPECT_LE(a["proxy_objects"].get<uint64_t>(), 600u) << "the wandering objects are never in a proxy";
  }
}

TEST(LodRunSceneHlod, BadSettingsAreRefusedNamingTheKey) {
  const auto dir = lod::test::temp_dir("lodrun-scene-hlod-bad");
  for (const char* bad : {"[scene_hlod]\nenabled = 1\n", "[scene_hlod]\nreduction = 1.5\n",
                          "[scene_hlod]\nmin_objects = 1\n", "[scene_hlod]\nsplit = true\n"}) {
    const auto cfg = write_field(dir, bad);
    const auto r = run_lod("run --config " + cfg.string() + " --frames 1 --quiet --cache " + (dir / "cache").string());
    EXPECT_NE(r.code, 0) << bad;
    EXPECT_NE(r.out.find("scene_hlod"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("scene.toml"), std::string::npos) << r.out;
  }
}

}  // namespace
