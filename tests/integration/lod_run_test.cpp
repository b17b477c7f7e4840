// End to end: the `lod` binary on small generated scenes, as a user runs it.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "run_cli.h"
#include "test_support.h"

namespace {

using lod::test::run_lod;

// A two-model scene of generated spheres: 400 objects, a budget that binds.
std::filesystem::path write_scene(const std::filesystem::path& dir, uint64_t budget) {
  return lod::test::balls_and_pebbles(dir, budget, "[1.0, 0.5, 0.25, 0.12, 0.06]");
}

using lod::test::read_json;

TEST(LodRun, WritesEveryFrameWithinBudgetAndCachesTheBake) {
  const auto dir = lod::test::temp_dir("lodrun");
  const auto cfg = write_scene(dir, 150000);
  const auto cache = dir / "cache";
  auto r = run_lod("run --config " + cfg.string() + " --cache " + cache.string() + " --json " +
                   (dir / "a.json").string() + " --report " + (dir / "report").string() + " --validate");
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j = read_json(dir / "a.json");
  ASSERT_EQ(j["frames"].size(), 24u);
  size_t binding = 0;
  for (const auto& f : j["frames"]) {
    for (const char* key : {"frame", "objects", "visible", "tris_in_view", "tris_selected", "level_cost", "budget",
                            "over_budget", "levels", "ms"})
      ASSERT_TRUE(f.contains(key)) << key;
    EXPECT_EQ(f["objects"], 400);
    EXPECT_TRUE(f["ms"].contains("total") && f["ms"].contains("selection") && f["ms"].contains("visibility"));
    if (!f["over_budget"].get<bool>()) {
      EXPECT_LE(f["tris_selected"].get<uint64_t>(), 150000u);
    }
    EXPECT_LE(f["tris_selected"].get<uint64_t>(), f["tris_in_view"].get<uint64_t>());
    uint64_t histogram = 0;
    for (auto& [l, count] : f["levels"].items()) histogram += count.get<uint64_t>();
    EXPECT_EQ(histogram, f["visible"].get<uint64_t>());
    binding += f["tris_in_view"].get<uint64_t>() > 150000u;
  }
  EXPECT_GT(binding, 0u) << "the test scene should make the budget bind";
  const auto& s = j["summary"];
  for (const char* key : {"frames", "over_budget_frames", "median_ms", "p99_ms", "bake_ms", "baked_models"})
    ASSERT_TRUE(s.contains(key)) << key;
  EXPECT_EQ(s["baked_models"], 2);
  for (const char* f : {"frames.csv", "summary.json", "triangles.svg", "stage_ms.svg", "graph.dot"})
    EXPECT_TRUE(std::filesystem::exists(dir / "report" / f)) << f;

  // Unchanged inputs: nothing is baked the second time.
  r = run_lod("run --config " + cfg.string() + " --cache " + cache.string() + " --quiet --json " +
              (dir / "b.json").string());
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j2 = read_json(dir / "b.json");
  EXPECT_EQ(j2["summary"]["baked_models"], 0);
  EXPECT_EQ(j2["summary"]["cached_models"], 2);
  // Same inputs, same selection.
  for (size_t i = 0; i < 24; ++i)
    EXPECT_EQ(j["frames"][i]["tris_selected"], j2["frames"][i]["tris_selected"]) << "frame " << i;

  // A changed mesh is baked again, the other one still comes from the cache.
  lod::test::write_text(dir / "pebble.off", lod::test::sphere_off(14, 24));
  r = run_lod("run --config " + cfg.string() + " --cache " + cache.string() + " --quiet --json " +
              (dir / "c.json").string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(read_json(dir / "c.json")["summary"]["baked_models"], 1);
}

TEST(LodRun, FlagsFramesWhoseCoarsestLevelsExceedTheBudget) {
  const auto dir = lod::test::temp_dir("lodrun-over");
  const auto cfg = write_scene(dir, 100);
  auto r = run_lod("run --config " + cfg.string() + " --cache " + (dir / "cache").string() + " --quiet --json " +
                   (dir / "o.json").string() + " --validate");
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j = read_json(dir / "o.json");
  EXPECT_EQ(j["summary"]["over_budget_frames"], 24);
  for (const auto& f : j["frames"]) {
    EXPECT_TRUE(f["over_budget"].get<bool>());
    EXPECT_GT(f["tris_selected"].get<uint64_t>(), 100u);
  }
}

TEST(LodRun, RefusesABadConfigNamingTheFile) {
  const auto dir = lod::test::temp_dir("lodrun-bad");
  const auto cfg = dir / "broken.toml";
  lod::test::write_text(cfg, "[run]\nframes = -5\n");
  auto r = run_lod("run --config " + cfg.string() + " --cache " + (dir / "cache").string());
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("broken.toml"), std::string::npos) << r.out;

  lod::test::write_text(cfg, "[run\nframes = 5\n");
  r = run_lod("run --config " + cfg.string());
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("broken.toml"), std::string::npos) << r.out;

  r = run_lod("run --config " + (dir / "missing.toml").string());
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("missing.toml"), std::string::npos) << r.out;
}

TEST(LodRun, RefusesAMissingOrMalformedMeshNamingIt) {
  const auto dir = lod::test::temp_dir("lodrun-mesh");
  const auto cfg = write_scene(dir, 150000);
  lod::test::write_text(dir / "pebble.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n");  // truncated
  auto r = run_lod("run --config " + cfg.string() + " --cache " + (dir / "cache").string());
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("pebble.off"), std::string::npos) << r.out;
  // Nothing half-written for the model that failed.
  for (const auto& e : std::filesystem::directory_iterator(dir / "cache"))
    EXPECT_EQ(e.path().filename().string().find("pebble"), std::string::npos) << e.path();
}

TEST(LodInspect, PrintsLevelsAndExportsPly) {
  const auto dir = lod::test::temp_dir("inspect");
  lod::test::write_text(dir / "ball.off", lod::test::sphere_off(30, 60));
  auto r = run_lod("bake " + (dir / "ball.off").string() + " -o " + (dir / "out").string() + " --measure");
  ASSERT_EQ(r.code, 0) << r.out;
  std::filesystem::path asset;
  for (const auto& e : std::filesystem::directory_iterator(dir / "out"))
    if (e.path().extension() == ".lod") asset = e.path();
  ASSERT_FALSE(asset.empty());
  r = run_lod("inspect " + asset.string() + " --json --export " + (dir / "ply").string());
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_GE(j["levels"].size(), 4u);
  EXPECT_EQ(j["levels"][0]["triangles"], 2 * 60 * 29);
  for (size_t i = 1; i < j["levels"].size(); ++i) {
    EXPECT_LT(j["levels"][i]["triangles"], j["levels"][i - 1]["triangles"]);
    EXPECT_GE(j["levels"][i]["error"].get<double>(), j["levels"][i - 1]["error"].get<double>());
    EXPECT_TRUE(std::filesystem::exists(dir / "ply" / ("ball-level" + std::to_string(i) + ".ply")));
  }
  // A corrupted asset is refused by inspect with the file's name.
  auto bytes = lod::test::read_bytes(asset);
  bytes[bytes.size() / 2] ^= 0x5a;
  lod::test::write_bytes(dir / "bad.lod", bytes);
  r = run_lod("inspect " + (dir / "bad.lod").string());
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("bad.lod"), std::string::npos) << r.out;
}

}  // namespace
