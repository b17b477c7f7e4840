// A scene of many models baked over ranks, one call per rank: every model's
// DIR/<stem>.hlod, byte-identical to `lod bake --hlod` of its file.
//
//   rank 0       estimate every model's triangles from its file's header -> broadcast
//   every rank   check its share of the model entries (CACHE/<key>.hlod, checked in full) and
//                copy those found to DIR -> gather -> rank 0 broadcasts what is missing
//   every rank   the same plan from the estimates (plan_hlod_models): the missing models are
//                handed out whole, longest first to the least loaded rank, and each is baked by
//                the local bake (bake_hlod_file, on the rank's --threads cores) into a folder of
//                its own in the cache, checked, renamed into the cache, copied to DIR
//   all ranks    then each model too big for one rank, one after another, with
//                bake_hlod_distributed (subtrees over the ranks, cached as subtrees); rank 0
//                takes its file into the cache and copies it to DIR
//   gather       per rank: its status (a failure names the model), its work and its models
//
// The communication is HlodRankComm's two collectives (lodkit's libraries never link MPI).
#pragma once
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "jobs/hlod_bake.h"
#include "jobs/hlod_distributed_bake.h"

namespace lod {

// A cheap estimate of a mesh file's triangles, for the plan only: the face count in a PLY or
// OFF header, a binary STL's count; otherwise (OBJ, ASCII STL, glTF) from the file's size.
// 0 when the file cannot be read (its bake then fails and says why).
uint64_t estimate_mesh_triangles(const std::filesystem::path& mesh_file);

// Every model's .hlod name (its file's stem) once; otherwise the first two sharing one, as
// `lod bake --hlod` refuses them.
Status hlod_model_names_unique(const std::vector<std::filesystem::path>& meshes);

inline constexpr int kHlodModelSplit = -1;     // baked by all ranks together
inline constexpr int kHlodModelNotBaked = -2;  // not missing

// Per model: the rank that bakes it whole, kHlodModelSplit, or kHlodModelNotBaked (missing[i]
// == 0). A missing model whose cost is above 1/ranks of all missing models' cost (or the only
// one missing) is split; the rest go whole, longest first to the least loaded rank
// (assign_subtrees), so the slowest rank carries at most the mean plus one model.
std::vector<int> plan_hlod_models(const std::vector<uint64_t>& costs, const std::vector<uint8_t>& missing, int ranks);

struct HlodModelsSettings {
  uint32_t min_verts = 1000;
  uint32_t threads = 0;   // per rank; 0 = all its cores
  uint32_t subtrees = 0;  // for split models: HlodDistributedSettings::subtrees
  std::filesystem::path cache_dir;
  uint64_t held_entry_bytes = 0;  // for split models: HlodDistributedSettings::held_entry_bytes
  // Called before each of this rank's cache entries (a model, or a split model's subtree) is
  // stored; `stored`: entries this rank stored so far in the job. Tests inject a crash here.
  std::function<void(const std::string& what, size_t stored)> before_store;
};

enum class HlodModelRoute : uint8_t { cached, whole, split, failed };

struct HlodModelFigures {
  std::string name;
  std::filesystem::path mesh;
  HlodModelRoute route = HlodModelRoute::failed;
  int32_t rank = -1;                 // who baked or checked it (-1: split, all ranks)
  uint64_t estimated_triangles = 0;  // the plan's estimate
  uint64_t source_triangles = 0;     // from the .hlod's head
  uint64_t nodes = 0, bytes = 0;
  double seconds = 0;      // whole: its bake on its rank; split: the distributed bake's
  double cpu_seconds = 0;  // whole: its rank's CPU in the bake; split: the job's critical CPU
  std::string error;       // failed: why (naming the rank, the model and the file)
};

struct HlodModelsRankWork {
  uint32_t baked = 0, checked = 0, failed = 0;  // models baked whole, cached ones checked, failed
  uint64_t triangles = 0;                        // source triangles of the models it baked whole
  uint64_t estimated = 0;                        // their estimate (what the plan balanced)
  double check_cpu_seconds = 0;                  // checking entries, copying them to DIR
  double bake_seconds = 0, bake_cpu_seconds = 0;  // its whole models (bake, store, copy)
  double split_cpu_seconds = 0;  // rank 0 fills it: this rank's phases in the split models' bakes
  double cpu_seconds = 0, total_seconds = 0;  // the rank's process up to its report
  uint64_t bytes_stored = 0;  // model entries it stored
};

struct HlodModelsResult {
  std::vector<HlodModelFigures> models;   // rank 0: every model, in the order given
  std::vector<HlodModelsRankWork> ranks;  // rank 0: every rank's work
  size_t cached = 0, whole = 0, split = 0, failed = 0;
  uint64_t source_triangles = 0;  // of the models written
  // Rank 0: the job on idle cores, one thread per rank: the slowest rank's check and whole
  // models, plus every split model's critical CPU.
  double critical_cpu_seconds = 0;
  // Rank 0: the slowest rank's bake CPU (whole + split) / the mean; and over whole models only.
  double balance_cpu = 1, balance_whole_cpu = 1;
  double total_seconds = 0;  // this rank's whole run
};

// Rank 0's log gets progress lines ("models 5/12 (3 cached), 1.20 M triangles/s"; a split
// model's "model NAME: subtrees ...") and one line per failure or refused entry; the other
// ranks log their own. Two meshes with one stem (one .hlod name) are refused before anything.
Status bake_hlod_models_distributed(const std::vector<std::filesystem::path>& meshes,
                                    const std::filesystem::path& out_dir, const HlodModelsSettings& settings,
                                    const HlodRankComm& comm, const HlodBakeLog& log, HlodModelsResult* result);

}  // namespace lod
