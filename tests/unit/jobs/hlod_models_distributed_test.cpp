// A scene of many models over ranks without MPI: the plan (split above a rank's
// share, the rest whole and balanced), the header estimates, the model cache (store, check,
// refuse), and whole jobs with ranks as threads, whose every file must be the local bake's
// bytes; reruns bake only what the cache lacks, a failing store names its model.
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <numeric>
#include <random>
#include <thread>

#include "jobs/hlod_bake.h"
#include "jobs/hlod_model_cache.h"
#include "jobs/hlod_models_distributed.h"
#include "preprocess/mesh_io.h"
#include "test_support.h"
#include "unit/jobs/thread_ranks.h"
#include "vd_meshes.h"

namespace lod {
namespace {

using test::ThreadRanks;

TEST(HlodModelsPlan, ModelsAboveARanksShareAreSplitTheRestGoWhole) {
  // total 200 at 2 ranks: 120 > 100 is split; 50, 20, 10 whole, longest first.
  EXPECT_EQ(plan_hlod_models({120, 50, 20, 10}, {1, 1, 1, 1}, 2), (std::vector<int>{kHlodModelSplit, 0, 1, 1}));
  // At one rank nothing is above the share; not missing: not baked.
  EXPECT_EQ(plan_hlod_models({120, 50, 20}, {1, 0, 1}, 1), (std::vector<int>{0, kHlodModelNotBaked, 0}));
  // The only missing model is baked by all ranks, at any rank count.
  EXPECT_EQ(plan_hlod_models({5, 500, 7}, {0, 1, 0}, 1),
            (std::vector<int>{kHlodModelNotBaked, kHlodModelSplit, kHlodModelNotBaked}));
  EXPECT_EQ(plan_hlod_models({5, 7}, {0, 0}, 4), (std::vector<int>{kHlodModelNotBaked, kHlodModelNotBaked}));
  // Equal to the share exactly stays whole.
  EXPECT_EQ(plan_hlod_models({100, 100}, {1, 1}, 2), (std::vector<int>{0, 1}));
}

TEST(HlodModelsPlan, WholeModelsLeaveTheSlowestRankAtMostTheMeanPlusOneModel) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    const int ranks = 1 + int(rng() % 8);
    std::vector<uint64_t> costs(2 + rng() % 100);
    std::vector<uint8_t> missing(costs.size());
    for (size_t i = 0; i < costs.size(); ++i) costs[i] = 1 + rng() % 5000, missing[i] = rng() % 4 != 0;
    const std::vector<int> plan = plan_hlod_models(costs, missing, ranks);
    std::vector<uint64_t> load(size_t(ranks), 0);
    uint64_t whole = 0, biggest = 0, missing_total = 0;
    for (size_t i = 0; i < costs.size(); ++i) {
      if (!missing[i]) {
        EXPECT_EQ(plan[i], kHlodModelNotBaked);
        continue;
      }
      missing_total += costs[i];
      ASSERT_GE(plan[i], kHlodModelSplit);
      ASSERT_LT(plan[i], ranks);
      if (plan[i] == kHlodModelSplit) continue;
      load[size_t(plan[i])] += costs[i], whole += costs[i], biggest = std::max(biggest, costs[i]);
    }
    for (size_t i = 0; i < costs.size(); ++i)
      if (missing[i] && plan[i] >= 0) {
        EXPECT_LE(costs[i] * uint64_t(ranks), missing_total) << "a whole model fits a share";
      }
    EXPECT_LE(double(*std::max_element(load.begin(), load.end())), double(whole) / ranks + double(biggest));
  }
}

TEST(HlodModelsPlan, EstimatesReadTheHeadersFaceCounts) {
  const auto dir = test::temp_dir("hlod_models_estimate");
  test::write_text(dir / "a.off", "# a comment\nOFF\n# another\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n");
  EXPECT_EQ(estimate_mesh_triangles(dir / "a.off"), 2u);
  const MeshData m = test::vd_sphere(10, 12);
  ASSERT_TRUE(save_ply(dir / "b.ply", m.positions.data(), m.vertex_count(), m.indices.data(), m.indices.size()));
  EXPECT_EQ(estimate_mesh_triangles(dir / "b.ply"), m.indices.size() / 3);
  std::vector<uint8_t> stl(84 + 50 * 7, 0);
  stl[80] = 7;
  test::write_bytes(dir / "c.stl", stl);
  EXPECT_EQ(estimate_mesh_triangles(dir / "c.stl"), 7u);
  EXPECT_EQ(estimate_mesh_triangles(dir / "absent.obj"), 0u);
}

std::filesystem::path write_sphere(const std::filesystem::path& dir, const std::string& name, int rings, int segments) {
  const MeshData m = test::vd_sphere(rings, segments, 0.5f + 0.01f * float(rings));
  const auto path = dir / (name + ".ply");
  EXPECT_TRUE(save_ply(path, m.positions.data(), m.vertex_count(), m.indices.data(), m.indices.size()));
  return path;
}

std::vector<uint8_t> local_bake(const std::filesystem::path& mesh, const std::filesystem::path& out) {
  HlodBakeSettings s;
  s.min_verts = 150;
  HlodBakeResult r;
  EXPECT_TRUE(bake_hlod_file(mesh, mesh.stem().string(), out, s, {}, &r));
  return test::read_bytes(r.file);
}

TEST(HlodModelCache, StoredEntryLoadsBackAndBrokenOrMisplacedEntriesAreRefused) {
  const auto dir = test::temp_dir("hlod_model_cache");
  const auto mesh = write_sphere(dir, "ball", 16, 20);
  const std::vector<uint8_t> good = local_bake(mesh, dir / "baked");
  uint64_t source = 0;
  ASSERT_TRUE(hlod_source_hash(mesh, 150, source));
  const uint64_t key = hlod_model_key(source, "ball");
  EXPECT_NE(hlod_model_key(source, "other"), key);
  EXPECT_NE(hlod_model_key(source + 1, "ball"), key);
  std::vector<uint8_t> bytes;
  EXPECT_EQ(load_hlod_model(dir / "cache", key, "ball", source, bytes), CacheLookup::missing);
  std::filesystem::create_directories(dir / "cache" / "stage");
  test::write_bytes(dir / "cache" / "stage" / "ball.hlod", good);
  ASSERT_TRUE(store_hlod_model(dir / "cache", key, dir / "cache" / "stage" / "ball.hlod", "ball", source, bytes));
  EXPECT_EQ(bytes, good);
  EXPECT_FALSE(std::filesystem::exists(dir / "cache" / "stage" / "ball.hlod")) << "renamed into place";
  bytes.clear();
  ASSERT_EQ(load_hlod_model(dir / "cache", key, "ball", source, bytes), CacheLookup::found);
  EXPECT_EQ(bytes, good);

  const auto path = hlod_model_entry_path(dir / "cache", key);
  std::string why;
  auto refused = [&](const std::vector<uint8_t>& bad, const std::string& name, uint64_t hash) {
    test::write_bytes(path, bad);
    return load_hlod_model(dir / "cache", key, name, hash, bytes, nullptr, &why) == CacheLookup::refused;
  };
  for (size_t at : {size_t(5), good.size() / 3, good.size() / 2, good.size() - 2}) {
    std::vector<uint8_t> bad = good;
    bad[at] ^= 0x20;
    EXPECT_TRUE(refused(bad, "ball", source)) << "flipped byte " << at;
  }
  EXPECT_TRUE(refused(std::vector<uint8_t>(good.begin(), good.end() - 1), "ball", source));
  EXPECT_NE(why.find(path.string()), std::string::npos) << why;
  std::vector<uint8_t> longer = good;
  longer.push_back(0);
  EXPECT_TRUE(refused(longer, "ball", source));
  EXPECT_NE(why.find(path.string()), std::string::npos) << why;
  EXPECT_TRUE(refused(good, "pebble", source)) << "another model's entry";
  EXPECT_TRUE(refused(good, "ball", source + 1)) << "another source's entry";
  EXPECT_FALSE(refused(good, "ball", source));

  test::write_bytes(dir / "cache" / "stage" / "ball.hlod", std::vector<uint8_t>(good.begin(), good.begin() + 100));
  EXPECT_FALSE(store_hlod_model(dir / "cache", key + 1, dir / "cache" / "stage" / "ball.hlod", "ball", source, bytes));
  EXPECT_FALSE(std::filesystem::exists(dir / "cache" / "stage" / "ball.hlod")) << "a bad bake is removed";
  EXPECT_FALSE(std::filesystem::exists(hlod_model_entry_path(dir / "cache", key + 1)));
}

struct Scene {
  std::vector<std::filesystem::path> meshes;
  std::vector<std::vector<uint8_t>> local;  // lod bake --hlod of each
};

// Four models; the largest holds more than a third of all triangles (split at 3 ranks).
Scene write_scene(const std::filesystem::path& dir) {
  Scene s;
  const int sizes[4][2] = {{10, 12}, {16, 20}, {22, 26}, {50, 60}};
  const char* names[4] = {"pebble", "stone", "rock", "boulder"};
  for (int k = 0; k < 4; ++k) {
    s.meshes.push_back(write_sphere(dir, names[k], sizes[k][0], sizes[k][1]));
    s.local.push_back(local_bake(s.meshes.back(), dir / "local"));
  }
  return s;
}

struct RankRun {
  Status status;
  HlodModelsResult result;
};

// out_of(r): rank r's output folder (the same for all unless a test says otherwise).
std::vector<RankRun> run_ranks(int ranks, const Scene& scene, const std::function<std::filesystem::path(int)>& out_of,
                               const std::filesystem::path& cache) {
  ThreadRanks tr(ranks);
  std::vector<RankRun> runs(static_cast<size_t>(ranks));
  std::vector<std::thread> threads;
  for (int r = 0; r < ranks; ++r)
    threads.emplace_back([&, r] {
      HlodModelsSettings s;
      s.min_verts = 150;
      s.threads = 1;
      s.cache_dir = cache;
      runs[size_t(r)].status =
          bake_hlod_models_distributed(scene.meshes, out_of(r), s, tr.comm(r), {}, &runs[size_t(r)].result);
    });
  for (auto& t : threads) t.join();
  return runs;
}

std::vector<RankRun> run_ranks(int ranks, const Scene& scene, const std::filesystem::path& out,
                               const std::filesystem::path& cache) {
  return run_ranks(ranks, scene, [&](int) { return out; }, cache);
}

void expect_local_bytes(const Scene& scene, const std::filesystem::path& out) {
  for (size_t k = 0; k < scene.meshes.size(); ++k)
    EXPECT_EQ(test::read_bytes(out / (scene.meshes[k].stem().string() + ".hlod")), scene.local[k])
        << scene.meshes[k].stem();
}

TEST(HlodModelsDistributedBake, ThreeRanksWriteEveryLocalBakesBytesAndARerunBakesNothing) {
  const auto dir = test::temp_dir("hlod_models3");
  const Scene scene = write_scene(dir);
  std::vector<RankRun> runs = run_ranks(3, scene, dir / "out", dir / "cache");
  for (const RankRun& r : runs) ASSERT_TRUE(r.status) << r.status.message;
  expect_local_bytes(scene, dir / "out");
  const HlodModelsResult& first = runs[0].result;
  ASSERT_EQ(first.models.size(), 4u);
  ASSERT_EQ(first.ranks.size(), 3u);
  EXPECT_EQ(first.models[3].route, HlodModelRoute::split) << "the boulder is more than a rank's share";
  EXPECT_EQ(first.split, 1u);
  EXPECT_EQ(first.whole, 3u);
  uint32_t baked = 0;
  for (const HlodModelsRankWork& w : first.ranks) baked += w.baked;
  EXPECT_EQ(baked, 3u);
  for (const HlodModelFigures& m : first.models) EXPECT_GT(m.source_triangles, 0u) << m.name;

  for (const auto& e : std::filesystem::directory_iterator(dir / "out")) std::filesystem::remove(e.path());
  runs = run_ranks(3, scene, dir / "out", dir / "cache");
  ASSERT_TRUE(runs[0].status) << runs[0].status.message;
  EXPECT_EQ(runs[0].result.cached, 4u);
  for (const HlodModelsRankWork& w : runs[0].result.ranks) EXPECT_EQ(w.baked, 0u);
  expect_local_bytes(scene, dir / "out");
  for (const auto& e : std::filesystem::directory_iterator(dir / "cache"))
    EXPECT_NE(e.path().filename().string().rfind(".stage-", 0), 0u) << "no staging folder left: " << e.path();
}

TEST(HlodModelsDistributedBake, FailingStoreNamesTheModelAndTheRerunBakesOnlyTheMissingOnes) {
  const auto dir = test::temp_dir("hlod_models_fail");
  const Scene scene = write_scene(dir);
  HlodModelsSettings s;
  s.min_verts = 150;
  s.threads = 1;
  s.cache_dir = dir / "cache";
  std::vector<std::string> stores;
  s.before_store = [&](const std::string& what, size_t stored) {
    stores.push_back(what);
    if (stored == 2) throw std::runtime_error("injected: the disk is full");
  };
  HlodModelsResult r;
  Status st = bake_hlod_models_distributed(scene.meshes, dir / "out", s, single_rank_comm(), {}, &r);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("the disk is full"), std::string::npos) << st.message;
  EXPECT_NE(st.message.find("model " + scene.meshes[2].stem().string()), std::string::npos) << st.message;
  EXPECT_NE(st.message.find("run again"), std::string::npos) << st.message;
  EXPECT_EQ(r.failed, 2u) << "every store after the second fails";
  size_t kept = 0;
  for (const auto& e : std::filesystem::directory_iterator(s.cache_dir)) kept += e.path().extension() == ".hlod";
  EXPECT_EQ(kept, 2u);

  // A corrupted entry is refused, removed and baked again too.
  uint64_t source = 0;
  ASSERT_TRUE(hlod_source_hash(scene.meshes[0], 150, source));
  const auto entry = hlod_model_entry_path(s.cache_dir, hlod_model_key(source, scene.meshes[0].stem().string()));
  std::vector<uint8_t> bytes = test::read_bytes(entry);
  bytes[bytes.size() / 2] ^= 1;
  test::write_bytes(entry, bytes);
  s.before_store = {};
  std::vector<std::string> lines;
  st = bake_hlod_models_distributed(scene.meshes, dir / "out", s, single_rank_comm(),
                                    [&](const std::string& l) { lines.push_back(l); }, &r);
  ASSERT_TRUE(st) << st.message;
  EXPECT_EQ(r.cached, 1u);
  EXPECT_EQ(r.whole, 3u);
  EXPECT_TRUE(std::any_of(lines.begin(), lines.end(), [](const std::string& l) { return l.find("baking it again") != std::string::npos; }));
  expect_local_bytes(scene, dir / "out");
}

TEST(HlodModelsDistributedBake, UnreadableModelIsNamedAndTheOthersAreStillBaked) {
  const auto dir = test::temp_dir("hlod_models_unreadable");
  Scene scene = write_scene(dir);
  scene.meshes.insert(scene.meshes.begin() + 1, dir / "absent.ply");
  std::vector<RankRun> runs = run_ranks(2, scene, dir / "out", dir / "cache");
  ASSERT_FALSE(runs[0].status);
  EXPECT_NE(runs[0].status.message.find("model absent (" + (dir / "absent.ply").string() + ")"), std::string::npos)
      << runs[0].status.message;
  EXPECT_NE(runs[0].status.message.find("1 of 5 models failed"), std::string::npos) << runs[0].status.message;
  EXPECT_EQ(runs[0].result.failed, 1u);
  EXPECT_EQ(runs[0].result.models[1].route, HlodModelRoute::failed);
  scene.meshes.erase(scene.meshes.begin() + 1);
  expect_local_bytes(scene, dir / "out");
}

// A rank whose output folder is its node's own would write its models where nobody looks (and
// say it had): the job stops before any bake, naming the rank and the folder.
TEST(HlodModelsDistributedBake, ARankWithItsOwnOutputFolderStopsTheJobBeforeAnyBake) {
  const auto dir = test::temp_dir("hlod_models_not_shared");
  const Scene scene = write_scene(dir);
  const std::vector<RankRun> runs =
      run_ranks(3, scene, [&](int r) { return r == 2 ? dir / "node-out" : dir / "out"; }, dir / "cache");
  for (size_t r = 0; r < runs.size(); ++r) {
    EXPECT_FALSE(runs[r].status) << r;
    EXPECT_NE(runs[r].status.message.find("rank 2 does not see, in its output folder"), std::string::npos)
        << r << ": " << runs[r].status.message;
  }
  for (const char* sub : {"out", "node-out", "cache"}) {
    if (!std::filesystem::exists(dir / sub)) continue;
    EXPECT_TRUE(std::filesystem::is_empty(dir / sub)) << sub << ": nothing baked, no probe left";
  }
}

TEST(HlodModelsDistributedBake, TwoModelsWithOneNameAreRefusedBeforeAnything) {
  const auto dir = test::temp_dir("hlod_models_names");
  std::filesystem::create_directories(dir / "a");
  std::filesystem::create_directories(dir / "b");
  const auto a = write_sphere(dir / "a", "ball", 10, 12), b = write_sphere(dir / "b", "ball", 12, 14);
  HlodModelsSettings s;
  s.cache_dir = dir / "cache";
  const Status st = bake_hlod_models_distributed({a, b}, dir / "out", s, single_rank_comm(), {}, nullptr);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("two models named 'ball'"), std::string::npos) << st.message;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

}  // namespace
}  // namespace lod
