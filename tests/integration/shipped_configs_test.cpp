// Every config the repository ships runs: `lod run --validate` on a few frames of each.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "run_cli.h"
#include "test_support.h"

namespace {

using lod::test::run_lod;

class ShippedConfig : public ::testing::TestWithParam<const char*> {};

TEST_P(ShippedConfig, RunsAndEveryFrameValidates) {
  const std::string name = GetParam();
  const auto config = std::filesystem::path(LOD_SOURCE_DIR) / "configs" / (name + ".toml");
  ASSERT_TRUE(std::filesystem::exists(config)) << config;
  if (name == "stress-scans") {
    if (lod::test::shared_meshes().empty()) GTEST_SKIP() << "needs ../shared/data/meshes (absent on this machine)";
  } else if (name == "terrain" && !std::filesystem::exists(std::filesystem::path(LOD_DATA_DIR) / "topography.txt")) {
    GTEST_SKIP() << "needs topography.txt in " << LOD_DATA_DIR << " (scripts/fetch-topography.sh " << LOD_DATA_DIR << ")";
  } else if (lod::test::data_dir().empty()) {
    GTEST_SKIP() << "needs Debian's CGAL meshes (libcgal-demo) extracted into " << LOD_DATA_DIR;
  }
  // One cache for all configs of this build, so the default models bake once.
  const auto cache = std::filesystem::path(LOD_BINARY_DIR) / "test-cache";
  const auto json = lod::test::temp_dir("config-" + name) / "run.json";
  const auto r = run_lod("run --config " + config.string() + " --frames 30 --validate --quiet --cache " + cache.string() +
                     " --json " + json.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("summary: 30 frames"), std::string::npos) << r.out;
  EXPECT_TRUE(std::filesystem::exists(json));
}

INSTANTIATE_TEST_SUITE_P(Configs, ShippedConfig,
                         ::testing::Values("default", "threads-1", "stress-10k", "stress-100k", "stress-scans", "town", "traffic", "hlod", "scene-hlod",
                                           "vdlod", "terrain"),
                         [](const ::testing::TestParamInfo<const char*>& param_info) {
                           std::string s = param_info.param;
                           for (auto& c : s)
                             if (c == '-') c = '_';
                           return s;
                         });

}  // namespace
