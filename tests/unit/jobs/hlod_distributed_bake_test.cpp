// The distributed HLOD bake without MPI: the balanced assignment, the subtree cache
// (store, verify, refuse), and whole bakes with one rank and with ranks as threads, whose files
// must be the local bake's bytes; reruns bake only what the cache lacks.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <numeric>
#include <random>
#include <thread>

#include "jobs/hlod_bake.h"
#include "jobs/hlod_distributed_bake.h"
#include "jobs/hlod_mesh_cache.h"
#include "jobs/hlod_subtree_cache.h"
#include "preprocess/gltf_io.h"  // gltf_external_files
#include "preprocess/mesh_io.h"
#include "runtime/hlod_asset.h"
#include "runtime/lod_asset.h"  // hash_bytes
#include "embedded_texture_fixture.h"
#include "test_support.h"
#include "textured_fixture.h"
#include "unit/jobs/thread_ranks.h"
#include "vd_meshes.h"

namespace lod {
namespace {

using test::ThreadRanks;

TEST(HlodAssign, LongestFirstToTheLeastLoadedRank) {
  EXPECT_EQ(assign_subtrees({5, 4, 3, 3, 3}, 2), (std::vector<int>{0, 1, 1, 0, 1}));
  EXPECT_EQ(assign_subtrees({1, 1, 1}, 1), (std::vector<int>{0, 0, 0}));
  EXPECT_TRUE(assign_subtrees({}, 4).empty());
}

TEST(HlodAssign, SlowestRankCarriesAtMostTheMeanPlusOneSubtree) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const int ranks = 1 + int(rng() % 8);
    std::vector<uint64_t> costs(1 + rng() % 200);
    for (uint64_t& c : costs) c = 1 + rng() % 5000;
    const std::vector<int> owner = assign_subtrees(costs, ranks);
    std::vector<uint64_t> load(size_t(ranks), 0);
    for (size_t i = 0; i < costs.size(); ++i) {
      ASSERT_GE(owner[i], 0);
      ASSERT_LT(owner[i], ranks);
      load[size_t(owner[i])] += costs[i];
    }
    const double mean = double(std::accumulate(costs.begin(), costs.end(), uint64_t(0))) / ranks;
    EXPECT_LE(double(*std::max_element(load.begin(), load.end())), mean + double(*std::max_element(costs.begin(), costs.end())));
  }
}

TEST(HlodAssign, SpatialRunsAreContiguousAndBalanced) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 200; ++trial) {
    const int ranks = 1 + int(rng() % 8);
    std::vector<uint64_t> costs(1 + rng() % 200);
    for (uint64_t& c : costs) c = 1 + rng() % 5000;
    std::vector<size_t> order(costs.size());
    std::iota(order.begin(), order.end(), size_t(0));
    std::shuffle(order.begin(), order.end(), rng);
    const std::vector<int> owner = assign_subtrees_spatially(costs, order, ranks);
    std::vector<uint64_t> load(size_t(ranks), 0);
    for (size_t k = 0; k < order.size(); ++k) {
      ASSERT_GE(owner[order[k]], 0);
      ASSERT_LT(owner[order[k]], ranks);
      if (k) {
        ASSERT_GE(owner[order[k]], owner[order[k - 1]]) << "runs follow the order";
      }
      load[size_t(owner[order[k]])] += costs[order[k]];
    }
    const double mean = double(std::accumulate(costs.begin(), costs.end(), uint64_t(0))) / ranks;
    EXPECT_LE(double(*std::max_element(load.begin(), load.end())), mean + double(*std::max_element(costs.begin(), costs.end())));
  }
  EXPECT_EQ(assign_subtrees_spatially({1, 1, 1, 1}, {3, 2, 1, 0}, 2), (std::vector<int>{1, 1, 0, 0}));
}

// The slowest rank's share of the estimated cost over the mean, for a frontier planned with
// `subtrees` and refined (or not) at the cuts between `ranks` spatial runs.
double spatial_imbalance(const MeshData& m, uint32_t subtrees, int ranks, bool refine) {
  HlodBuildOptions o;
  o.min_verts = 100;
  o.subtrees = subtrees;
  o.balance_parts = refine ? uint32_t(ranks) : 1;
  HlodBuilder b(m, o);
  EXPECT_TRUE(b.plan());
  std::vector<uint64_t> costs;
  std::vector<size_t> order(b.subtrees().size());
  for (const HlodSubtreeSpec& s : b.subtrees()) costs.push_back(s.triangles);
  std::iota(order.begin(), order.end(), size_t(0));
  std::sort(order.begin(), order.end(), [&](size_t a, size_t c) { return b.subtrees()[a].spatial < b.subtrees()[c].spatial; });
  const std::vector<int> owner = assign_subtrees_spatially(costs, order, ranks);
  std::vector<double> load(size_t(ranks), 0);
  for (size_t i = 0; i < costs.size(); ++i) load[size_t(owner[i])] += double(costs[i]);
  const double mean = std::accumulate(load.begin(), load.end(), 0.0) / ranks;
  return *std::max_element(load.begin(), load.end()) / mean;
}

// Ranks that load the mesh for their node bake less, by the load's estimated cost; the cuts
// are ascending and leave every rank a share. Without loaders, or all loaders: equal shares.
TEST(HlodAssign, NodeLoadersGetSmallerSharesAndTheRunsFollowTheCuts) {
  EXPECT_TRUE(node_loader_cuts({0, 0}).empty());
  EXPECT_TRUE(node_loader_cuts({1, 1, 1}).empty());
  EXPECT_TRUE(node_loader_cuts({1}).empty());
  const std::vector<double> two = node_loader_cuts({1, 0});
  ASSERT_EQ(two.size(), 1u);
  EXPECT_LT(two[0], 0.5);
  EXPECT_GT(two[0], 0.45);
  const std::vector<double> four = node_loader_cuts({1, 0, 1, 0});
  ASSERT_EQ(four.size(), 3u);
  const double shares[4] = {four[0], four[1] - four[0], four[2] - four[1], 1 - four[2]};
  EXPECT_NEAR(shares[0], shares[2], 1e-12);
  EXPECT_NEAR(shares[1], shares[3], 1e-12);
  EXPECT_LT(shares[0], shares[1]);
  for (const std::vector<double>& cuts : {node_loader_cuts(std::vector<uint8_t>(64, 0)), node_loader_cuts([] {
         std::vector<uint8_t> one_node(64, 0);
         one_node[0] = 1;
         return one_node;
       }())})
    for (size_t k = 1; k < cuts.size(); ++k) EXPECT_GT(cuts[k], cuts[k - 1]);
  // Runs at equal cuts are the equal split's; at a quarter, rank 0 gets about a quarter.
  std::mt19937 rng(5);
  std::vector<uint64_t> costs(300);
  for (uint64_t& c : costs) c = 1 + rng() % 1000;
  std::vector<size_t> order(costs.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::shuffle(order.begin(), order.end(), rng);
  EXPECT_EQ(assign_subtrees_at_cuts(costs, order, {0.5}), assign_subtrees_spatially(costs, order, 2));
  EXPECT_EQ(assign_subtrees_at_cuts(costs, order, {1.0 / 3, 2.0 / 3}), assign_subtrees_spatially(costs, order, 3));
  const std::vector<int> owner = assign_subtrees_at_cuts(costs, order, {0.25});
  double first = 0, total = 0;
  for (size_t i = 0; i < costs.size(); ++i) first += owner[i] == 0 ? double(costs[i]) : 0, total += double(costs[i]);
  EXPECT_NEAR(first / total, 0.25, 1000 / total);
}

// Few subtrees (a small top) split evenly once the cuts between the ranks' runs are refined;
// without it the same frontier leaves a rank a subtree-sized share more.
TEST(HlodAssign, FrontierRefinedAtTheCutsSplitsFewSubtreesEvenly) {
  const MeshData m = test::vd_concat(test::vd_sphere(120, 160, 0.4f, 0.5f, 0.3f, 0.5f), test::vd_grid(120, 120));
  for (int ranks : {2, 3, 4}) EXPECT_LT(spatial_imbalance(m, uint32_t(ranks), ranks, true), 1.01) << ranks << " ranks";
  // Where the coarse frontier's runs are uneven (this mesh is symmetric enough at 2 ranks).
  for (int ranks : {3, 4}) EXPECT_GT(spatial_imbalance(m, uint32_t(ranks), ranks, false), 1.05) << ranks << " ranks";
}

// The mixed test mesh as an OFF file.
std::filesystem::path write_mesh(const std::filesystem::path& dir) {
  const MeshData m = test::vd_concat(test::vd_sphere(40, 50, 0.4f, 0.5f, 0.3f, 0.5f), test::vd_grid(40, 40));
  const auto path = dir / "mixed.ply";
  EXPECT_TRUE(save_ply(path, m.positions.data(), m.vertex_count(), m.indices.data(), m.indices.size()));
  return path;
}

HlodSubtree one_subtree(const MeshData& m, HlodBuildOptions& o, size_t which, HlodSubtreeSpec* spec = nullptr) {
  HlodBuilder b(m, o);
  EXPECT_TRUE(b.plan());
  HlodSubtree out;
  EXPECT_TRUE(b.bake_subtrees({which}, [&](size_t, HlodSubtree&& s) {
    out = std::move(s);
    return Status::success();
  }));
  if (spec) *spec = b.subtrees()[which];
  return out;
}

TEST(HlodSubtreeCache, StoredEntryLoadsBackAndLeavesNoTemporary) {
  const auto dir = test::temp_dir("hlod_cache");
  const MeshData m = test::vd_sphere(40, 50);
  HlodBuildOptions o;
  o.min_verts = 150;
  HlodSubtreeSpec spec;
  const HlodSubtree s = one_subtree(m, o, 1, &spec);
  const uint64_t key = hlod_subtree_key(42, o, spec);
  HlodSubtree back;
  EXPECT_EQ(load_hlod_subtree(dir, key, m.vertex_count(), back), CacheLookup::missing);
  ASSERT_TRUE(store_hlod_subtree(dir, key, m.vertex_count(), s));
  ASSERT_EQ(load_hlod_subtree(dir, key, m.vertex_count(), back), CacheLookup::found);
  EXPECT_EQ(back.root_source, s.root_source);
  EXPECT_EQ(back.nodes.size(), s.nodes.size());
  size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    ++files;
    EXPECT_EQ(e.path().extension(), ".hsub");
  }
  EXPECT_EQ(files, 1u);
}

TEST(HlodSubtreeCache, KeyChangesWithSourceSettingsAndSubtree) {
  HlodBuildOptions o;
  HlodSubtreeSpec spec;
  spec.fingerprint = 5;
  const uint64_t k = hlod_subtree_key(1, o, spec);
  EXPECT_NE(hlod_subtree_key(2, o, spec), k);
  HlodBuildOptions fewer = o;
  fewer.min_verts = 500;
  EXPECT_NE(hlod_subtree_key(1, fewer, spec), k);
  spec.fingerprint = 6;
  EXPECT_NE(hlod_subtree_key(1, o, spec), k);
}

TEST(HlodSubtreeCache, TruncatedFlippedOrMisplacedEntriesAreRefused) {
  const auto dir = test::temp_dir("hlod_cache_bad");
  const MeshData m = test::vd_sphere(40, 50);
  HlodBuildOptions o;
  o.min_verts = 150;
  const HlodSubtree s = one_subtree(m, o, 0);
  ASSERT_TRUE(store_hlod_subtree(dir, 1, m.vertex_count(), s));
  const auto path = hlod_subtree_entry_path(dir, 1);
  const std::vector<uint8_t> good = test::read_bytes(path);
  HlodSubtree out;
  std::string why;
  test::write_bytes(path, std::vector<uint8_t>(good.begin(), good.begin() + std::ptrdiff_t(good.size() / 2)));
  EXPECT_EQ(load_hlod_subtree(dir, 1, m.vertex_count(), out, &why), CacheLookup::refused);
  EXPECT_NE(why.find(path.string()), std::string::npos) << why;
  std::vector<uint8_t> flipped = good;
  flipped[flipped.size() / 3] ^= 4;
  test::write_bytes(path, flipped);
  EXPECT_EQ(load_hlod_subtree(dir, 1, m.vertex_count(), out), CacheLookup::refused);
  std::filesystem::rename(path, hlod_subtree_entry_path(dir, 2));
  test::write_bytes(hlod_subtree_entry_path(dir, 2), good);
  EXPECT_EQ(load_hlod_subtree(dir, 2, m.vertex_count(), out, &why), CacheLookup::refused) << "stored under key 1";
  EXPECT_EQ(load_hlod_subtree(dir, 2, 10, out), CacheLookup::refused) << "vertices beyond a 10-vertex mesh";
}

struct RankRun {
  Status status;
  HlodDistributedResult result;
};

// What one rank is given: its mesh path, output and cache folders (the same on every rank
// unless a test says otherwise, as a node with its own storage would have).
struct RankPaths {
  std::filesystem::path mesh, out, cache;
};

// Ranks as threads; `per_node` consecutive ones form a node, which shares the mesh from
// `share_from` ranks on in at most `node_memory` bytes.
std::vector<RankRun> run_ranks(int ranks, const std::function<RankPaths(int)>& paths_of,
                               uint64_t held_entry_bytes = uint64_t(1) << 30, int per_node = 1, uint32_t share_from = 2,
                               uint64_t node_memory = UINT64_MAX) {
  ThreadRanks tr(ranks, per_node);
  for (auto& node : tr.nodes) node->memory = node_memory;
  std::vector<RankRun> runs(static_cast<size_t>(ranks));
  std::vector<std::thread> threads;
  for (int r = 0; r < ranks; ++r)
    threads.emplace_back([&, r] {
      const RankPaths p = paths_of(r);
      HlodDistributedSettings s;
      s.min_verts = 150;
      s.threads = 1;
      s.cache_dir = p.cache;
      s.held_entry_bytes = held_entry_bytes;
      s.share_mesh_from = share_from;
      runs[size_t(r)].status = bake_hlod_distributed(p.mesh, "mixed", p.out, s, tr.comm(r), {}, &runs[size_t(r)].result);
    });
  for (auto& t : threads) t.join();
  return runs;
}

std::vector<RankRun> run_ranks(int ranks, const std::filesystem::path& mesh, const std::filesystem::path& out,
                               const std::filesystem::path& cache, uint64_t held_entry_bytes = uint64_t(1) << 30,
                               int per_node = 1, uint32_t share_from = 2) {
  return run_ranks(ranks, [&](int) { return RankPaths{mesh, out, cache}; }, held_entry_bytes, per_node, share_from);
}

std::vector<uint8_t> local_bake(const std::filesystem::path& mesh, const std::filesystem::path& out) {
  HlodBakeSettings s;
  s.min_verts = 150;
  HlodBakeResult r;
  EXPECT_TRUE(bake_hlod_file(mesh, "mixed", out, s, {}, &r));
  return test::read_bytes(r.file);
}

// Shared storage that is not: one rank reads another version of MESH (one vertex moved a
// little, so the same counts, plan shape and payload sizes). The ranks would bake subtrees of
// two meshes into one file; the job refuses instead, naming the rank, and writes nothing.
TEST(HlodDistributedBake, ARankThatReadsAnotherInputFailsTheJobNamingIt) {
  const auto dir = test::temp_dir("hlod_dist_other_input");
  const auto mesh = write_mesh(dir);
  MeshData other = test::vd_concat(test::vd_sphere(40, 50, 0.4f, 0.5f, 0.3f, 0.5f), test::vd_grid(40, 40));
  other.positions[3 * 7 + 1] += 1e-4f;
  std::filesystem::create_directories(dir / "elsewhere");
  const auto moved = dir / "elsewhere" / "mixed.ply";
  ASSERT_TRUE(save_ply(moved, other.positions.data(), other.vertex_count(), other.indices.data(), other.indices.size()));
  const std::vector<RankRun> runs =
      run_ranks(3, [&](int r) { return RankPaths{r == 1 ? moved : mesh, dir / "out", dir / "cache"}; });
  for (size_t r = 0; r < runs.size(); ++r) {
    EXPECT_FALSE(runs[r].status) << "rank " << r;
    EXPECT_NE(runs[r].status.message.find("rank 1"), std::string::npos) << r << ": " << runs[r].status.message;
  }
  EXPECT_NE(runs[0].status.message.find("another input"), std::string::npos) << runs[0].status.message;
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "mixed.hlod"));
}

// Folders that are not shared: a rank whose cache (or output) folder is its node's own would
// bake into a cache rank 0 never reads, or write its part where nobody looks. The job stops
// before any load or bake, naming the rank and the folder, and leaves no probe file behind.
TEST(HlodDistributedBake, ARankThatDoesNotSeeTheSharedFoldersStopsTheJobBeforeAnyWork) {
  const auto dir = test::temp_dir("hlod_dist_not_shared");
  const auto mesh = write_mesh(dir);
  struct Case {
    int odd_rank;
    bool cache;  // else the output folder is the odd one
  };
  for (const Case c : {Case{1, true}, Case{2, false}}) {
    const auto base = dir / (c.cache ? "cache-case" : "out-case");
    const std::vector<RankRun> runs = run_ranks(3, [&](int r) {
      const bool odd = r == c.odd_rank;
      return RankPaths{mesh, base / (odd && !c.cache ? "node-out" : "out"), base / (odd && c.cache ? "node-cache" : "cache")};
    });
    const std::string folder = c.cache ? "cache folder" : "output folder";
    for (size_t r = 0; r < runs.size(); ++r) {
      EXPECT_FALSE(runs[r].status) << r;
      EXPECT_NE(runs[r].status.message.find("rank " + std::to_string(c.odd_rank) + " does not see, in its " + folder),
                std::string::npos)
          << r << ": " << runs[r].status.message;
    }
    EXPECT_FALSE(std::filesystem::exists(base / "out" / "mixed.hlod"));
    for (const char* sub : {"out", "cache", "node-out", "node-cache"}) {
      std::error_code ec;
      if (!std::filesystem::exists(base / sub)) continue;
      for (const auto& e : std::filesystem::directory_iterator(base / sub, ec))
        ADD_FAILURE() << "left behind (nothing is loaded, baked or probed any more): " << e.path();
    }
  }
}

TEST(HlodDistributedBake, ThreeRanksWriteTheLocalBakesBytesAndARerunBakesNothing) {
  const auto dir = test::temp_dir("hlod_dist3");
  const auto mesh = write_mesh(dir);
  const std::vector<uint8_t> local = local_bake(mesh, dir / "local");
  std::vector<RankRun> runs = run_ranks(3, mesh, dir / "out", dir / "cache");
  for (const RankRun& r : runs) ASSERT_TRUE(r.status) << r.status.message;
  EXPECT_EQ(test::read_bytes(dir / "out" / "mixed.hlod"), local);
  const HlodDistributedResult& first = runs[0].result;
  ASSERT_EQ(first.ranks.size(), 3u);
  size_t baked = 0;
  for (const HlodRankWork& w : first.ranks) {
    baked += w.subtrees;
    EXPECT_GT(w.subtrees, 0u);
  }
  EXPECT_EQ(baked, first.subtrees);
  EXPECT_GE(first.subtrees, 48u) << "16 per rank";
  const size_t subtrees = first.subtrees;  // `runs` is replaced below

  std::filesystem::remove(dir / "out" / "mixed.hlod");
  runs = run_ranks(3, mesh, dir / "out", dir / "cache");
  ASSERT_TRUE(runs[0].status) << runs[0].status.message;
  EXPECT_EQ(runs[0].result.cached, subtrees);
  for (const HlodRankWork& w : runs[0].result.ranks) EXPECT_EQ(w.subtrees, 0u);
  EXPECT_EQ(test::read_bytes(dir / "out" / "mixed.hlod"), local);
}

// Ranks on one node share one copy of the cleaned mesh, which the node's first rank loads
// (HlodRankComm::node_buffer): 4 ranks as 2 nodes of 2 write the local bake's bytes, each
// node's first rank alone loading; a rerun views the cached mesh the same way.
TEST(HlodDistributedBake, RanksOfANodeShareOneCopyOfTheMeshAndWriteTheSameBytes) {
  const auto dir = test::temp_dir("hlod_dist_node");
  const auto mesh = write_mesh(dir);
  const std::vector<uint8_t> local = local_bake(mesh, dir / "local");
  for (bool rerun : {false, true}) {
    std::filesystem::remove(dir / "out" / "mixed.hlod");
    const std::vector<RankRun> runs = run_ranks(4, mesh, dir / "out", dir / "cache", uint64_t(1) << 30, 2);
    for (const RankRun& r : runs) ASSERT_TRUE(r.status) << r.status.message;
    EXPECT_EQ(test::read_bytes(dir / "out" / "mixed.hlod"), local) << (rerun ? "rerun" : "first run");
    const HlodDistributedResult& res = runs[0].result;
    EXPECT_TRUE(res.mesh_shared);
    EXPECT_EQ(res.mesh_cached, rerun);
    ASSERT_EQ(res.ranks.size(), 4u);
    for (size_t r = 0; r < 4; ++r) EXPECT_EQ(res.ranks[r].mesh_loaded, r % 2 == 0 ? 1u : 0u) << "rank " << r;
    if (!rerun) {  // a loader's share is smaller by its load
      for (size_t r : {0, 2}) EXPECT_LT(res.ranks[r].triangles, res.ranks[r + 1].triangles) << "rank " << r;
    }
  }
  uint64_t source_hash = 0;
  ASSERT_TRUE(hlod_source_hash(mesh, 150, source_hash));
  EXPECT_TRUE(std::filesystem::exists(hlod_mesh_entry_path(dir / "cache", source_hash))) << "stored from the node's copy";
}

// Nodes share from share_mesh_from ranks on (8 by default): with 4, a node of 4 shares (its
// first loads), a node of 2 keeps a copy per rank (both load), every rank agrees on the plan,
// and the bytes are the local bake's.
TEST(HlodDistributedBake, NodesShareFromTheirThresholdAndMixedNodesAgreeOnThePlan) {
  const auto dir = test::temp_dir("hlod_dist_node_mixed");
  const auto mesh = write_mesh(dir);
  const std::vector<uint8_t> local = local_bake(mesh, dir / "local");
  EXPECT_EQ(HlodDistributedSettings{}.share_mesh_from, 8u);
  const std::vector<RankRun> runs = run_ranks(6, mesh, dir / "out", dir / "cache", uint64_t(1) << 30, 4, 4);
  for (const RankRun& r : runs) ASSERT_TRUE(r.status) << r.status.message;
  EXPECT_EQ(test::read_bytes(dir / "out" / "mixed.hlod"), local);
  const std::vector<uint32_t> loaded{1, 0, 0, 0, 1, 1};
  ASSERT_EQ(runs[0].result.ranks.size(), 6u);
  for (size_t r = 0; r < 6; ++r) EXPECT_EQ(runs[0].result.ranks[r].mesh_loaded, loaded[r]) << "rank " << r;
  EXPECT_TRUE(runs[0].result.mesh_shared);
  EXPECT_FALSE(runs[4].result.mesh_shared);
}

// A textured model's uvs, runs and materials go through the node's copy unchanged.
TEST(HlodDistributedBake, TexturedModelThroughANodesCopyGivesTheLocalBytes) {
  const auto dir = test::temp_dir("hlod_dist_node_textured");
  const auto mesh = test::write_two_material_gltf(dir, "mixed", 48, 96);
  ASSERT_FALSE(mesh.empty());
  const std::vector<uint8_t> local = local_bake(mesh, dir / "local");
  for (bool rerun : {false, true}) {
    std::filesystem::remove(dir / "out" / "mixed.hlod");
    const std::vector<RankRun> runs = run_ranks(3, mesh, dir / "out", dir / "cache", uint64_t(1) << 30, 3);
    for (const RankRun& r : runs) ASSERT_TRUE(r.status) << r.status.message;
    EXPECT_TRUE(runs[0].result.mesh_shared);
    EXPECT_EQ(runs[0].result.mesh_cached, rerun);
    EXPECT_EQ(test::read_bytes(dir / "out" / "mixed.hlod"), local) << (rerun ? "rerun" : "first run");
  }
}

void expect_failure_saying(const Status& s, const std::string& words) {
  EXPECT_FALSE(s) << "expected a failure saying: " << words;
  EXPECT_NE(s.message.find(words), std::string::npos) << s.message;
}

// The node's first rank cannot load: it names the file, its node's other rank says its
// loader failed, rank 0 fails the job naming them, and nothing is written.
TEST(HlodDistributedBake, ANodesFirstRankThatCannotLoadFailsItsNodeByName) {
  const auto dir = test::temp_dir("hlod_dist_node_fail");
  const auto mesh = write_mesh(dir);
  const auto gone = dir / "gone" / "mixed.ply";
  const std::vector<RankRun> runs = run_ranks(
      4, [&](int r) { return RankPaths{r == 2 ? gone : mesh, dir / "out", dir / "cache"}; }, uint64_t(1) << 30, 2);
  expect_failure_saying(runs[0].status, "rank 2");
  expect_failure_saying(runs[2].status, gone.string());
  expect_failure_saying(runs[3].status, "this node's first rank could not load it");
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "mixed.hlod"));
}

// Memory the node cannot share (/dev/shm full): the loader says so and how to go on, the
// node's other rank that its loader failed; nothing is written.
TEST(HlodDistributedBake, ANodeThatCannotShareItsMemorySaysSoAndHowToGoOn) {
  const auto dir = test::temp_dir("hlod_dist_node_full");
  const auto mesh = write_mesh(dir);
  const std::vector<RankRun> runs =
      run_ranks(2, [&](int) { return RankPaths{mesh, dir / "out", dir / "cache"}; }, uint64_t(1) << 30, 2, 2, 1024);
  expect_failure_saying(runs[0].status, "memory this node's ranks share (/dev/shm full?): run with --mesh-copies rank");
  expect_failure_saying(runs[1].status, "this node's first rank could not load it");
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "mixed.hlod"));
}

// A rank holds its entries' bytes for the write up to held_entry_bytes; the others are read
// back from the cache when written. Nothing held, half held, all held: the same bytes.
TEST(HlodDistributedBake, EntriesBeyondTheMemoryBudgetAreReadBackIntoTheSameBytes) {
  const auto dir = test::temp_dir("hlod_dist_held");
  const auto mesh = write_mesh(dir);
  const std::vector<uint8_t> local = local_bake(mesh, dir / "local");
  auto sums = [](const std::vector<RankRun>& runs, uint64_t HlodRankWork::*field) {
    uint64_t sum = 0;
    for (const HlodRankWork& w : runs[0].result.ranks) sum += w.*field;
    return sum;
  };
  std::vector<RankRun> runs = run_ranks(2, mesh, dir / "none" / "out", dir / "none" / "cache", 0);
  for (const RankRun& r : runs) ASSERT_TRUE(r.status) << r.status.message;
  EXPECT_EQ(test::read_bytes(dir / "none" / "out" / "mixed.hlod"), local);
  const uint64_t written = sums(runs, &HlodRankWork::bytes_written);
  EXPECT_GT(written, 0u);
  EXPECT_EQ(sums(runs, &HlodRankWork::bytes_read_back), written) << "every entry read back";

  // From the cache (checked, not baked), half of each rank's share held.
  std::filesystem::remove(dir / "none" / "out" / "mixed.hlod");
  runs = run_ranks(2, mesh, dir / "none" / "out", dir / "none" / "cache", written / 4);
  for (const RankRun& r : runs) ASSERT_TRUE(r.status) << r.status.message;
  EXPECT_EQ(test::read_bytes(dir / "none" / "out" / "mixed.hlod"), local);
  const uint64_t back = sums(runs, &HlodRankWork::bytes_read_back);
  EXPECT_GT(back, 0u);
  EXPECT_LT(back, written);
  EXPECT_EQ(sums(runs, &HlodRankWork::bytes_checked), written);

  runs = run_ranks(2, mesh, dir / "all" / "out", dir / "all" / "cache");
  for (const RankRun& r : runs) ASSERT_TRUE(r.status) << r.status.message;
  EXPECT_EQ(test::read_bytes(dir / "all" / "out" / "mixed.hlod"), local);
  EXPECT_EQ(sums(runs, &HlodRankWork::bytes_read_back), 0u);
}

// An entry that changed on the shared storage between its store and its write (a byte flipped,
// cut short, removed) is found out when read back: the job fails naming it and writes no file;
// the rerun bakes that one again and gives the local bytes.
TEST(HlodDistributedBake, AnEntryChangedBeforeItIsReadBackFailsTheJobNamingIt) {
  const auto dir = test::temp_dir("hlod_dist_changed");
  const auto mesh = write_mesh(dir);
  const std::vector<uint8_t> local = local_bake(mesh, dir / "local");
  enum Change { flip, cut, remove };
  for (Change change : {flip, cut, remove}) {
    SCOPED_TRACE(change == flip ? "flipped" : change == cut ? "cut short" : "removed");
    HlodDistributedSettings s;
    s.min_verts = 150;
    s.threads = 1;
    s.cache_dir = dir / ("cache" + std::to_string(int(change)));
    s.held_entry_bytes = 0;
    std::filesystem::path changed;
    s.before_store = [&](size_t, size_t stored) {
      if (stored != 3) return;
      for (const auto& e : std::filesystem::directory_iterator(s.cache_dir))
        if (e.path().extension() == ".hsub") changed = e.path();
      std::vector<uint8_t> bytes = test::read_bytes(changed);
      if (change == flip) bytes[bytes.size() / 2] ^= 0x10;
      if (change == cut) bytes.resize(bytes.size() - 1);
      if (change == remove) std::filesystem::remove(changed);
      else test::write_bytes(changed, bytes);
    };
    HlodDistributedResult r;
    const Status st = bake_hlod_distributed(mesh, "mixed", dir / "out", s, single_rank_comm(), {}, &r);
    ASSERT_FALSE(st);
    ASSERT_FALSE(changed.empty());
    EXPECT_NE(st.message.find(changed.filename().string()), std::string::npos) << st.message;
    EXPECT_NE(st.message.find("reading"), std::string::npos) << st.message;
    EXPECT_NE(st.message.find("run again"), std::string::npos) << st.message;
    EXPECT_FALSE(std::filesystem::exists(dir / "out" / "mixed.hlod"));

    s.before_store = {};
    ASSERT_TRUE(bake_hlod_distributed(mesh, "mixed", dir / "out", s, single_rank_comm(), {}, &r)) << st.message;
    EXPECT_EQ(r.ranks.at(0).subtrees, 1u) << "only the changed entry is baked again";
    EXPECT_EQ(test::read_bytes(dir / "out" / "mixed.hlod"), local);
    std::filesystem::remove(dir / "out" / "mixed.hlod");
  }
}

TEST(HlodDistributedBake, OneRankRebakesOnlyTheCorruptedAndMissingEntries) {
  const auto dir = test::temp_dir("hlod_dist1");
  const auto mesh = write_mesh(dir);
  const std::vector<uint8_t> local = local_bake(mesh, dir / "local");
  HlodDistributedSettings s;
  s.min_verts = 150;
  s.cache_dir = dir / "cache";
  HlodDistributedResult r;
  ASSERT_TRUE(bake_hlod_distributed(mesh, "mixed", dir / "out", s, single_rank_comm(), {}, &r));
  EXPECT_EQ(test::read_bytes(dir / "out" / "mixed.hlod"), local);
  EXPECT_FALSE(r.mesh_cached);
  uint64_t source = 0;
  ASSERT_TRUE(hlod_source_hash(mesh, s.min_verts, source));
  EXPECT_TRUE(std::filesystem::exists(hlod_mesh_entry_path(s.cache_dir, source))) << "the cleaned mesh is kept for reruns";
  std::vector<std::filesystem::path> entries;
  for (const auto& e : std::filesystem::directory_iterator(s.cache_dir))
    if (e.path().extension() == ".hsub") entries.push_back(e.path());
  std::sort(entries.begin(), entries.end());
  ASSERT_EQ(entries.size(), r.subtrees);
  std::vector<uint8_t> bytes = test::read_bytes(entries[0]);
  bytes[bytes.size() - 20] ^= 0x80;
  test::write_bytes(entries[0], bytes);
  std::filesystem::remove(entries[1]);
  std::vector<std::string> lines;
  ASSERT_TRUE(bake_hlod_distributed(mesh, "mixed", dir / "out", s, single_rank_comm(),
                                    [&](const std::string& l) { lines.push_back(l); }, &r));
  EXPECT_EQ(r.cached, r.subtrees - 2);
  EXPECT_TRUE(r.mesh_cached) << "the rerun reads the cleaned mesh";
  ASSERT_EQ(r.ranks.size(), 1u);
  EXPECT_EQ(r.ranks[0].subtrees, 2u);
  EXPECT_TRUE(std::any_of(lines.begin(), lines.end(), [](const std::string& l) { return l.find("baking it again") != std::string::npos; }));
  EXPECT_EQ(test::read_bytes(dir / "out" / "mixed.hlod"), local);
}

// The source hash covers a glTF's other files (images, buffers), hashed piece by piece now: the
// same value as over each file whole, a file of several pieces included, and a missing one
// adds nothing (the load says it is missing).
TEST(HlodDistributedBake, SourceHashCoversTheFilesAGltfNamesPieceByPiece) {
  const auto dir = test::temp_dir("hlod_source_hash_gltf");
  const auto mesh = test::write_two_material_gltf(dir, "mixed", 8, 16);
  const std::vector<std::filesystem::path> named = gltf_external_files(mesh);
  ASSERT_FALSE(named.empty()) << "the fixture's images and buffer are files of their own";
  const std::filesystem::path victim = named.back();
  std::vector<uint8_t> big(size_t(2) << 20 | 12345);
  std::iota(big.begin(), big.end(), uint8_t(7));
  test::write_bytes(victim, big);  // bytes only: nothing decodes them here
  auto expected = [&] {
    const std::vector<uint8_t> own = test::read_bytes(mesh);
    uint64_t content = hash_bytes(own.data(), own.size());
    for (const auto& other : gltf_external_files(mesh)) {
      const std::vector<uint8_t> more = std::filesystem::exists(other) ? test::read_bytes(other) : std::vector<uint8_t>{};
      content = hash_bytes(more.data(), more.size(), content);
    }
    const uint64_t settings[2] = {kHlodBuildVersion, 150};
    return hash_bytes(settings, sizeof settings, content);
  };
  uint64_t got = 0;
  ASSERT_TRUE(hlod_source_hash(mesh, 150, got));
  EXPECT_EQ(got, expected());
  std::filesystem::remove(victim);
  const uint64_t before = got;
  ASSERT_TRUE(hlod_source_hash(mesh, 150, got));
  EXPECT_EQ(got, expected());
  EXPECT_NE(got, before) << victim << " is part of the source";
}

// A textured, two-material sphere: the distributed bake writes the local bake's
// bytes with its uvs, runs and materials, at 1, 2 and 3 ranks, and again from the cleaned mesh
// (uvs, submeshes and materials) and the subtrees in the cache.
TEST(HlodDistributedBake, TexturedModelGivesTheLocalBytesAtEveryRankCountAndFromTheCache) {
  const auto dir = test::temp_dir("hlod_dist_textured");
  const auto mesh = test::write_two_material_gltf(dir, "mixed", 48, 96);
  ASSERT_FALSE(mesh.empty());
  const std::vector<uint8_t> local = local_bake(mesh, dir / "local");
  HlodTree tree;
  std::vector<HlodPayload> payloads;
  ASSERT_TRUE(decode_hlod_asset(local, "mixed.hlod", tree, payloads));
  ASSERT_EQ(tree.materials.size(), 2u);
  EXPECT_TRUE(tree.uvs);
  EXPECT_EQ(tree.materials[0].base_color_texture, "mixed-image0.png");
  EXPECT_GT(tree.nodes.size(), 8u);
  for (int ranks : {1, 2, 3}) {
    const auto cache = dir / ("cache" + std::to_string(ranks));
    std::vector<RankRun> runs = run_ranks(ranks, mesh, dir / "out", cache);
    for (const RankRun& r : runs) ASSERT_TRUE(r.status) << r.status.message;
    EXPECT_EQ(test::read_bytes(dir / "out" / "mixed.hlod"), local) << ranks << " ranks";
    std::filesystem::remove(dir / "out" / "mixed.hlod");
    runs = run_ranks(ranks, mesh, dir / "out", cache);
    ASSERT_TRUE(runs[0].status) << runs[0].status.message;
    EXPECT_TRUE(runs[0].result.mesh_cached);
    EXPECT_EQ(runs[0].result.cached, runs[0].result.subtrees);
    EXPECT_EQ(test::read_bytes(dir / "out" / "mixed.hlod"), local) << ranks << " ranks, from the cache";
  }
}

// A GLB with its texture inside (most real glTF inputs): the tree keeps the PNG byte for byte,
// and the distributed bake writes the local bake's bytes at 1, 2 and 3 ranks, and again from
// the cleaned mesh entry (which stores the image) and the subtrees in the cache.
TEST(HlodDistributedBake, EmbeddedTextureGivesTheLocalBytesAtEveryRankCountAndFromTheCache) {
  const auto dir = test::temp_dir("hlod_dist_embedded");
  const std::vector<uint8_t> png = test::checker_png(32, 4);
  const auto mesh = dir / "globe.glb";
  test::write_bytes(mesh, test::embedded_texture_sphere({{"mimeType", "image/png"}}, &png, 48, 96).glb());
  const std::vector<uint8_t> local = local_bake(mesh, dir / "local");
  HlodTree tree;
  std::vector<HlodPayload> payloads;
  ASSERT_TRUE(decode_hlod_asset(local, "mixed.hlod", tree, payloads));
  ASSERT_EQ(tree.materials.size(), 2u);
  EXPECT_EQ(tree.materials[0].base_color_texture, "embedded:0");
  ASSERT_EQ(tree.images.size(), 1u);
  EXPECT_EQ(tree.images[0].type, ImageType::png);
  EXPECT_EQ(tree.images[0].bytes, png);
  EXPECT_GT(tree.nodes.size(), 8u);
  for (int ranks : {1, 2, 3}) {
    const auto cache = dir / ("cache" + std::to_string(ranks));
    std::vector<RankRun> runs = run_ranks(ranks, mesh, dir / "out", cache);
    for (const RankRun& r : runs) ASSERT_TRUE(r.status) << r.status.message;
    EXPECT_EQ(test::read_bytes(dir / "out" / "mixed.hlod"), local) << ranks << " ranks";
    std::filesystem::remove(dir / "out" / "mixed.hlod");
    runs = run_ranks(ranks, mesh, dir / "out", cache);
    ASSERT_TRUE(runs[0].status) << runs[0].status.message;
    EXPECT_TRUE(runs[0].result.mesh_cached);
    EXPECT_EQ(runs[0].result.cached, runs[0].result.subtrees);
    EXPECT_EQ(test::read_bytes(dir / "out" / "mixed.hlod"), local) << ranks << " ranks, from the cache";
  }
}

// Vertex colours and a second uv set with a material whose occlusion texture reads
// TEXCOORD_1: the tree keeps both attributes and the texture, and the distributed bake writes the
// local bake's bytes at 1, 2 and 3 ranks, and again from the cache (the cleaned mesh keeps them).
TEST(HlodDistributedBake, ColouredModelGivesTheLocalBytesAtEveryRankCountAndFromTheCache) {
  const auto dir = test::temp_dir("hlod_dist_coloured");
  const auto mesh = test::write_coloured_gltf(dir, "painted", 48, 96);
  ASSERT_FALSE(mesh.empty());
  const std::vector<uint8_t> local = local_bake(mesh, dir / "local");
  HlodTree tree;
  std::vector<HlodPayload> payloads;
  ASSERT_TRUE(decode_hlod_asset(local, "mixed.hlod", tree, payloads));
  EXPECT_TRUE(tree.uvs && tree.uvs1 && tree.colors);
  ASSERT_EQ(tree.materials.size(), 1u);
  EXPECT_FALSE(tree.materials[0].occlusion_texture.empty()) << "the texture reading TEXCOORD_1 is kept";
  EXPECT_EQ(tree.materials[0].tex_coords[3], 1);
  EXPECT_GT(tree.nodes.size(), 8u);
  for (const HlodPayload& p : payloads) EXPECT_EQ(p.colors.size(), p.positions.size() / 3 * 4);
  for (int ranks : {1, 2, 3}) {
    const auto cache = dir / ("cache" + std::to_string(ranks));
    std::vector<RankRun> runs = run_ranks(ranks, mesh, dir / "out", cache);
    for (const RankRun& r : runs) ASSERT_TRUE(r.status) << r.status.message;
    EXPECT_EQ(test::read_bytes(dir / "out" / "mixed.hlod"), local) << ranks << " ranks";
    std::filesystem::remove(dir / "out" / "mixed.hlod");
    runs = run_ranks(ranks, mesh, dir / "out", cache);
    ASSERT_TRUE(runs[0].status) << runs[0].status.message;
    EXPECT_TRUE(runs[0].result.mesh_cached);
    EXPECT_EQ(runs[0].result.cached, runs[0].result.subtrees);
    EXPECT_EQ(test::read_bytes(dir / "out" / "mixed.hlod"), local) << ranks << " ranks, from the cache";
  }
}

// The cleaned mesh entry keeps colours and uv1; hostile ones are refused: a flag set with no
// data (or cleared with data) no longer matches the size, an unknown flag and a non-finite
// colour or uv1 are named.
TEST(HlodMeshCache, ColouredMeshKeepsColoursAndUv1AndHostileOnesAreRefused) {
  const auto dir = test::temp_dir("hlod_mesh_cache_coloured");
  const MeshData m = test::coloured_sphere(8, 12);
  ASSERT_TRUE(store_hlod_mesh(dir, 5, m, 77));
  MeshData back;
  uint64_t input = 0;
  ASSERT_EQ(load_hlod_mesh(dir, 5, "painted.gltf", back, input), CacheLookup::found);
  EXPECT_EQ(back.uvs, m.uvs);
  EXPECT_EQ(back.uvs1, m.uvs1);
  EXPECT_EQ(back.colors, m.colors);
  const auto path = hlod_mesh_entry_path(dir, 5);
  const std::vector<uint8_t> good = test::read_bytes(path);
  EXPECT_EQ(good[12], 7) << "uvs, colours and uv1 flagged";
  const auto refused = [&](auto&& edit, const char* expected) {
    std::vector<uint8_t> bad = good;
    edit(bad);
    const uint64_t sum = hash_bytes(bad.data(), bad.size() - 8);
    std::memcpy(bad.data() + bad.size() - 8, &sum, 8);
    test::write_bytes(path, bad);
    std::string why;
    MeshData out;
    out.source = "untouched";
    EXPECT_EQ(load_hlod_mesh(dir, 5, "painted.gltf", out, input, &why), CacheLookup::refused) << expected;
    EXPECT_NE(why.find(expected), std::string::npos) << why;
    EXPECT_EQ(out.source, "untouched");
  };
  refused([](std::vector<uint8_t>& b) { b[12] = 5; }, "do not match");  // colours cleared, their bytes still there
  refused([](std::vector<uint8_t>& b) { b[12] = 3; }, "do not match");  // uv1 cleared
  refused([](std::vector<uint8_t>& b) { b[12] = 15; }, "unknown flags 15");
  const size_t nv = m.vertex_count();
  const size_t colours = 72 + 12 * nv + 4 * m.indices.size() + 8 * nv + 8 * nv;
  refused([&](std::vector<uint8_t>& b) {
    const float nan = NAN;
    std::memcpy(b.data() + colours + 4 * 6, &nan, 4);
  }, "a colour is not finite");
  refused([&](std::vector<uint8_t>& b) {
    const float inf = -INFINITY;
    std::memcpy(b.data() + colours - 8 * nv + 4, &inf, 4);
  }, "a TEXCOORD_1 value is not finite");
  // Flags set, the data missing: the entry is shorter than its counts say.
  std::vector<uint8_t> short_entry(good.begin(), good.begin() + std::ptrdiff_t(colours));
  short_entry.insert(short_entry.end(), good.begin() + std::ptrdiff_t(colours + 16 * nv), good.end());
  const uint64_t sum = hash_bytes(short_entry.data(), short_entry.size() - 8);
  std::memcpy(short_entry.data() + short_entry.size() - 8, &sum, 8);
  test::write_bytes(path, short_entry);
  std::string why;
  EXPECT_EQ(load_hlod_mesh(dir, 5, "painted.gltf", back, input, &why), CacheLookup::refused);
  EXPECT_NE(why.find("do not match"), std::string::npos) << why;
}

TEST(HlodMeshCache, TexturedMeshKeepsUvsSubmeshesAndMaterials) {
  const auto dir = test::temp_dir("hlod_mesh_cache_textured");
  const MeshData m = test::two_material_sphere(8, 12);
  HlodSurfaces surfaces;
  surfaces.materials.resize(2);
  surfaces.materials[0].name = "cap";
  surfaces.materials[0].base_color_texture = "checker.png";
  surfaces.texture_base = "/textures";
  surfaces.materials[1].emissive_texture = "embedded:0";
  surfaces.images.push_back({ImageType::png, test::checker_png(8, 2)});
  ASSERT_TRUE(store_hlod_mesh(dir, 9, m, 99, surfaces));
  MeshData back;
  HlodSurfaces got;
  uint64_t input = 0;
  ASSERT_EQ(load_hlod_mesh(dir, 9, "ball.gltf", back, input, nullptr, &got), CacheLookup::found);
  EXPECT_EQ(back.uvs, m.uvs);
  ASSERT_EQ(back.submeshes.size(), m.submeshes.size());
  EXPECT_EQ(back.submeshes[1].material, 1);
  ASSERT_EQ(got.materials.size(), 2u);
  EXPECT_EQ(got.materials[0].base_color_texture, "checker.png");
  EXPECT_EQ(got.texture_base, "/textures");
  EXPECT_EQ(got.materials[1].emissive_texture, "embedded:0");
  ASSERT_EQ(got.images.size(), 1u);
  EXPECT_EQ(got.images[0].bytes, surfaces.images[0].bytes);
  // Each edit under a forged checksum: refused, saying why.
  const auto path = hlod_mesh_entry_path(dir, 9);
  const std::vector<uint8_t> good = test::read_bytes(path);
  const auto refused = [&](size_t at, uint8_t value, const char* expected) {
    std::vector<uint8_t> bad = good;
    bad[at] = value;
    const uint64_t sum = hash_bytes(bad.data(), bad.size() - 8);
    std::memcpy(bad.data() + bad.size() - 8, &sum, 8);
    test::write_bytes(path, bad);
    std::string why;
    EXPECT_EQ(load_hlod_mesh(dir, 9, "ball.gltf", back, input, &why, &got), CacheLookup::refused) << expected;
    EXPECT_NE(why.find(expected), std::string::npos) << why;
  };
  // A submesh naming a material the entry does not hold.
  const size_t submeshes = 72 + 20 * m.vertex_count() + 4 * m.indices.size();
  refused(submeshes + 12 + 8, 5, "names a material of the 2");
  // The image's PNG signature broken (its bytes end where the checksum starts; its 16-byte entry,
  // u64 length then u8 type, comes just before them).
  const size_t image = good.size() - 8 - surfaces.images[0].bytes.size();
  refused(image + 1, 'Q', "is not the PNG or JPEG its type says");
  // Its type byte neither PNG nor JPEG.
  refused(image - 16 + 8, 9, "has type 9");
  // More images bytes than the entry holds (the count field at 64).
  refused(64, uint8_t(good[64] + 8), "do not match");
}

TEST(HlodMeshCache, CleanedMeshRoundTripsAndBrokenEntriesAreRefused) {
  const auto dir = test::temp_dir("hlod_mesh_cache");
  const MeshData m = test::vd_sphere(20, 30);
  MeshData back;
  uint64_t input = 0;
  EXPECT_EQ(load_hlod_mesh(dir, 7, "ball.ply", back, input), CacheLookup::missing);
  ASSERT_TRUE(store_hlod_mesh(dir, 7, m, 1234));
  ASSERT_EQ(load_hlod_mesh(dir, 7, "ball.ply", back, input), CacheLookup::found);
  EXPECT_EQ(back.positions, m.positions);
  EXPECT_EQ(back.indices, m.indices);
  EXPECT_EQ(back.source, "ball.ply");
  EXPECT_EQ(input, 1234u);
  const auto path = hlod_mesh_entry_path(dir, 7);
  const std::vector<uint8_t> good = test::read_bytes(path);
  std::string why;
  for (size_t at : {size_t(3), size_t(20), good.size() / 2, good.size() - 3}) {
    std::vector<uint8_t> bad = good;
    bad[at] ^= 0x40;
    test::write_bytes(path, bad);
    MeshData out;
    out.source = "untouched";
    EXPECT_EQ(load_hlod_mesh(dir, 7, "ball.ply", out, input, &why), CacheLookup::refused) << "flipped byte " << at;
    EXPECT_EQ(out.source, "untouched");
  }
  test::write_bytes(path, std::vector<uint8_t>(good.begin(), good.end() - 1));
  EXPECT_EQ(load_hlod_mesh(dir, 7, "ball.ply", back, input, &why), CacheLookup::refused);
  EXPECT_NE(why.find("truncated"), std::string::npos) << why;
  test::write_bytes(path, good);
  std::filesystem::rename(path, hlod_mesh_entry_path(dir, 8));
  EXPECT_EQ(load_hlod_mesh(dir, 8, "ball.ply", back, input, &why), CacheLookup::refused) << "stored for source 7";
  EXPECT_NE(why.find("another source"), std::string::npos) << why;
}

TEST(HlodDistributedBake, FailingStoreNamesTheSubtreeAndKeepsTheOthers) {
  const auto dir = test::temp_dir("hlod_dist_fail");
  const auto mesh = write_mesh(dir);
  HlodDistributedSettings s;
  s.min_verts = 150;
  s.threads = 1;
  s.cache_dir = dir / "cache";
  s.before_store = [](size_t, size_t stored) {
    if (stored == 5) throw std::runtime_error("injected: the disk is full");
  };
  HlodDistributedResult r;
  const Status st = bake_hlod_distributed(mesh, "mixed", dir / "out", s, single_rank_comm(), {}, &r);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("rank 0"), std::string::npos) << st.message;
  EXPECT_NE(st.message.find("the disk is full"), std::string::npos) << st.message;
  EXPECT_NE(st.message.find("run again"), std::string::npos) << st.message;
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "mixed.hlod"));
  size_t kept = 0;
  for (const auto& e : std::filesystem::directory_iterator(s.cache_dir)) kept += e.path().extension() == ".hsub";
  EXPECT_EQ(kept, 5u);
}

// The input is hashed before anything else: a directory or a FIFO is refused by name, never
// read (a directory once reached an allocation of its "size"; a FIFO would block).
TEST(HlodDistributedBake, InputThatIsNotARegularFileIsRefusedByName) {
  const auto dir = test::temp_dir("hlod_dist_notfile");
  HlodDistributedSettings s;
  s.cache_dir = dir / "cache";
  std::filesystem::create_directories(dir / "folder.ply");
  const std::filesystem::path fifo = dir / "pipe.ply";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::pair<std::filesystem::path, const char*> inputs[] = {
      {dir / "folder.ply", "is a directory"}, {fifo, "FIFO"}, {dir / "absent.ply", "no such file"}};
  for (const auto& [input, says] : inputs) {
    HlodDistributedResult r;
    const Status st = bake_hlod_distributed(input, "x", dir / "out", s, single_rank_comm(), {}, &r);
    ASSERT_FALSE(st) << input;
    EXPECT_NE(st.message.find(input.string()), std::string::npos) << st.message;
    EXPECT_NE(st.message.find(says), std::string::npos) << st.message;
    EXPECT_EQ(st.message.find("run again"), std::string::npos) << "nothing was baked: " << st.message;
    uint64_t hash = 0;
    EXPECT_FALSE(hlod_source_hash(input, 150, hash)) << input;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "x.hlod"));
}

}  // namespace
}  // namespace lod
