// lod-bake-mpi under mpirun on loopback: at 1, 2 and 4 ranks the file is the bytes
// of `lod bake --hlod`; a rank killed mid-run (LOD_MPI_FAIL_AFTER) fails the job, keeps the
// partial cache, and the rerun bakes only what is missing into the same bytes; corrupted and
// truncated entries are rebaked; a rank that fails says which subtree and why.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "bake_cache_files.h"
#include "run_cli.h"
#include "runtime/hlod_asset.h"
#include "test_support.h"
#include "textured_fixture.h"

namespace lod {
namespace {

#if defined(LOD_BAKE_MPI_PATH) && defined(LOD_MPIEXEC)

using test::run_mpi;

// A closed sphere of 48,000 triangles, written by the test (no third-party mesh).
struct Fixture {
  std::filesystem::path dir, mesh;
  std::vector<uint8_t> local;  // lod bake --hlod of it
};

const Fixture& fixture() {
  static const Fixture f = [] {
    Fixture x;
    x.dir = test::temp_dir("lod_bake_mpi");
    x.mesh = x.dir / "ball.off";
    test::write_text(x.mesh, test::sphere_off(120, 200));
    const test::CliResult r = test::run_lod("bake " + x.mesh.string() + " -o " + (x.dir / "local").string() +
                                            " --hlod --min-verts 300 --quiet");
    EXPECT_EQ(r.code, 0) << r.out;
    x.local = test::read_bytes(x.dir / "local" / "ball.hlod");
    return x;
  }();
  return f;
}

std::string bake_args(const std::filesystem::path& out, const std::filesystem::path& cache) {
  return fixture().mesh.string() + " -o " + out.string() + " --cache " + cache.string() + " --min-verts 300 --threads 1";
}

size_t entries(const std::filesystem::path& cache) { return test::cache_entries(cache, ".hsub").size(); }


TEST(LodBakeMpi, SameBytesAsTheLocalBakeAtOneTwoAndFourRanks) {
  ASSERT_FALSE(fixture().local.empty());
  for (int ranks : {1, 2, 4}) {
    const auto dir = test::temp_dir("lod_bake_mpi_np" + std::to_string(ranks));
    const test::CliResult r = run_mpi(ranks, bake_args(dir / "out", dir / "cache") + " --json");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_EQ(test::read_bytes(dir / "out" / "ball.hlod"), fixture().local) << ranks << " ranks";
    const nlohmann::json j = test::printed_json(r);
    ASSERT_TRUE(j.is_object()) << r.out;
    EXPECT_EQ(j["ranks"], ranks);
    EXPECT_GE(j["subtrees"].get<int>(), std::max(16, 8 * ranks));  // lod::default_subtrees
    EXPECT_EQ(j["per_rank"].size(), size_t(ranks));
    for (const auto& w : j["per_rank"]) {
      EXPECT_GT(w["subtrees"].get<int>(), 0) << "a rank without work";
      // Every rank's own process figures, taken at its last report (an MPI process holds MBs).
      EXPECT_GT(w["kernel_cpu_s"].get<double>(), 0.0) << w;
      EXPECT_GT(w["peak_rss_mb"].get<double>(), 1.0) << w;
    }
  }
}

// "At any rank and thread count": several TBB threads per rank (subtrees finished in any
// order, the BVH beside them) and an odd rank count (uneven shares, cuts refined for 3) give
// the local bake's bytes too; the test above runs 1 thread per rank.
TEST(LodBakeMpi, SameBytesWithSeveralThreadsPerRankAndThreeRanks) {
  ASSERT_FALSE(fixture().local.empty());
  const std::pair<int, int> runs[] = {{1, 3}, {2, 2}, {3, 1}, {3, 2}};
  for (const auto& [ranks, threads] : runs) {
    const std::string what = std::to_string(ranks) + " ranks x " + std::to_string(threads) + " threads";
    const auto dir = test::temp_dir("lod_bake_mpi_np" + std::to_string(ranks) + "t" + std::to_string(threads));
    std::string args = bake_args(dir / "out", dir / "cache");
    args.replace(args.rfind("--threads 1"), std::string("--threads 1").size(), "--threads " + std::to_string(threads));
    const test::CliResult r = run_mpi(ranks, args + " --json");
    ASSERT_EQ(r.code, 0) << what << "\n" << r.out;
    EXPECT_EQ(test::read_bytes(dir / "out" / "ball.hlod"), fixture().local) << what;
    const nlohmann::json j = test::printed_json(r);
    ASSERT_TRUE(j.is_object()) << r.out;
    EXPECT_EQ(j["ranks"], ranks) << what;
    int baked = 0;
    for (const auto& w : j["per_rank"]) baked += w["subtrees"].get<int>();
    EXPECT_EQ(baked, j["subtrees"].get<int>()) << what << ": every subtree baked once, from an empty cache";
  }
}

// A textured, two-material model: uvs, runs and materials, the same bytes at 1, 2
// and 4 ranks as lod bake --hlod.
TEST(LodBakeMpi, TexturedModelSameBytesAsTheLocalBakeAtOneTwoAndFourRanks) {
  const auto dir = test::temp_dir("lod_bake_mpi_textured");
  const std::filesystem::path gltf = test::write_two_material_gltf(dir / "src", "globe", 60, 120);
  ASSERT_FALSE(gltf.empty());
  const test::CliResult local =
      test::run_lod("bake " + gltf.string() + " -o " + (dir / "local").string() + " --hlod --min-verts 300 --quiet");
  ASSERT_EQ(local.code, 0) << local.out;
  const std::vector<uint8_t> bytes = test::read_bytes(dir / "local" / "globe.hlod");
  for (int ranks : {1, 2, 4}) {
    const auto out = dir / ("np" + std::to_string(ranks));
    const test::CliResult r = run_mpi(ranks, gltf.string() + " -o " + (out / "out").string() + " --cache " +
                                                 (out / "cache").string() + " --min-verts 300 --threads 1");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_EQ(test::read_bytes(out / "out" / "globe.hlod"), bytes) << ranks << " ranks";
  }
}

// Vertex colours and a second uv set, with a texture reading TEXCOORD_1: the same
// bytes at 1, 2 and 4 ranks as lod bake --hlod, and the tree has both attributes.
TEST(LodBakeMpi, ColouredModelSameBytesAsTheLocalBakeAtOneTwoAndFourRanks) {
  const auto dir = test::temp_dir("lod_bake_mpi_coloured");
  const std::filesystem::path gltf = test::write_coloured_gltf(dir / "src", "painted", 60, 120);
  ASSERT_FALSE(gltf.empty());
  const test::CliResult local =
      test::run_lod("bake " + gltf.string() + " -o " + (dir / "local").string() + " --hlod --min-verts 300 --quiet");
  ASSERT_EQ(local.code, 0) << local.out;
  const std::vector<uint8_t> bytes = test::read_bytes(dir / "local" / "painted.hlod");
  HlodTree tree;
  ASSERT_TRUE(read_hlod_tree(dir / "local" / "painted.hlod", tree));
  EXPECT_TRUE(tree.colors && tree.uvs1 && tree.uvs);
  for (int ranks : {1, 2, 4}) {
    const auto out = dir / ("np" + std::to_string(ranks));
    const test::CliResult r = run_mpi(ranks, gltf.string() + " -o " + (out / "out").string() + " --cache " +
                                                 (out / "cache").string() + " --min-verts 300 --threads 1");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_EQ(r.out.find("not kept"), std::string::npos) << r.out;
    EXPECT_EQ(test::read_bytes(out / "out" / "painted.hlod"), bytes) << ranks << " ranks";
  }
}

TEST(LodBakeMpi, KilledRankThenRerunBakesOnlyTheMissingSubtreesIntoTheSameBytes) {
  const auto dir = test::temp_dir("lod_bake_mpi_kill");
  const test::CliResult killed = test::run_mpi_program(2, LOD_BAKE_MPI_FAULTS_PATH, bake_args(dir / "out", dir / "cache"),
                                                       "LOD_MPI_FAIL_AFTER=4 LOD_MPI_FAIL_RANK=1");
  EXPECT_NE(killed.code, 0) << killed.out;
  EXPECT_NE(killed.out.find("injected failure"), std::string::npos) << killed.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "ball.hlod"));
  const size_t kept = entries(dir / "cache");
  EXPECT_GE(kept, 4u) << "the partial cache is kept";

  const test::CliResult rerun = run_mpi(2, bake_args(dir / "out", dir / "cache") + " --json");
  ASSERT_EQ(rerun.code, 0) << rerun.out;
  const nlohmann::json j = test::printed_json(rerun);
  ASSERT_TRUE(j.is_object()) << rerun.out;
  const size_t total = j["subtrees"].get<size_t>();
  ASSERT_LT(kept, total);
  EXPECT_EQ(j["cached"].get<size_t>(), kept);
  size_t baked = 0;
  for (const auto& w : j["per_rank"]) baked += w["subtrees"].get<size_t>();
  EXPECT_EQ(baked, total - kept) << "only the missing subtrees are baked";
  EXPECT_EQ(test::read_bytes(dir / "out" / "ball.hlod"), fixture().local);
  EXPECT_EQ(entries(dir / "cache"), total);
  EXPECT_TRUE(j["mesh_cached"].get<bool>()) << "the rerun reads the cleaned mesh the killed run stored";
}

// The `lod bake` spelling of the job, `mpirun -np N lod bake ... --hlod --distributed`: each rank becomes
// the lod-bake-mpi beside lod; without --cache the cache is OUT/hlod-cache, so the same command
// run again resumes from it (here: finds every subtree).
TEST(LodBakeMpi, LodBakeDistributedIsTheSameBakeAndResumesFromItsDefaultCache) {
  const auto dir = test::temp_dir("lod_bake_distributed");
  const std::string args = "bake " + fixture().mesh.string() + " -o " + (dir / "out").string() +
                           " --hlod --distributed --min-verts 300 --threads 1 --json";
  const test::CliResult first = test::run_mpi_program(2, LOD_CLI_PATH, args);
  ASSERT_EQ(first.code, 0) << first.out;
  EXPECT_EQ(test::read_bytes(dir / "out" / "ball.hlod"), fixture().local);
  const nlohmann::json j = test::printed_json(first);
  ASSERT_TRUE(j.is_object()) << first.out;
  EXPECT_EQ(j["ranks"], 2);
  EXPECT_EQ(j["cached"].get<size_t>(), 0u);
  const size_t total = j["subtrees"].get<size_t>();
  EXPECT_EQ(entries(dir / "out" / "hlod-cache"), total);

  const test::CliResult again = test::run_mpi_program(2, LOD_CLI_PATH, args);
  ASSERT_EQ(again.code, 0) << again.out;
  const nlohmann::json k = test::printed_json(again);
  ASSERT_TRUE(k.is_object()) << again.out;
  EXPECT_EQ(k["cached"].get<size_t>(), total) << "the rerun found the default cache";
  EXPECT_EQ(test::read_bytes(dir / "out" / "ball.hlod"), fixture().local);
  EXPECT_FALSE(j["mesh_shared"].get<bool>()) << "2 ranks on a node keep a copy each by default";

  const test::CliResult shared = test::run_mpi_program(
      2, LOD_CLI_PATH, args + " --mesh-copies node --cache " + (dir / "node-cache").string());
  ASSERT_EQ(shared.code, 0) << shared.out;
  const nlohmann::json o = test::printed_json(shared);
  ASSERT_TRUE(o.is_object()) << shared.out;
  EXPECT_TRUE(o["mesh_shared"].get<bool>()) << "--mesh-copies reaches lod-bake-mpi";
  EXPECT_EQ(test::read_bytes(dir / "out" / "ball.hlod"), fixture().local);
}

TEST(LodBakeMpi, LodBakeDistributedRefusesWhatItCannotDo) {
  const std::string mesh = fixture().mesh.string(), out = (test::temp_dir("lod_bake_distributed_bad") / "o").string();
  const std::pair<std::string, std::string> cases[] = {
      {"bake " + mesh + " -o " + out + " --distributed", "add --hlod"},
      {"bake " + mesh + " -o " + out + " --hlod --distributed --ratios 1 0.5", "--ratios and --method"},
      {"bake " + mesh + " -o " + out + " --hlod --cache " + out, "options of --distributed"},
      {"bake " + mesh + " -o " + out + " --subtrees 4", "options of --distributed"},
      {"bake " + mesh + " -o " + out + " --hlod --mesh-copies rank", "options of --distributed"},
  };
  for (const auto& [args, says] : cases) {
    const test::CliResult r = test::run_lod(args);
    EXPECT_EQ(r.code, 1) << args << "\n" << r.out;
    EXPECT_NE(r.out.find(says), std::string::npos) << args << "\n" << r.out;
  }
  EXPECT_FALSE(std::filesystem::exists(out)) << "nothing written";
}

// A cache folder of each node's own (here: a path per rank, as a job script giving node-local
// scratch would): the job stops before any bake, exit code 1, naming the rank and the folder.
TEST(LodBakeMpi, NodeLocalCacheFolderStopsTheJobBeforeAnyBake) {
  const auto dir = test::temp_dir("lod_bake_mpi_node_local");
  const std::string per_rank = std::string("sh -c '") + LOD_BAKE_MPI_PATH + " " + fixture().mesh.string() + " -o " +
                               (dir / "out").string() + " --cache " + (dir / "cache-").string() +
                               "$OMPI_COMM_WORLD_RANK --min-verts 300 --threads 1'";
  const test::CliResult r = test::run_mpi_program(2, per_rank, "");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("rank 1 does not see, in its cache folder, the file rank 0 made in " + (dir / "cache-0").string()),
            std::string::npos)
      << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "ball.hlod"));
  EXPECT_EQ(entries(dir / "cache-0") + entries(dir / "cache-1"), 0u) << "nothing baked";
}

TEST(LodBakeMpi, CorruptedAndTruncatedEntriesAreRebaked) {
  const auto dir = test::temp_dir("lod_bake_mpi_corrupt");
  ASSERT_EQ(run_mpi(2, bake_args(dir / "out", dir / "cache") + " --quiet").code, 0);
  const std::vector<std::filesystem::path> files = test::cache_entries(dir / "cache", ".hsub");
  ASSERT_GE(files.size(), 2u);
  test::corrupt_entry(files[0]);
  test::truncate_entry(files[1]);
  std::filesystem::remove(dir / "out" / "ball.hlod");

  const test::CliResult r = run_mpi(2, bake_args(dir / "out", dir / "cache") + " --json");
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json j = test::printed_json(r);
  ASSERT_TRUE(j.is_object()) << r.out;
  EXPECT_EQ(j["cached"].get<size_t>(), files.size() - 2);
  EXPECT_NE(r.out.find("checksum mismatch"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("truncated"), std::string::npos) << r.out;
  EXPECT_EQ(test::read_bytes(dir / "out" / "ball.hlod"), fixture().local);
}

// An entry's place taken by a non-empty folder: the rank baking it cannot rename into place.
TEST(LodBakeMpi, FailingRankNamesTheSubtreeAndTheJobFailsKeepingTheCache) {
  const auto dir = test::temp_dir("lod_bake_mpi_fail");
  ASSERT_EQ(run_mpi(2, bake_args(dir / "out", dir / "cache") + " --quiet").code, 0);
  const std::vector<std::filesystem::path> files = test::cache_entries(dir / "cache", ".hsub");
  const auto blocked = files[files.size() / 2];
  std::filesystem::remove(blocked);
  std::filesystem::create_directories(blocked / "in-the-way");
  std::filesystem::remove(dir / "out" / "ball.hlod");

  const test::CliResult r = run_mpi(2, bake_args(dir / "out", dir / "cache"));
  EXPECT_NE(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("subtree "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(blocked.filename().string()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("run again"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "ball.hlod"));
  EXPECT_EQ(entries(dir / "cache"), files.size() - 1);
}

// A 2-rank bake per environment: `key` in --json as expected, the bytes those of the local bake.
void expect_malloc_flag(const char* dir_name, const char* key, std::initializer_list<std::pair<std::string, bool>> cases) {
  const auto dir = test::temp_dir(dir_name);
  int k = 0;
  for (const auto& [env, expected] : cases) {
    const auto run = dir / std::to_string(k++);
    const test::CliResult r = run_mpi(2, bake_args(run / "out", run / "cache") + " --json", env);
    ASSERT_EQ(r.code, 0) << env << "\n" << r.out;
    const nlohmann::json j = test::printed_json(r);
    ASSERT_TRUE(j.is_object()) << r.out;
    EXPECT_EQ(j[key], expected) << env;
    EXPECT_EQ(test::read_bytes(run / "out" / "ball.hlod"), fixture().local) << env;
  }
}

// Each rank starts itself again with glibc.malloc.hugetlb=1 where the kernel gives huge pages by
// madvise (cli/huge_page_malloc.h), unless told not to; the bytes never change.
TEST(LodBakeMpi, RanksAskForHugePagesUnlessToldNotTo) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "a sanitizer's allocator ignores glibc's malloc tunables";
#endif
  std::ifstream thp("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string modes;
  std::getline(thp, modes);
  if (modes.find("[madvise]") == std::string::npos)
    GTEST_SKIP() << "transparent huge pages are not in madvise mode here: '" << modes << "'";
  expect_malloc_flag("lod_bake_mpi_huge_pages", "malloc_huge_pages",
                     {{"", true}, {"LOD_HUGE_PAGES=0", false}, {"GLIBC_TUNABLES=glibc.malloc.hugetlb=0", false}});
}

// Each rank keeps what it frees for its next phase (cli/freed_memory.h) unless told not to; the
// bytes never change.
TEST(LodBakeMpi, RanksKeepFreedMemoryUnlessToldNotTo) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "a sanitizer's allocator refuses glibc's mallopt";
#endif
  expect_malloc_flag("lod_bake_mpi_freed_memory", "malloc_keeps_freed_memory",
                     {{"", true}, {"LOD_KEEP_FREED_MEMORY=0", false}});
}

// One node here: with --mesh-copies node its first rank loads the mesh into the memory the
// ranks share and the others read it in place; with rank every rank has its own copy; auto
// shares from 8 ranks on a node. The same bytes every way.
TEST(LodBakeMpi, RanksOfANodeShareOneCopyOfTheMeshWhenAskedOrFromEightRanks) {
  const auto dir = test::temp_dir("lod_bake_mpi_node_share");
  struct Case {
    const char* copies;
    int ranks;
    bool shared;
  };
  for (const Case c : {Case{"node", 3, true}, Case{"rank", 3, false}, Case{"auto", 4, false}, Case{"auto", 8, true}}) {
    const std::string what = std::string(c.copies) + " at " + std::to_string(c.ranks);
    const auto run = dir / (std::string(c.copies) + std::to_string(c.ranks));
    const test::CliResult r =
        run_mpi(c.ranks, bake_args(run / "out", run / "cache") + " --json --mesh-copies " + c.copies, "");
    ASSERT_EQ(r.code, 0) << r.out;
    const nlohmann::json j = test::printed_json(r);
    ASSERT_TRUE(j.is_object()) << r.out;
    EXPECT_EQ(j["mesh_shared"], c.shared) << what;
    ASSERT_EQ(j["per_rank"].size(), size_t(c.ranks));
    for (int rank = 0; rank < c.ranks; ++rank)
      EXPECT_EQ(j["per_rank"][size_t(rank)]["mesh_loaded"], !c.shared || rank == 0) << what << ", rank " << rank;
    EXPECT_EQ(test::read_bytes(run / "out" / "ball.hlod"), fixture().local) << what;
  }
}

#else
TEST(LodBakeMpi, NeedsMpi) { GTEST_SKIP() << "built without MPI (lod-bake-mpi absent): run scripts/install-deps.sh"; }
#endif

}  // namespace
}  // namespace lod
