// Helpers for the lod-viewer tests: generated scenes (OFF meshes written from code), running
// the viewer binary under xvfb-run, and reading back its PNG and per-frame CSV.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace lod::test {

// Closed cube [-1, 1]^3 as OFF text, each face an n x n grid of quads (welded along edges).
std::string box_off(int n);

// A [camera] block of one keyframe at z = 30 looking at the origin (60 degrees, near 0.5, far 500).
std::string front_camera(int width, int height);

// An [[instances]] block of one `model` object at the origin, `scale` times its size; `seed`
// (when >= 0) picks the placement's yaw draw (seed 1061's first is -0.1 degrees: square on).
std::string one_object_at_origin(const std::string& model, float scale, int seed = -1);

struct ViewerScene {
  std::filesystem::path dir;     // holds config.toml, the meshes, the cache and outputs
  std::filesystem::path config;
};

// A scene of one generated sphere (2,304 triangles) and one generated box (3,072 triangles).
// `instances` and `camera` are TOML text appended after the [[model]] blocks; `extra_models`
// is more [[model]] blocks (they may use sphere.off / box.off).
ViewerScene write_viewer_scene(const std::string& tag, const std::string& budget_and_run, const std::string& camera,
                               const std::string& instances, const std::string& extra_models = "");

struct RunResult {
  int exit_code = -1;
  std::string output;  // stdout + stderr
};

bool have_xvfb();
// Runs lod-viewer with `args`, under `xvfb-run -a` when `headless`. The bake cache is the
// scene's own folder. Pictures are checked against the flat background colour, so the run
// starts with `--backdrop off`; a test that wants sky and ground passes `--backdrop on`.
RunResult run_viewer(const ViewerScene& scene, const std::string& args, bool under_xvfb = true,
                     const std::string& env_prefix = "");

struct Image {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
  const uint8_t* at(int x, int y) const { return &rgb[(size_t(y) * size_t(width) + size_t(x)) * 3]; }
};
bool load_png(const std::filesystem::path& path, Image& out);

// One row of --stats, by column name.
struct CsvTable {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  double get(size_t row, const std::string& column) const;
  double last(const std::string& column) const { return get(rows.size() - 1, column); }
};
bool load_csv(const std::filesystem::path& path, CsvTable& out);

// A run with --screenshot DIR/<name>.png and --stats DIR/<name>.csv (DIR the scene's folder)
// and `args`; the picture and the table read back when the run succeeded.
struct Screenshot {
  RunResult run;
  Image image;
  CsvTable stats;
  bool image_read = false, stats_read = false;
};
Screenshot take_screenshot(const ViewerScene& scene, const std::string& name, const std::string& args);

}  // namespace lod::test

#define LOD_REQUIRE_XVFB()                                                                    \
  if (!::lod::test::have_xvfb())                                                              \
  GTEST_SKIP() << "needs xvfb-run (Debian package xvfb) and Mesa's libgl1-mesa-dri to run lod-viewer headless"
