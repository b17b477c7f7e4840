// Hostile input through the `lod` command: names that try to be paths or terminal escapes,
// non-UTF-8 names, directories and FIFOs given as assets, negative counts, repeated ratios,
// a camera looking straight down, `lod bake --quiet`.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "run_cli.h"
#include "runtime/lod_asset.h"
#include "test_support.h"

namespace {

namespace fs = std::filesystem;
using lod::test::run_lod;

// Every file below `dir`, as paths relative to it.
std::set<std::string> files_below(const fs::path& dir) {
  std::set<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) out.insert(fs::relative(e.path(), dir).string());
  return out;
}

// A one-level asset of a tetrahedron under `name` (any bytes).
fs::path write_named_asset(const fs::path& dir, const std::string& file, const std::string& name) {
  lod::LodChain c;
  c.name = name;
  c.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  c.indices = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  lod::LodLevel lv;
  lv.index_count = 12;
  lv.vertex_count = 4;
  lv.level = lod::level_of_triangles(4);
  lv.bounds.radius = 1;
  c.levels.push_back(lv);
  const fs::path p = dir / file;
  EXPECT_TRUE(lod::write_lod_asset(p, c).ok);
  return p;
}

TEST(LodInspectNames, ExportNamesStayInsideTheFolderWhateverTheModelName) {
  const auto dir = lod::test::temp_dir("hostile-export");
  const fs::path outside = dir / "outside";
  fs::create_directories(outside);
  const std::string names[] = {"../../x", "/tmp/lodkit-abs-name", (outside / "abs").string(),
                               std::string("a\0b", 3), "..", "", "ok_name-1.2", "sub/dir/name",
                               "\x1b[31mred\x1b[0m"};
  int k = 0;
  for (const std::string& name : names) {
    const fs::path exp = dir / ("export" + std::to_string(k));
    const fs::path asset = write_named_asset(dir, "m" + std::to_string(k++) + ".lod", name);
    const auto r = run_lod("inspect " + asset.string() + " --export " + exp.string());
    ASSERT_EQ(r.code, 0) << r.out;
    const auto files = files_below(exp);
    ASSERT_EQ(files.size(), 1u) << r.out;
    const std::string f = *files.begin();
    EXPECT_EQ(f.find('/'), std::string::npos) << f;
    EXPECT_NE(f.front(), '.') << f;
    EXPECT_EQ(f.substr(f.size() - 11), "-level0.ply") << f;
    for (char ch : f) EXPECT_TRUE(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-' || ch == '.') << f;
    EXPECT_EQ(r.out.find('\x1b'), std::string::npos) << "raw escape printed";
  }
  EXPECT_FALSE(fs::exists(outside / "abs-level0.ply"));
  EXPECT_FALSE(fs::exists("/tmp/lodkit-abs-name-level0.ply"));
  EXPECT_TRUE(files_below(outside).empty());
  EXPECT_TRUE(fs::exists(dir / "export6" / "ok_name-1.2-level0.ply"));  // plain names unchanged
  EXPECT_TRUE(fs::exists(dir / "export5" / "model-level0.ply"));        // nothing left: a default
}

TEST(LodInspectNames, ExportNeverWritesThroughAPlantedLink) {
  const auto dir = lod::test::temp_dir("hostile-link");
  const fs::path asset = write_named_asset(dir, "m.lod", "ball");
  fs::create_directories(dir / "export");
  fs::create_symlink(dir / "victim.ply", dir / "export" / "ball-level0.ply");
  const auto r = run_lod("inspect " + asset.string() + " --export " + (dir / "export").string());
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("is a symbolic link"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "victim.ply"));
}

TEST(LodInspectNames, ControlCharactersAreEscapedAndJsonSurvivesNonUtf8) {
  const auto dir = lod::test::temp_dir("hostile-names");
  const fs::path esc = write_named_asset(dir, "esc.lod", "evil\x1b]0;title\x07\x9b\r\nname\xc2\x9b");
  auto r = run_lod("inspect " + esc.string());
  ASSERT_EQ(r.code, 0) << r.out;
  for (char ch : {'\x1b', '\x07', '\r', '\x9b'}) EXPECT_EQ(r.out.find(ch), std::string::npos) << int(ch);
  EXPECT_NE(r.out.find("evil\\e]0;title\\x07\\x9b\\r\\nname\\xc2\\x9b"), std::string::npos) << r.out;
  const fs::path bad = write_named_asset(dir, "bad.lod", "caf\xe9 \xff\xfe");
  r = run_lod("inspect " + bad.string() + " --json");
  ASSERT_EQ(r.code, 0) << r.out;  // aborted with nlohmann's type_error before
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["name"].get<std::string>().substr(0, 3), "caf");
  EXPECT_EQ(j["levels"].size(), 1u);
}

TEST(LodInspectNames, DirectoryOrFifoGivenAsAssetIsRefusedAtOnce) {
  const auto dir = lod::test::temp_dir("hostile-kinds");
  fs::create_directories(dir / "folder.lod");
  auto r = run_lod("inspect " + (dir / "folder.lod").string());
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("is a directory"), std::string::npos) << r.out;
  ASSERT_EQ(::mkfifo((dir / "pipe.lod").c_str(), 0600), 0);
  r = run_lod("inspect " + (dir / "pipe.lod").string());  // hung before, waiting for a writer
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("is a FIFO"), std::string::npos) << r.out;
}

TEST(LodCliCounts, NegativeFramesAndThreadsAreRefused) {
  const auto cfg = fs::path(LOD_SOURCE_DIR) / "configs" / "default.toml";
  for (const std::string flag : {"--frames -5", "--frames 0", "--threads -1"}) {
    const auto r = run_lod("run --config " + cfg.string() + " " + flag);
    EXPECT_NE(r.code, 0) << flag << ": " << r.out;
    EXPECT_NE(r.out.find(flag.substr(0, flag.find(' '))), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("not in range"), std::string::npos) << r.out;
  }
  const auto r = run_lod("bake x.off -o /tmp --threads -2");
  EXPECT_NE(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("--threads"), std::string::npos) << r.out;
}

TEST(LodBakeFlags, RepeatedOrRisingRatiosAreRefusedAndQuietPrintsNothing) {
  const auto dir = lod::test::temp_dir("hostile-bake");
  lod::test::write_text(dir / "ball.off", lod::test::sphere_off(12, 24));
  const std::string base = "bake " + (dir / "ball.off").string() + " -o " + (dir / "out").string();
  auto r = run_lod(base + " --ratios 1 0.5 0.5");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("ratio 2 (0.5) repeats the one before"), std::string::npos) << r.out;
  r = run_lod(base + " --ratios 1 0.25 0.5");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("above the one before"), std::string::npos) << r.out;
  r = run_lod(base + " --ratios 0.5 0.25");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("must be 1"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "out"));
  r = run_lod(base + " --ratios 1 0.5 0.25 --quiet");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(r.out, "");
  r = run_lod(base + " --ratios 1 0.5 0.25");  // from the cache now, and not quiet
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("ball: 3 levels"), std::string::npos) << r.out;
}

// A keyframe camera straight above the scene looking down (up = +y, parallel to the view
// direction) saw 0 objects on every frame; now the scene below is in view.
TEST(LodRunCamera, LookingStraightDownSeesTheSceneBelow) {
  const auto dir = lod::test::temp_dir("hostile-down");
  lod::test::write_text(dir / "ball.off", lod::test::sphere_off(8, 16));
  lod::test::write_text(dir / "scene.toml", R"([run]
frames = 3
threads = 1

[camera]
path = "keyframes"
near = 0.5
far = 1000.0

[[camera.keyframe]]
frame = 0
position = [0, 200, 0]
look_at = [0, 0, 0]

[[model]]
name = "ball"
file = "ball.off"

[[instances]]
model = "ball"
count = 50
box_min = [-40, 0, -40]
box_max = [40, 0, 40]
)");
  const auto r = run_lod("run --config " + (dir / "scene.toml").string() + " --cache " + (dir / "cache").string() +
                         " --json " + (dir / "run.json").string() + " --validate --quiet");
  ASSERT_EQ(r.code, 0) << r.out;
  std::ifstream f(dir / "run.json");
  const auto j = nlohmann::json::parse(f);
  ASSERT_EQ(j["frames"].size(), 3u);
  for (const auto& fr : j["frames"]) EXPECT_EQ(fr["visible"].get<int>(), 50) << fr.dump();
}

}  // namespace
