// End to end, the selectors: `[budget] selector = "benefit_cost"` runs through `lod run` and
// meets M, and `--json` gives each frame's fraction of the optimum (a scene of <= 300
// entries): in (0, 1], 1 when the budget is loose, its min and mean in the summary.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "run_cli.h"
#include "test_support.h"

namespace {

// 120 balls (6,240 triangles each at full detail, 374 at the coarsest) around an orbit; about
// 100 in view need 85k to 110k triangles at their initial levels.
std::filesystem::path small_scene(const std::filesystem::path& dir, uint64_t budget,
                                  const std::string& selector) {
  lod::test::write_text(dir / "ball.off", lod::test::sphere_off(40, 80));
  const auto cfg = dir / (selector + "-" + std::to_string(budget) + ".toml");
  using namespace lod::test;
  write_text(cfg, run_block(12) + "[lod]\npixel_error = 0.05\n\n" +
                      budget_block(budget, "reserve_blends = false\nselector = \"" + selector + "\"\n") +
                      orbit_camera_block({.period_frames = 12}) +
                      model_block("ball", "ball.off", "[1.0, 0.5, 0.25, 0.12, 0.06]") +
                      scattered_block("ball", 120, 100, "scale_range = [1.0, 3.0]\nseed = 7\n"));
  return cfg;
}

nlohmann::json run_json(const std::filesystem::path& dir, const std::filesystem::path& cfg) {
  const auto json = dir / (cfg.stem().string() + ".json");
  const auto r = lod::test::run_lod("run --config " + cfg.string() + " --cache " + (dir / "cache").string() +
                                    " --quiet --json " + json.string());
  EXPECT_EQ(r.code, 0) << r.out;
  return lod::test::read_json(json);
}

TEST(LodRunSelectors, FractionOfTheOptimumPerFrameForEverySelector) {
  const auto dir = lod::test::temp_dir("lodrun-optimum");
  for (const char* selector : {"greedy", "greedy_multi", "benefit_cost"}) {
    const auto j = run_json(dir, small_scene(dir, 60000, selector));
    uint64_t raised = 0;
    for (const auto& f : j["frames"]) {
      ASSERT_LE(f["visible"].get<uint64_t>(), 300u);
      EXPECT_LE(f["tris_selected"].get<uint64_t>(), 60000u) << selector;
      ASSERT_TRUE(f["benefit_optimum_fraction"].is_number()) << selector << ": measured under 300 entries";
      const double x = f["benefit_optimum_fraction"].get<double>();
      EXPECT_GT(x, 0.0);
      EXPECT_LE(x, 1.0);
      if (std::string(selector) == "benefit_cost") {
        EXPECT_GE(x, 0.5);
      }
      raised += f["lowered_steps"].get<uint64_t>();
    }
    EXPECT_GT(raised, 0u) << selector << ": the budget must bind";
    const auto& s = j["summary"];
    EXPECT_EQ(s["optimum_frames"].get<uint64_t>(), j["frames"].size());
    EXPECT_GT(s["min_benefit_optimum_fraction"].get<double>(), 0.0);
    EXPECT_LE(s["min_benefit_optimum_fraction"].get<double>(),
              s["mean_benefit_optimum_fraction"].get<double>());
    EXPECT_LE(s["mean_benefit_optimum_fraction"].get<double>(), 1.0);
  }
}

TEST(LodRunSelectors, LooseBudgetIsTheWholeOptimum) {
  const auto dir = lod::test::temp_dir("lodrun-optimum-loose");
  const auto j = run_json(dir, small_scene(dir, 100000000, "benefit_cost"));
  for (const auto& f : j["frames"]) {
    EXPECT_NEAR(f["benefit_optimum_fraction"].get<double>(), 1.0, 1e-9);
    EXPECT_TRUE(f["benefit_optimum_exact"].get<bool>());
  }
  EXPECT_NEAR(j["summary"]["min_benefit_optimum_fraction"].get<double>(), 1.0, 1e-9);
}

}  // namespace
