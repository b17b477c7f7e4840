// End to end, budget modes: `lod run` explains once which models keep the coarsest levels over
// M and what last ratio would fit, --strict-exit fails such a run, a culled level (ratios
// ending in 0) and lod.max_distance make a budget reachable, both selectors meet it, and the
// report carries the selection figures.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "run_cli.h"
#include "test_support.h"

namespace {

using lod::test::run_lod;

// 300 balls (6,240 triangles) and 100 pebbles (528); `ball_ratios` and `extra` TOML vary it.
std::filesystem::path budget_scene(const std::filesystem::path& dir, uint64_t budget,
                                   const std::string& ball_ratios, const std::string& extra = "") {
  return lod::test::balls_and_pebbles(dir, budget, ball_ratios, "[1.0, 0.5, 0.25]", extra);
}

using lod::test::read_json;

std::string read_text(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

size_t count_of(const std::string& text, const std::string& part) {
  size_t n = 0;
  for (size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
  return n;
}

TEST(LodRunBudget, ExplainsOnceWhatKeepsTheCoarsestLevelsOverBudget) {
  const auto dir = lod::test::temp_dir("lodrun-shortfall");
  const auto cfg = budget_scene(dir, 20000, "[1.0, 0.5, 0.25, 0.12, 0.06]");
  const std::string base =
      "run --config " + cfg.string() + " --cache " + (dir / "cache").string() + " --quiet";
  auto r = run_lod(base + " --json " + (dir / "o.json").string());
  ASSERT_EQ(r.code, 0) << "without --strict-exit an over-budget run still succeeds\n" << r.out;
  EXPECT_EQ(count_of(r.out, "cannot be met"), 1u) << r.out;
  EXPECT_NE(r.out.find("budget 20,000 triangles cannot be met"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("of model 'ball' at their coarsest level 4 (374 triangles each)"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("model 'pebble' at their coarsest level 2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("a last ratio of 0.0"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("or culling, ratios ending in 0"), std::string::npos) << r.out;
  const auto j = read_json(dir / "o.json");
  EXPECT_EQ(j["summary"]["over_budget_frames"], 24) << "the summary counts every such frame";

  r = run_lod(base + " --strict-exit");
  EXPECT_EQ(r.code, 5) << r.out;
  EXPECT_NE(r.out.find("--strict-exit"), std::string::npos) << r.out;
}

TEST(LodRunBudget, ACulledLevelMeetsWhatTheCoarsestLevelsCannot) {
  const auto dir = lod::test::temp_dir("lodrun-culled");
  const auto cfg = budget_scene(dir, 20000, "[1.0, 0.5, 0.25, 0.12, 0.06, 0.0]");
  auto r = run_lod("run --config " + cfg.string() + " --cache " + (dir / "cache").string() +
                   " --quiet --strict-exit --validate --json " + (dir / "c.json").string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(r.out.find("cannot be met"), std::string::npos) << r.out;
  const auto j = read_json(dir / "c.json");
  EXPECT_EQ(j["summary"]["over_budget_frames"], 0);
  uint64_t culled = 0;
  for (const auto& f : j["frames"]) {
    EXPECT_FALSE(f["over_budget"].get<bool>());
    EXPECT_LE(f["tris_selected"].get<uint64_t>(), 20000u);
    culled += f["culled"].get<uint64_t>();
  }
  EXPECT_GT(culled, 0u);
}

TEST(LodRunBudget, MaxDistanceLeavesFarObjectsOut) {
  const auto dir = lod::test::temp_dir("lodrun-maxdist");
  const std::string ratios = "[1.0, 0.5, 0.25]";
  const auto cache = (dir / "cache").string();
  auto r = run_lod("run --config " + budget_scene(dir, 10000000, ratios).string() + " --cache " + cache +
                   " --quiet --json " + (dir / "all.json").string());
  ASSERT_EQ(r.code, 0) << r.out;
  r = run_lod("run --config " + budget_scene(dir, 10000000, ratios, "[lod]\nmax_distance = 60\n").string() +
              " --cache " + cache + " --quiet --validate --json " + (dir / "near.json").string());
  ASSERT_EQ(r.code, 0) << r.out;
  const auto all = read_json(dir / "all.json"), near = read_json(dir / "near.json");
  for (size_t i = 0; i < 24; ++i) {
    const auto &a = all["frames"][i], &n = near["frames"][i];
    EXPECT_EQ(a["visible"].get<uint64_t>(), n["visible"].get<uint64_t>() + n["culled"].get<uint64_t>())
        << "frame " << i << ": what the limit drops is counted culled";
    EXPECT_LT(n["visible"].get<uint64_t>(), a["visible"].get<uint64_t>()) << "frame " << i;
  }
}

TEST(LodRunBudget, BothSelectorsMeetTheBudgetAndTheReportShowsTheSelection) {
  const auto dir = lod::test::temp_dir("lodrun-selectors");
  const std::string ratios = "[1.0, 0.5, 0.25, 0.12, 0.06]";
  const auto cache = (dir / "cache").string();
  uint64_t pops[2] = {0, 0};
  int k = 0;
  for (const char* selector : {"greedy", "greedy_multi"}) {
    // A fine pixel threshold, so initial levels are finer than M allows.
    const auto cfg = budget_scene(dir, 200000, ratios, "[lod]\npixel_error = 0.05\n");
    std::string text = read_text(cfg);
    text.replace(text.find("[budget]"), 8, std::string("[budget]\nselector = \"") + selector + "\"");
    lod::test::write_text(cfg, text);
    const auto json = dir / (std::string(selector) + ".json");
    const auto report = dir / (std::string(selector) + "-report");
    auto r = run_lod("run --config " + cfg.string() + " --cache " + cache + " --quiet --validate --json " +
                     json.string() + " --report " + report.string());
    ASSERT_EQ(r.code, 0) << r.out;
    const auto j = read_json(json);
    for (const auto& f : j["frames"]) {
      for (const char* key : {"benefit", "culled", "level_changes", "pixel_error_max", "tris_drawn"})
        ASSERT_TRUE(f.contains(key)) << key;
      EXPECT_LE(f["tris_selected"].get<uint64_t>(), 200000u);
      EXPECT_GT(f["benefit"].get<double>(), 0.0);
      pops[k] += f["lowered_steps"].get<uint64_t>();
    }
    for (const char* file : {"drawn.svg", "levels.svg", "level_changes.svg", "pixel_error.svg", "frames.csv"})
      EXPECT_TRUE(std::filesystem::exists(report / file)) << file;
    const std::string csv = read_text(report / "frames.csv");
    const std::string header = csv.substr(0, csv.find('\n'));
    for (const char* column :
         {"tris_drawn", "tris_blend_extra", "benefit", "pixel_error_max", "level_changes"})
      EXPECT_NE(header.find(column), std::string::npos) << column;
    ++k;
  }
  ASSERT_GT(pops[0], 0u) << "the budget must bind";
  EXPECT_LE(pops[1], pops[0]) << "greedy_multi pops no more than greedy";
}

}  // namespace
