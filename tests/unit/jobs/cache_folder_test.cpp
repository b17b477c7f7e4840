// Where baked models are cached: an explicit folder, then the config's [cache] dir, then
// $LOD_CACHE_DIR, $XDG_CACHE_HOME/lodkit, $HOME/.cache/lodkit, a temp folder; never the build
// tree. Checked through cache_dir_for, the config loader and Service::from_config.
#include "jobs/cache_folder.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <string>

#include "jobs/scene_config.h"
#include "lodkit/service.hpp"
#include "test_support.h"

namespace lod {
namespace {

namespace fs = std::filesystem;

// Sets or clears the variables cache_dir_for reads for one test, and puts them back after.
class CacheEnvironment : public ::testing::Test {
 protected:
  static constexpr const char* kNames[] = {"LOD_CACHE_DIR", "XDG_CACHE_HOME", "HOME"};

  void SetUp() override {
    for (size_t i = 0; i < 3; ++i) {
      const char* v = std::getenv(kNames[i]);
      saved_[i] = v ? std::optional<std::string>(v) : std::nullopt;
      ::unsetenv(kNames[i]);
    }
  }
  void TearDown() override {
    for (size_t i = 0; i < 3; ++i) {
      if (saved_[i])
        ::setenv(kNames[i], saved_[i]->c_str(), 1);
      else
        ::unsetenv(kNames[i]);
    }
  }
  static void set(const char* name, const fs::path& value) { ::setenv(name, value.c_str(), 1); }

 private:
  std::optional<std::string> saved_[3];
};

TEST_F(CacheEnvironment, PrecedenceIsAskedConfigEnvironmentXdgHomeTemp) {
  const fs::path base = test::temp_dir("cache-precedence");
  set("HOME", base / "home");
  set("XDG_CACHE_HOME", base / "xdg");
  set("LOD_CACHE_DIR", base / "env");
  EXPECT_EQ(cache_dir_for(base / "asked", base / "config"), base / "asked");
  EXPECT_EQ(cache_dir_for({}, base / "config"), base / "config");
  EXPECT_EQ(cache_dir_for({}, {}), base / "env");
  ::unsetenv("LOD_CACHE_DIR");
  EXPECT_EQ(cache_dir_for({}, {}), base / "xdg" / "lodkit");
  ::unsetenv("XDG_CACHE_HOME");
  EXPECT_EQ(cache_dir_for({}, {}), base / "home" / ".cache" / "lodkit");
  ::unsetenv("HOME");
  EXPECT_EQ(cache_dir_for({}, {}), fs::temp_directory_path() / "lodkit-cache");
}

TEST_F(CacheEnvironment, EmptyVariablesAndARelativeXdgCacheHomeAreSkipped) {
  const fs::path base = test::temp_dir("cache-empty");
  ::setenv("LOD_CACHE_DIR", "", 1);
  ::setenv("XDG_CACHE_HOME", "relative/cache", 1);  // invalid by the XDG spec
  set("HOME", base / "home");
  EXPECT_EQ(cache_dir_for({}, {}), base / "home" / ".cache" / "lodkit");
  ::setenv("XDG_CACHE_HOME", "", 1);
  EXPECT_EQ(cache_dir_for({}, {}), base / "home" / ".cache" / "lodkit");
}

// A config next to a tiny mesh; `cache` is the [cache] table's text (may be empty).
fs::path write_scene(const fs::path& dir, const std::string& cache) {
  test::write_text(dir / "ball.off", test::sphere_off(6, 8));
  test::write_text(dir / "scene.toml", "[run]\nthreads = 1\n\n" + cache +
                                           "[[model]]\nname = \"ball\"\nfile = \"ball.off\"\n"
                                           "ratios = [1.0, 0.5]\n");
  return dir / "scene.toml";
}

bool holds_files(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return false;
  for (const auto& e : fs::recursive_directory_iterator(dir, ec))
    if (e.is_regular_file()) return true;
  return false;
}

TEST_F(CacheEnvironment, ConfigCacheDirIsReadRelativeToTheConfigFolder) {
  const fs::path dir = test::temp_dir("cache-config");
  SceneConfig c;
  ASSERT_TRUE(load_scene_config(write_scene(dir, "[cache]\ndir = \"baked/here\"\n\n"), {}, c, true).ok);
  EXPECT_EQ(c.cache_dir, dir / "baked" / "here");
  ASSERT_TRUE(load_scene_config(write_scene(dir, "[cache]\ndir = \"/abs/cache\"\n\n"), {}, c, true).ok);
  EXPECT_EQ(c.cache_dir, fs::path("/abs/cache"));
  ASSERT_TRUE(load_scene_config(write_scene(dir, ""), {}, c, true).ok);
  EXPECT_TRUE(c.cache_dir.empty());
  for (const char* bad : {"[cache]\ndir = \"\"\n\n", "[cache]\ndir = 3\n\n", "[cache]\nfolder = \"x\"\n\n"}) {
    const Status st = load_scene_config(write_scene(dir, bad), {}, c, true);
    EXPECT_FALSE(st.ok) << bad;
    EXPECT_NE(st.message.find("cache."), std::string::npos) << st.message;
    EXPECT_NE(st.message.find("scene.toml"), std::string::npos) << st.message;
  }
}

TEST_F(CacheEnvironment, ServiceBakesIntoTheConfigsFolderBeforeTheEnvironment) {
  const fs::path dir = test::temp_dir("cache-service-config");
  set("LOD_CACHE_DIR", dir / "env");
  std::string why;
  auto s = Service::from_config(write_scene(dir, "[cache]\ndir = \"mine\"\n\n"), &why);
  ASSERT_NE(s, nullptr) << why;
  EXPECT_TRUE(holds_files(dir / "mine"));
  EXPECT_FALSE(holds_files(dir / "env"));
}

TEST_F(CacheEnvironment, ServiceBakesIntoLodCacheDirThenTheUsersCacheFolder) {
  const fs::path dir = test::temp_dir("cache-service-env");
  set("HOME", dir / "home");
  set("XDG_CACHE_HOME", dir / "xdg");
  set("LOD_CACHE_DIR", dir / "env");
  std::string why;
  ASSERT_NE(Service::from_config(write_scene(dir, ""), &why), nullptr) << why;
  EXPECT_TRUE(holds_files(dir / "env"));
  EXPECT_FALSE(holds_files(dir / "xdg"));

  ::unsetenv("LOD_CACHE_DIR");
  ASSERT_NE(Service::from_config(write_scene(dir, ""), &why), nullptr) << why;
  EXPECT_TRUE(holds_files(dir / "xdg" / "lodkit"));
  EXPECT_FALSE(holds_files(dir / "home"));

  ::unsetenv("XDG_CACHE_HOME");
  ASSERT_NE(Service::from_config(write_scene(dir, ""), &why), nullptr) << why;
  EXPECT_TRUE(holds_files(dir / "home" / ".cache" / "lodkit"));
}

}  // namespace
}  // namespace lod
