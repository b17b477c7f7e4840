// End to end: HLOD models (hlod = true) drawn through the hlod node of `lod run`, streamed
// under [stream] budget_mb, validated frame by frame (closed cut, no crack, no hole, budget).
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "runtime/hlod_asset.h"
#include "run_cli.h"
#include "test_support.h"

namespace {

using lod::test::run_lod;

using lod::test::read_json;

// Every frame: no hole, resident bytes within the budget, something drawn; counters grow.
void expect_streamed_frames(const nlohmann::json& j, uint64_t budget_bytes, size_t frames) {
  ASSERT_EQ(j["frames"].size(), frames);
  uint64_t last_loads = 0;
  for (const auto& f : j["frames"]) {
    for (const char* key : {"hlod_nodes_drawn", "resident_bytes", "stream_requests", "stream_loads", "holes"})
      ASSERT_TRUE(f.contains(key)) << key;
    EXPECT_EQ(f["holes"].get<uint64_t>(), 0u) << "frame " << f["frame"];
    EXPECT_LE(f["resident_bytes"].get<uint64_t>(), budget_bytes) << "frame " << f["frame"];
    EXPECT_GT(f["hlod_nodes_drawn"].get<uint64_t>(), 0u) << "frame " << f["frame"];
    EXPECT_GE(f["stream_loads"].get<uint64_t>(), last_loads);
    EXPECT_LE(f["stream_loads"].get<uint64_t>(), f["stream_requests"].get<uint64_t>());
    EXPECT_LE(f["tris_selected"].get<uint64_t>(), f["budget"].get<uint64_t>());
    last_loads = f["stream_loads"].get<uint64_t>();
  }
  EXPECT_GT(last_loads, 1u) << "the pager loaded more than the root";
  const auto& s = j["summary"];
  EXPECT_EQ(s["total_holes"].get<uint64_t>(), 0u);
  EXPECT_EQ(s["stream_budget"].get<uint64_t>(), budget_bytes);
  EXPECT_LE(s["max_resident_bytes"].get<uint64_t>(), budget_bytes);
  EXPECT_GT(s["max_resident_bytes"].get<uint64_t>(), 0u);
}

TEST(LodRunHlod, ShippedHlodConfigStreamsWithoutHolesWithinTheBudget) {
  if (lod::test::data_dir().empty()) GTEST_SKIP() << "needs Debian's CGAL meshes in " << LOD_DATA_DIR;
  const auto dir = lod::test::temp_dir("lodrun-hlod-shipped");
  const auto config = std::filesystem::path(LOD_SOURCE_DIR) / "configs" / "hlod.toml";
  const auto cache = std::filesystem::path(LOD_BINARY_DIR) / "test-cache";
  const auto r = run_lod("run --config " + config.string() + " --frames 60 --validate --quiet --cache " +
                         cache.string() + " --json " + (dir / "run.json").string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("hlod: 1 models"), std::string::npos) << r.out;
  expect_streamed_frames(read_json(dir / "run.json"), 1u << 20, 60);
}

// A discrete model and an HLOD model in one scene: the HLOD cut's triangles count in M
// (tris_selected includes them, --validate checks the sum) and its objects are not discrete.
std::filesystem::path write_mixed_scene(const std::filesystem::path& dir, const std::string& hlod_instances) {
  lod::test::write_text(dir / "ball.off", lod::test::sphere_off(12, 24));   // 528 triangles
  lod::test::write_text(dir / "big.off", lod::test::sphere_off(80, 160));   // ~25k triangles
  const auto cfg = dir / "scene.toml";
  using namespace lod::test;
  write_text(cfg, run_block(40) + budget_block(60000) + "[stream]\nbudget_mb = 1\nloader_threads = 2\n\n" +
                      keyframe_camera_block(0.1, 0, {{0, "[0.0, 5.0, 400.0]", "[0.0, 0.0, 0.0]"},
                                                     {39, "[0.0, 2.0, 25.0]", "[0.0, 0.0, 0.0]"}}) +
                      model_block("ball", "ball.off", "[1.0, 0.5, 0.25]") +
                      model_block("big", "big.off", "", "hlod = true\nmin_verts = 500\n") +
                      scattered_block("ball", 50, 100) + "[[instances]]\nmodel = \"big\"\n" + hlod_instances);
  return cfg;
}

TEST(LodRunHlod, MixedSceneCountsHlodTrianglesInTheBudget) {
  const auto dir = lod::test::temp_dir("lodrun-hlod-mixed");
  const auto cfg = write_mixed_scene(dir, "count = 1\nplacement = \"grid\"\nbox_min = [0, 0, 0]\nbox_max = [0, 0, 0]\nscale = 10.0\n");
  const auto r = run_lod("run --config " + cfg.string() + " --validate --quiet --cache " + (dir / "cache").string() +
                         " --json " + (dir / "run.json").string());
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j = read_json(dir / "run.json");
  expect_streamed_frames(j, 1u << 20, 40);
  for (const auto& f : j["frames"]) EXPECT_EQ(f["objects"].get<uint64_t>(), 50u) << "the hlod object is not discrete";
  EXPECT_EQ(j["summary"]["hlod_models"].get<uint64_t>(), 1u);
  EXPECT_EQ(j["summary"]["models"].get<uint64_t>(), 2u);
  // Cached: the second run bakes nothing.
  const auto again = run_lod("run --config " + cfg.string() + " --frames 2 --quiet --cache " + (dir / "cache").string());
  ASSERT_EQ(again.code, 0) << again.out;
  EXPECT_NE(again.out.find("bake big: cached"), std::string::npos) << again.out;
}

// Behind the camera all the way: nothing of it drawn or wanted, no hole, and --validate passes.
TEST(LodRunHlod, ModelOutOfViewDrawsNothingAndValidates) {
  const auto dir = lod::test::temp_dir("lodrun-hlod-behind");
  const auto cfg = write_mixed_scene(dir, "count = 1\nbox_min = [0, 0, 3000]\nbox_max = [0, 0, 3000]\nscale = 10.0\n");
  const auto r = run_lod("run --config " + cfg.string() + " --frames 10 --validate --quiet --cache " +
                         (dir / "cache").string() + " --json " + (dir / "run.json").string());
  ASSERT_EQ(r.code, 0) << r.out;
  const auto run = read_json(dir / "run.json");  // held: the loop must not range over a temporary
  ASSERT_FALSE(run["frames"].empty());
  for (const auto& f : run["frames"]) {
    EXPECT_EQ(f["hlod_nodes_drawn"].get<uint64_t>(), 0u);
    EXPECT_EQ(f["holes"].get<uint64_t>(), 0u);
  }
}

TEST(LodRunHlod, RefusesAnHlodBlockOfTwoObjects) {
  const auto dir = lod::test::temp_dir("lodrun-hlod-two");
  const auto cfg = write_mixed_scene(dir, "count = 2\n");
  const auto r = run_lod("run --config " + cfg.string() + " --quiet --cache " + (dir / "cache").string());
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("instances[1].count"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("count = 1"), std::string::npos) << r.out;
}

// The scene's cached .hlod (written by a first run).
std::filesystem::path cached_hlod(const std::filesystem::path& cache) {
  std::filesystem::path file;
  for (const auto& e : std::filesystem::directory_iterator(cache))
    if (e.path().extension() == ".hlod") file = e.path();
  return file;
}

// A corrupted root payload in the cache: every frame reports the hole (nothing can be drawn),
// the failed read is named, nothing crashes; --validate fails the run. The entry is marked bad,
// and the next run rebakes it.
TEST(LodRunHlod, CorruptedRootIsAHoleThatValidateRefuses) {
  const auto dir = lod::test::temp_dir("lodrun-hlod-corrupt");
  const auto cfg = write_mixed_scene(dir, "count = 1\nscale = 10.0\n");
  const auto cache = dir / "cache";
  ASSERT_EQ(run_lod("run --config " + cfg.string() + " --frames 1 --quiet --cache " + cache.string()).code, 0);
  const std::filesystem::path file = cached_hlod(cache);
  ASSERT_FALSE(file.empty());
  lod::HlodTree tree;
  ASSERT_TRUE(lod::read_hlod_tree(file, tree).ok);
  {
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(std::streamoff(tree.nodes[0].payload_offset + tree.nodes[0].payload_size / 2));
    char c = 0;
    f.read(&c, 1);
    c = char(c ^ 0x5a);
    f.seekp(std::streamoff(tree.nodes[0].payload_offset + tree.nodes[0].payload_size / 2));
    f.write(&c, 1);
  }
  const auto damaged = lod::test::read_bytes(file);
  const auto r = run_lod("run --config " + cfg.string() + " --frames 5 --quiet --cache " + cache.string() + " --json " +
                         (dir / "run.json").string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("hlod read failed: " + file.string() + ": node 0: payload checksum mismatch"), std::string::npos)
      << r.out;
  const auto j = read_json(dir / "run.json");
  for (const auto& f : j["frames"]) {
    EXPECT_EQ(f["holes"].get<uint64_t>(), 1u);
    EXPECT_EQ(f["hlod_nodes_drawn"].get<uint64_t>(), 0u);
  }
  EXPECT_EQ(j["summary"]["stream_failures"].get<uint64_t>(), 1u);
  ASSERT_EQ(j["summary"]["stream_failed"].size(), 1u);
  EXPECT_EQ(j["summary"]["total_holes"].get<uint64_t>(), 5u);
  // The damaged file once more, without its mark (as a .hlod a config names itself would be).
  lod::test::write_bytes(file, damaged);
  std::filesystem::remove(file.string() + ".bad");
  const auto v = run_lod("run --config " + cfg.string() + " --frames 5 --validate --quiet --cache " + cache.string());
  EXPECT_EQ(v.code, 3) << v.out;
  EXPECT_NE(v.out.find("1 hlod holes"), std::string::npos) << v.out;
  const auto again = run_lod("run --config " + cfg.string() + " --frames 5 --validate --quiet --cache " + cache.string());
  EXPECT_EQ(again.code, 0) << again.out;
  EXPECT_NE(again.out.find("was marked bad"), std::string::npos) << again.out;
}

// 5 x 4 KB of the payloads overwritten with 0xff, the head intact: the run names the file, the
// nodes and the checksum (not a bare count), the rerun rebakes instead of saying "cached", and
// lod inspect --verify exits 2 on the damaged file naming the nodes, 0 on the rebaked one.
TEST(LodRunHlod, DamagedPayloadsAreNamedAndTheEntryRebaked) {
  const auto dir = lod::test::temp_dir("lodrun-hlod-damaged");
  const auto cfg = write_mixed_scene(dir, "count = 1\nscale = 10.0\n");
  const auto cache = dir / "cache";
  ASSERT_EQ(run_lod("run --config " + cfg.string() + " --frames 1 --quiet --cache " + cache.string()).code, 0);
  const std::filesystem::path file = cached_hlod(cache);
  ASSERT_FALSE(file.empty());
  const auto clean = run_lod("inspect --verify " + file.string());
  EXPECT_EQ(clean.code, 0) << clean.out;
  EXPECT_NE(clean.out.find("node payloads verified"), std::string::npos) << clean.out;

  lod::HlodTree tree;
  ASSERT_TRUE(lod::read_hlod_tree(file, tree).ok);
  std::vector<uint8_t> bytes = lod::test::read_bytes(file);
  const uint64_t first = tree.nodes[0].payload_offset;  // past the head
  ASSERT_GT(bytes.size(), first + 5 * 4096);
  const uint64_t stride = (bytes.size() - first - 4096) / 4;
  for (uint64_t k = 0; k < 5; ++k) std::fill_n(bytes.begin() + std::ptrdiff_t(first + k * stride), 4096, uint8_t(0xff));
  lod::test::write_bytes(file, bytes);

  const auto verify = run_lod("inspect --verify " + file.string());
  EXPECT_EQ(verify.code, 2) << verify.out;
  EXPECT_NE(verify.out.find(file.string() + ": node 0: payload checksum mismatch"), std::string::npos) << verify.out;
  EXPECT_NE(verify.out.find("node payloads damaged"), std::string::npos) << verify.out;
  const auto verify_json = lod::test::printed_json(run_lod("inspect --verify --json " + file.string()));
  ASSERT_TRUE(verify_json.is_object());
  EXPECT_FALSE(verify_json["verified"].get<bool>());
  EXPECT_GE(verify_json["damaged"].size(), 5u) << "each 4 KB block falls in at least one payload";

  const auto r = run_lod("run --config " + cfg.string() + " --frames 5 --quiet --cache " + cache.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("bake big: cached"), std::string::npos) << "the head alone checks out: " << r.out;
  EXPECT_NE(r.out.find("hlod read failed: " + file.string() + ": node 0: payload checksum mismatch"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("marked bad"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("failed: " + file.string()), std::string::npos) << "the summary names them: " << r.out;
  EXPECT_TRUE(std::filesystem::exists(file.string() + ".bad"));

  const auto rerun = run_lod("run --config " + cfg.string() + " --frames 5 --validate --quiet --cache " + cache.string());
  ASSERT_EQ(rerun.code, 0) << rerun.out;
  EXPECT_EQ(rerun.out.find("bake big: cached"), std::string::npos) << rerun.out;
  EXPECT_NE(rerun.out.find("bake big: cache file " + file.string() + " was marked bad"), std::string::npos) << rerun.out;
  EXPECT_EQ(rerun.out.find("hlod read failed"), std::string::npos) << rerun.out;
  EXPECT_FALSE(std::filesystem::exists(file.string() + ".bad"));
  const auto rebaked = run_lod("inspect --verify " + file.string());
  EXPECT_EQ(rebaked.code, 0) << rebaked.out;
}

}  // namespace
