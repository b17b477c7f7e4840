// lod-bake-mpi over a scene of several meshes under mpirun on loopback ("a scene of
// many models is split by models"): at 1, 2 and 4 ranks every DIR/<name>.hlod is the bytes of
// `lod bake --hlod` of its file; a rank killed mid-run (LOD_MPI_FAIL_AFTER) fails the job, keeps
// the cache, and the rerun bakes only the missing models into the same bytes; a corrupted or
// truncated model entry is rebaked; a failing rank names the model; one name twice is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "bake_cache_files.h"
#include "run_cli.h"
#include "test_support.h"

namespace lod {
namespace {

#if defined(LOD_BAKE_MPI_PATH) && defined(LOD_MPIEXEC)

using test::run_mpi;

// Five closed spheres of 400 to 16,000 triangles, written by the test. The boulder holds two
// thirds of the triangles (split over the ranks at 2 and 4); the rest go whole.
const char* const kNames[] = {"pebble", "stone", "rock", "crag", "boulder"};
constexpr int kSizes[5][2] = {{10, 20}, {20, 30}, {30, 40}, {40, 50}, {80, 100}};

struct Fixture {
  std::filesystem::path dir;
  std::string meshes;                 // the five paths, space separated
  std::vector<std::vector<uint8_t>> local;  // lod bake --hlod of each
};

const Fixture& fixture() {
  static const Fixture f = [] {
    Fixture x;
    x.dir = test::temp_dir("lod_bake_mpi_models");
    for (int k = 0; k < 5; ++k) {
      const auto mesh = x.dir / (std::string(kNames[k]) + ".off");
      test::write_text(mesh, test::sphere_off(kSizes[k][0], kSizes[k][1]));
      x.meshes += mesh.string() + " ";
    }
    const test::CliResult r = test::run_lod("bake " + x.meshes + "-o " + (x.dir / "local").string() +
                                            " --hlod --min-verts 300 --quiet");
    EXPECT_EQ(r.code, 0) << r.out;
    for (const char* name : kNames) x.local.push_back(test::read_bytes(x.dir / "local" / (std::string(name) + ".hlod")));
    return x;
  }();
  return f;
}

std::string bake_args(const std::filesystem::path& out, const std::filesystem::path& cache) {
  return fixture().meshes + "-o " + out.string() + " --cache " + cache.string() + " --min-verts 300 --threads 1";
}

void expect_local_bytes(const std::filesystem::path& out, const std::string& what) {
  for (size_t k = 0; k < 5; ++k)
    EXPECT_EQ(test::read_bytes(out / (std::string(kNames[k]) + ".hlod")), fixture().local[k]) << kNames[k] << ", " << what;
}



size_t baked(const nlohmann::json& j) {
  size_t n = j["split"].get<size_t>();
  for (const auto& w : j["per_rank"]) n += w["baked"].get<size_t>();
  return n;
}

TEST(LodBakeMpiModels, EveryModelHasTheLocalBakesBytesAtOneTwoAndFourRanks) {
  for (const auto& bytes : fixture().local) ASSERT_FALSE(bytes.empty());
  for (int ranks : {1, 2, 4}) {
    const auto dir = test::temp_dir("lod_bake_mpi_models_np" + std::to_string(ranks));
    const test::CliResult r = run_mpi(ranks, bake_args(dir / "out", dir / "cache") + " --json");
    ASSERT_EQ(r.code, 0) << r.out;
    expect_local_bytes(dir / "out", std::to_string(ranks) + " ranks");
    const nlohmann::json j = test::printed_json(r);
    ASSERT_TRUE(j.is_object()) << r.out;
    EXPECT_EQ(j["ranks"], ranks);
    EXPECT_EQ(j["models_total"], 5);
    EXPECT_EQ(j["failed"], 0);
    EXPECT_EQ(j["split"], ranks == 1 ? 0 : 1) << "the boulder is above a rank's share at 2 and 4 ranks";
    EXPECT_EQ(j["models"][4]["route"], ranks == 1 ? "whole" : "split");
    EXPECT_EQ(j["per_rank"].size(), size_t(ranks));
    for (const auto& w : j["per_rank"]) EXPECT_GT(w["baked"].get<int>(), 0) << "a rank without a whole model";
    EXPECT_EQ(test::cache_entries(dir / "cache", ".hlod").size(), 5u) << "every model in the cache";
  }
}

TEST(LodBakeMpiModels, KilledRankThenRerunBakesOnlyTheMissingModelsIntoTheSameBytes) {
  const auto dir = test::temp_dir("lod_bake_mpi_models_kill");
  const test::CliResult killed = test::run_mpi_program(2, LOD_BAKE_MPI_FAULTS_PATH, bake_args(dir / "out", dir / "cache"),
                                                       "LOD_MPI_FAIL_AFTER=1 LOD_MPI_FAIL_RANK=1");
  EXPECT_NE(killed.code, 0) << killed.out;
  EXPECT_NE(killed.out.find("injected failure"), std::string::npos) << killed.out;
  const size_t kept = test::cache_entries(dir / "cache", ".hlod").size();
  EXPECT_GE(kept, 1u) << "the killed rank's first model is kept";
  ASSERT_LT(kept, 5u);

  const test::CliResult rerun = run_mpi(2, bake_args(dir / "out", dir / "cache") + " --json");
  ASSERT_EQ(rerun.code, 0) << rerun.out;
  const nlohmann::json j = test::printed_json(rerun);
  ASSERT_TRUE(j.is_object()) << rerun.out;
  EXPECT_EQ(j["cached"].get<size_t>(), kept);
  EXPECT_EQ(baked(j), 5 - kept) << "only the missing models are baked";
  expect_local_bytes(dir / "out", "after the rerun");
}

// Rank 0 dies in the boulder's subtrees (after its whole model and two subtrees): the rerun
// takes the whole models from the cache and the boulder's finished subtrees too.
TEST(LodBakeMpiModels, KilledInASplitModelThenRerunKeepsItsSubtrees) {
  const auto dir = test::temp_dir("lod_bake_mpi_models_kill_split");
  const test::CliResult killed = test::run_mpi_program(2, LOD_BAKE_MPI_FAULTS_PATH, bake_args(dir / "out", dir / "cache"),
                                                       "LOD_MPI_FAIL_AFTER=3 LOD_MPI_FAIL_RANK=0");
  EXPECT_NE(killed.code, 0) << killed.out;
  EXPECT_NE(killed.out.find("subtree"), std::string::npos) << killed.out;
  EXPECT_EQ(test::cache_entries(dir / "cache", ".hlod").size(), 4u) << "the four whole models are finished before the split one";
  const size_t subtrees = test::cache_entries(dir / "cache", ".hsub").size();
  EXPECT_GE(subtrees, 2u);

  const test::CliResult rerun = run_mpi(2, bake_args(dir / "out", dir / "cache") + " --json");
  ASSERT_EQ(rerun.code, 0) << rerun.out;
  const nlohmann::json j = test::printed_json(rerun);
  ASSERT_TRUE(j.is_object()) << rerun.out;
  EXPECT_EQ(j["cached"], 4);
  EXPECT_EQ(j["split"], 1) << "the one model missing is baked by both ranks";
  expect_local_bytes(dir / "out", "after the rerun");
}

TEST(LodBakeMpiModels, CorruptedAndTruncatedModelEntriesAreRebaked) {
  const auto dir = test::temp_dir("lod_bake_mpi_models_corrupt");
  ASSERT_EQ(run_mpi(2, bake_args(dir / "out", dir / "cache") + " --quiet").code, 0);
  const std::vector<std::filesystem::path> files = test::cache_entries(dir / "cache", ".hlod");
  ASSERT_EQ(files.size(), 5u);
  test::corrupt_entry(files[0]);
  test::truncate_entry(files[1]);
  std::filesystem::remove_all(dir / "out");

  const test::CliResult r = run_mpi(2, bake_args(dir / "out", dir / "cache") + " --json");
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json j = test::printed_json(r);
  ASSERT_TRUE(j.is_object()) << r.out;
  EXPECT_EQ(j["cached"], 3);
  EXPECT_EQ(baked(j), 2u);
  EXPECT_NE(r.out.find(files[0].filename().string()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(files[1].filename().string()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("baking it again"), std::string::npos) << r.out;
  expect_local_bytes(dir / "out", "after the rebake");
}

// The rock's output taken by a non-empty folder: its rank cannot write it; the others finish.
TEST(LodBakeMpiModels, FailingRankNamesTheModelAndTheJobFailsKeepingTheCache) {
  const auto dir = test::temp_dir("lod_bake_mpi_models_fail");
  std::filesystem::create_directories(dir / "out" / "rock.hlod" / "in-the-way");
  const test::CliResult r = run_mpi(2, bake_args(dir / "out", dir / "cache"));
  EXPECT_NE(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("model rock ("), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("run again"), std::string::npos) << r.out;
  EXPECT_EQ(test::cache_entries(dir / "cache", ".hlod").size(), 5u) << "the rock's entry was stored before its copy failed";
  for (const char* name : {"pebble", "stone", "crag", "boulder"})
    EXPECT_TRUE(std::filesystem::is_regular_file(dir / "out" / (std::string(name) + ".hlod"))) << name;

  std::filesystem::remove_all(dir / "out" / "rock.hlod");
  const test::CliResult rerun = run_mpi(2, bake_args(dir / "out", dir / "cache") + " --json");
  ASSERT_EQ(rerun.code, 0) << rerun.out;
  EXPECT_EQ(test::printed_json(rerun)["cached"], 5);
  expect_local_bytes(dir / "out", "after the rerun");
}

TEST(LodBakeMpiModels, TwoModelsWithOneNameAreRefused) {
  const auto dir = test::temp_dir("lod_bake_mpi_models_names");
  std::filesystem::create_directories(dir / "a");
  std::filesystem::create_directories(dir / "b");
  test::write_text(dir / "a" / "ball.off", test::sphere_off(8, 10));
  test::write_text(dir / "b" / "ball.off", test::sphere_off(9, 10));
  const test::CliResult r = run_mpi(2, (dir / "a" / "ball.off").string() + " " + (dir / "b" / "ball.off").string() +
                                          " -o " + (dir / "out").string() + " --cache " + (dir / "cache").string());
  EXPECT_NE(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("two models named 'ball'"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "ball.hlod"));
}

#else
TEST(LodBakeMpiModels, NeedsMpi) { GTEST_SKIP() << "built without MPI (lod-bake-mpi absent): run scripts/install-deps.sh"; }
#endif

}  // namespace
}  // namespace lod
