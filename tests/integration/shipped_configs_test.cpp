// Every config the repository ships runs: `lod run --validate` on a few frames of each.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "test_support.h"

namespace {

struct Result {
  int code = -1;
  std::string out;
};

Result run(const std::string& args) {
  const std::string cmd = std::string(LOD_CLI_PATH) + " " + args + " 2>&1";
  Result r;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

class ShippedConfig : public ::testing::TestWithParam<const char*> {};

TEST_P(ShippedConfig, RunsAndEveryFrameValidates) {
  const std::string name = GetParam();
  const auto config = std::filesystem::path(LOD_SOURCE_DIR) / "configs" / (name + ".toml");
  ASSERT_TRUE(std::filesystem::exists(config)) << config;
  if (name == "stress-scans") {
    if (lod::test::shared_meshes().empty()) GTEST_SKIP() << "needs ../shared/data/meshes (absent on this machine)";
  } else if (lod::test::data_dir().empty()) {
    GTEST_SKIP() << "needs Debian's CGAL meshes (libcgal-demo) extracted into " << LOD_DATA_DIR;
  }
  // One cache for all configs of this build, so the default models bake once.
  const auto cache = std::filesystem::path(LOD_BINARY_DIR) / "test-cache";
  const auto json = lod::test::temp_dir("config-" + name) / "run.json";
  const auto r = run("run --config " + config.string() + " --frames 30 --validate --quiet --cache " + cache.string() +
                     " --json " + json.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("summary: 30 frames"), std::string::npos) << r.out;
  EXPECT_TRUE(std::filesystem::exists(json));
}

INSTANTIATE_TEST_SUITE_P(Configs, ShippedConfig,
                         ::testing::Values("default", "threads-1", "stress-10k", "stress-100k", "stress-scans",
                                           "vdlod"),
                         [](const auto& info) {
                           std::string s = info.param;
                           for (auto& c : s)
                             if (c == '-') c = '_';
                           return s;
                         });

}  // namespace
