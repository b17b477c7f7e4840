// The HLOD bake spread over ranks, one call per rank (an MPI process, say):
//
//   every rank   sees the probe files rank 0 made in the cache and output folders, or the job
//                stops before any work (check_shared_folders)
//   every rank   load the mesh from the shared path (where the ranks of a node share memory,
//                the node's first loads it once for all: HlodRankComm::node_buffer), plan the
//                split (the same on every rank), check its share of the cache's entries in full
//   gather       which entries were found -> rank 0 broadcasts which are missing
//   every rank   bake its share of the missing ones (spatially contiguous runs balanced by
//                cost), each result stored in the cache as it is finished; queries against
//                the original go to a BVH of the part of it near the subtree being measured
//   gather       per rank: its status (a failure names the subtree), work and bytes
//   rank 0       read the subtrees' roots from the entries (a refused one is baked again here),
//                build the layers of the levels above -> broadcast them
//   every rank   measure those layers' samples in the cells it writes (against the parts of
//                the original near them) and the other side of a share of the layers -> gather ->
//                rank 0 measures any sample no rank answered, against the original near them
//   rank 0       finish the levels above, write the head and their payloads into a temporary
//                file at its full size -> broadcast where every subtree node's payload goes
//   every rank   write the payloads of the subtrees it baked or checked, at those offsets (from
//                the entries' bytes it held, or read back: HlodDistributedSettings::held_entry_bytes)
//   gather       per rank: its write's status -> rank 0 renames the file into place
//
// The communication is two collectives (HlodRankComm), so that lodkit's libraries never link
// MPI: lod-bake-mpi gives MPI_Bcast and MPI_Gatherv (and a node's shared memory); tests may
// give threads or nothing.
#pragma once
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "jobs/hlod_bake.h"
#include "jobs/shared_folder_probe.h"

namespace lod {

struct HlodRankComm {
  int rank = 0;
  int size = 1;
  // Every rank calls it; afterwards every rank's `bytes` are rank 0's.
  std::function<void(std::vector<uint8_t>& bytes)> broadcast;
  // Every rank calls it; rank 0 gets every rank's bytes (by rank), the others nothing.
  std::function<std::vector<std::vector<uint8_t>>(const std::vector<uint8_t>& mine)> gather;
  // Optional (null: every rank loads its own copy of the mesh). The ranks on this one's node,
  // which share memory: how many, and whether this is their first (it loads for all of them).
  int node_size = 1;
  bool node_first = true;
  // Every rank of the node calls it, as often: waits until all have, without spinning (a
  // waiting rank's core is another's).
  std::function<void()> node_barrier;
  // Every rank of the node calls it, as often: the first passes the bytes it needs, the
  // others 0; each gets the first's buffer (for the first to write, then the node to read),
  // kept until node_release.
  std::function<std::span<uint8_t>(uint64_t bytes)> node_buffer;
  // Every rank of the node calls it, as often: frees the buffers node_buffer gave.
  std::function<void()> node_release;
  // Per rank of the job: its node's first rank. The same on every rank; empty without node_buffer.
  std::vector<int32_t> node_of;
};

// One rank, no communication: the distributed bake run in one process.
HlodRankComm single_rank_comm();

// Every rank calls it with its own folders, the same kinds in the same order (three
// collectives): fails on every rank, naming the ranks and folders, unless each rank finds in
// its folders the files rank 0 made in its own (jobs/shared_folder_probe.h).
Status check_shared_folders(const std::vector<SharedFolder>& folders, const HlodRankComm& comm);

// Longest processing time first: subtrees by cost, largest first (ties: lower index), each to
// the rank with the least cost so far (ties: lower rank). The slowest rank then carries at
// most the mean plus one subtree. Returns each subtree's rank.
std::vector<int> assign_subtrees(const std::vector<uint64_t>& costs, int ranks);

// Spatially contiguous runs: subtrees taken in `order` (a permutation of their indices; the
// top's depth-first order keeps neighbours together), each to the rank whose 1/ranks of the
// total cost holds the middle of the subtree's cost. The slowest rank then carries at most the
// mean plus one subtree, and each rank's cells form a few compact regions.
std::vector<int> assign_subtrees_spatially(const std::vector<uint64_t>& costs, const std::vector<size_t>& order,
                                           int ranks);
// The same with unequal shares: rank r's run ends at cuts[r] of the total cost (fractions,
// ascending; ranks - 1 of them).
std::vector<int> assign_subtrees_at_cuts(const std::vector<uint64_t>& costs, const std::vector<size_t>& order,
                                         const std::vector<double>& cuts);

// The ranks' cuts when some load the mesh for their node and others do not (loads[r] = 1 where
// rank r loads a copy; HlodRankComm::node_of, HlodDistributedSettings::share_mesh_from):
// each such rank's share of the bake is smaller by that load's estimated cost, so that every
// rank's CPU time comes out even. Empty when every rank loads (equal shares).
std::vector<double> node_loader_cuts(const std::vector<uint8_t>& loads);

// The frontier's default target: 8 per rank, at least 16 (the local bake's). A split refined
// at the ranks' cuts (HlodBuildOptions::balance_parts) needs no more for an even split.
inline uint32_t default_subtrees(int ranks) { return std::max(16u, 8u * uint32_t(std::max(1, ranks))); }

struct HlodDistributedSettings {
  uint32_t min_verts = 1000;
  uint32_t threads = 0;    // per rank; 0 = all its cores
  uint32_t subtrees = 0;   // the frontier's target (HlodBuildOptions::subtrees); 0 = default_subtrees
  std::filesystem::path cache_dir;
  // The entries' bytes a rank holds in memory between storing (or checking) them and writing
  // their payloads into the .hlod; an entry beyond it is read back from the cache when its
  // payloads are written (its size and hash checked against what the rank had), so a rank's
  // memory stays bounded however large its share. 0 by default: on the 13.9M-triangle bake,
  // holding nothing was also faster (fresh memory costs more than reading back); where the
  // cache is on slow shared storage, holding some saves reading it.
  uint64_t held_entry_bytes = 0;
  // The ranks on one node share one copy of the mesh (HlodRankComm::node_buffer) when the node
  // runs at least this many; 0 = never. Measured on the 13.9M scan (2-core VM): the shared
  // copy's fresh pages cost its loader 0.6-2 s more CPU than its own load (spikes to 8 s) while
  // each other rank saves 0.3-1.7 s: a loss at 2 ranks, even at 4, a clear gain at 8 (and a
  // mesh's memory saved per rank).
  uint32_t share_mesh_from = 8;
  // Called before each of this rank's entries is stored (count: entries this rank stored so
  // far), from the thread that finished it. Tests inject a crash here.
  std::function<void(size_t subtree, size_t stored)> before_store;
};

// One rank's work. CPU times are its process's (the machine may be shared); each phase's own.
struct HlodRankWork {
  uint32_t subtrees = 0;     // baked by the rank in this run
  uint64_t triangles = 0;    // their original triangles
  uint32_t checked = 0;      // cached entries it checked in full (it writes their payloads)
  uint64_t bytes_checked = 0;
  double bake_seconds = 0;   // the rank's time in its bakes
  double bake_cpu_seconds = 0;  // CPU time in them (the original's BVH included)
  double total_seconds = 0;     // the rank's whole run, up to its first report
  double cpu_seconds = 0;       // its process's CPU time over that run
  double load_cpu_seconds = 0, clean_cpu_seconds = 0, plan_cpu_seconds = 0, check_cpu_seconds = 0,
         surface_cpu_seconds = 0;  // the BVH, within bake_cpu_seconds
  double measure_cpu_seconds = 0;  // its share of the top's layers' errors
  double write_cpu_seconds = 0;    // placing its payloads into the .hlod (after rank 0's assembly)
  uint64_t bytes_written = 0;      // cache entries
  uint64_t bytes_placed = 0;       // payload bytes it wrote into the .hlod
  uint64_t bytes_read_back = 0;    // of entries it did not hold (held_entry_bytes), read back to write them
  uint64_t part_triangles = 0;     // in the BVHs of the original's parts it built (near each subtree)
  uint32_t whole_surface = 0;      // 1: it needed the whole original's BVH too
  uint32_t mesh_loaded = 0;        // 1: it loaded the mesh (its own copy, or its node's for all)
  // The process over its whole run so far (getrusage, at its last report): CPU time in the kernel
  // (mostly first touches of fresh memory: on a VM whose host takes free pages back, each is a
  // host fault too) and the peak resident memory.
  double kernel_cpu_seconds = 0;
  uint64_t peak_rss_bytes = 0;
};

struct HlodDistributedResult {
  std::filesystem::path file;  // rank 0: what was written
  uint64_t bytes = 0;
  size_t input_triangles = 0;
  bool mesh_cached = false;    // the cleaned mesh came from the cache (a run before stored it)
  bool mesh_shared = false;    // one copy on rank 0's node, which its first rank loaded for all
  size_t subtrees = 0, cached = 0, rebaked = 0;  // rebaked: refused at assembly, baked again on rank 0
  std::vector<HlodRankWork> ranks;                // rank 0: every rank's work
  uint64_t entry_bytes_read = 0;                  // rank 0: of the entries, to take up their roots
  double cpu_after_gather_seconds = 0;            // rank 0: CPU time reading roots, assembling, writing
  double collect_cpu_seconds = 0, assemble_cpu_seconds = 0, head_cpu_seconds = 0;  // rank 0, after the gather
  // Rank 0: the top's samples no rank answered (measured by rank 0 near them), and
  // whether rank 0 needed the whole original's BVH at all (a refused entry rebaked, or those).
  size_t top_samples_left = 0;
  bool top_whole_surface = false;
  double top_rest_cpu_seconds = 0;  // rank 0: merging the top's answers and measuring those left
  // Rank 0: the job's length on idle cores, one thread per rank: the slowest rank up to the
  // first gather, rank 0's serial part (roots, the top's layers, its finish, the head), the
  // slowest rank's share of the top's errors and of the write.
  double critical_cpu_seconds = 0;
  double load_seconds = 0, plan_seconds = 0, lookup_seconds = 0, bake_seconds = 0, assemble_seconds = 0,
         write_seconds = 0, total_seconds = 0;    // this rank's phases (lookup: its check of the cache)
  HlodBuildReport report;
};

// Rank 0's log gets progress lines ("subtrees 12/64 (3 cached), 1.20 M triangles/s") and one
// line per failure; other ranks log their own failures only.
Status bake_hlod_distributed(const std::filesystem::path& mesh_file, const std::string& name,
                             const std::filesystem::path& out_dir, const HlodDistributedSettings& settings,
                             const HlodRankComm& comm, const HlodBakeLog& log, HlodDistributedResult* result);

}  // namespace lod
