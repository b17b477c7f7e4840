// lod-bake-mpi: the HLOD bake of one mesh, or of a scene of many, spread over MPI ranks.
//
//   mpirun -np 4 lod-bake-mpi MESH... -o DIR --cache DIR [--min-verts N] [--threads N] [--subtrees N]
//                             [--entry-memory-mb N]
//
// One mesh: every rank reads MESH itself (a path all ranks see) and bakes its share of the
// subtrees into the cache folder (shared storage); rank 0 prints progress, assembles and writes
// DIR/<name>.hlod, byte-identical to `lod bake MESH -o DIR --hlod`. Several meshes: the models
// are handed out whole to the ranks (each baked by the local bake), a model too big for one
// rank's share by all ranks as above; each DIR/<name>.hlod is the local bake's bytes and goes
// through the cache (jobs/hlod_models_distributed.h). A rerun bakes only what the cache lacks.
//
// Fault injection, compiled only into the test build's lod-bake-mpi-faults (LOD_FAULT_INJECTION):
// LOD_MPI_FAIL_AFTER=N makes rank LOD_MPI_FAIL_RANK (default: the
// last; -1: every rank) die without a word to MPI once it has stored N cache entries (subtrees,
// and with several meshes models too), as a killed process would.
#include <mpi.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <memory>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "cli/freed_memory.h"
#include "cli/huge_page_malloc.h"
#include "jobs/hlod_distributed_bake.h"
#include "jobs/hlod_models_distributed.h"

namespace {

using namespace lod;

// A node's ranks (MPI_COMM_TYPE_SHARED) and the shared windows made on it, freed (a collective
// of the node) by node_release, or when the last copy of the comm goes, before MPI_Finalize.
struct NodeMemory {
  MPI_Comm node = MPI_COMM_NULL;
  std::vector<MPI_Win> windows;
  ~NodeMemory() {
    for (MPI_Win& w : windows) MPI_Win_free(&w);
    if (node != MPI_COMM_NULL) MPI_Comm_free(&node);
  }
};

// Waits in a nonblocking barrier, sleeping between tests: the waiting rank's core goes to
// the rank loading for the node, and its CPU time is not a spin.
void sleeping_barrier(MPI_Comm comm) {
  std::atomic_thread_fence(std::memory_order_seq_cst);
  MPI_Request req;
  MPI_Ibarrier(comm, &req);
  for (int done = 0;;) {
    MPI_Test(&req, &done, MPI_STATUS_IGNORE);
    if (done) break;
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  std::atomic_thread_fence(std::memory_order_seq_cst);
}

void add_node_memory(HlodRankComm& c) {
  auto m = std::make_shared<NodeMemory>();
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, c.rank, MPI_INFO_NULL, &m->node);
  int node_rank = 0;
  MPI_Comm_rank(m->node, &node_rank);
  MPI_Comm_size(m->node, &c.node_size);
  MPI_Comm_set_errhandler(m->node, MPI_ERRORS_RETURN);
  c.node_first = node_rank == 0;
  int first = c.rank;  // the node's first rank, as every rank of the job knows it
  MPI_Bcast(&first, 1, MPI_INT, 0, m->node);
  c.node_of.assign(size_t(c.size), 0);
  MPI_Allgather(&first, 1, MPI_INT, c.node_of.data(), 1, MPI_INT, MPI_COMM_WORLD);
  c.node_barrier = [m] { sleeping_barrier(m->node); };
  c.node_buffer = [m](uint64_t bytes) -> std::span<uint8_t> {
    MPI_Win win;
    void* mine = nullptr;
    // /dev/shm full, say: an error the job reports, not an abort (errors return on `node`).
    if (MPI_Win_allocate_shared(MPI_Aint(bytes), 1, MPI_INFO_NULL, m->node, &mine, &win) != MPI_SUCCESS) return {};
    m->windows.push_back(win);
    MPI_Aint size = 0;
    int unit = 0;
    void* base = nullptr;
    MPI_Win_shared_query(win, 0, &size, &unit, &base);
    if (size <= 0 || base == nullptr) return {};
    return {static_cast<uint8_t*>(base), size_t(size)};
  };
  c.node_release = [m] {
    sleeping_barrier(m->node);  // MPI_Win_free would spin there
    for (MPI_Win& w : m->windows) MPI_Win_free(&w);
    m->windows.clear();
  };
}

HlodRankComm mpi_comm() {
  HlodRankComm c;
  MPI_Comm_rank(MPI_COMM_WORLD, &c.rank);
  MPI_Comm_size(MPI_COMM_WORLD, &c.size);
  c.broadcast = [](std::vector<uint8_t>& bytes) {
    unsigned long long n = bytes.size();
    MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD);
    bytes.resize(size_t(n));
    MPI_Bcast(bytes.data(), int(n), MPI_BYTE, 0, MPI_COMM_WORLD);
  };
  const int rank = c.rank, size = c.size;
  c.gather = [rank, size](const std::vector<uint8_t>& mine) {
    int n = int(mine.size());
    std::vector<int> counts(size_t(size), 0), offsets(size_t(size), 0);
    MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
    int total = 0;
    for (int r = 0; r < size; ++r) offsets[size_t(r)] = total, total += counts[size_t(r)];
    std::vector<uint8_t> all(size_t(rank == 0 ? total : 0));
    MPI_Gatherv(mine.data(), n, MPI_BYTE, all.data(), counts.data(), offsets.data(), MPI_BYTE, 0, MPI_COMM_WORLD);
    std::vector<std::vector<uint8_t>> out;
    if (rank != 0) return out;
    for (int r = 0; r < size; ++r)
      out.emplace_back(all.begin() + offsets[size_t(r)], all.begin() + offsets[size_t(r)] + counts[size_t(r)]);
    return out;
  };
  add_node_memory(c);
  return c;
}

#ifdef LOD_FAULT_INJECTION
long env_number(const char* name, long fallback) {
  const char* v = std::getenv(name);
  return v && *v ? std::strtol(v, nullptr, 10) : fallback;
}
#endif

nlohmann::json to_json(const HlodDistributedResult& r, int ranks) {
  nlohmann::json per_rank = nlohmann::json::array();
  double slowest = 0, sum = 0;
  for (const HlodRankWork& w : r.ranks) {
    per_rank.push_back({{"subtrees", w.subtrees}, {"triangles", w.triangles}, {"checked", w.checked},
                        {"bytes_checked", w.bytes_checked}, {"bake_s", w.bake_seconds},
                        {"bake_cpu_s", w.bake_cpu_seconds}, {"until_report_s", w.total_seconds},
                        {"cpu_until_report_s", w.cpu_seconds},
                        // Each phase's CPU seconds on this rank (bvh is part of bake).
                        {"cpu_s", {{"load", w.load_cpu_seconds}, {"clean", w.clean_cpu_seconds},
                                   {"plan", w.plan_cpu_seconds}, {"check", w.check_cpu_seconds},
                                   {"bvh", w.surface_cpu_seconds}, {"bake", w.bake_cpu_seconds},
                                   {"measure_top", w.measure_cpu_seconds}, {"write", w.write_cpu_seconds}}},
                        {"bytes_written", w.bytes_written}, {"bytes_placed", w.bytes_placed},
                        {"bytes_read_back", w.bytes_read_back},
                        {"part_triangles", w.part_triangles}, {"whole_bvh", w.whole_surface != 0},
                        {"mesh_loaded", w.mesh_loaded != 0},
                        // The process's whole run: CPU time in the kernel, peak resident memory.
                        {"kernel_cpu_s", w.kernel_cpu_seconds}, {"peak_rss_mb", double(w.peak_rss_bytes) / 1e6}});
    slowest = std::max(slowest, w.bake_cpu_seconds), sum += w.bake_cpu_seconds;
  }
  return {{"file", r.file.string()}, {"bytes", r.bytes}, {"ranks", ranks}, {"input_triangles", r.input_triangles},
          {"mesh_cached", r.mesh_cached}, {"mesh_shared", r.mesh_shared},
          {"subtrees", r.subtrees}, {"cached", r.cached}, {"rebaked", r.rebaked}, {"nodes", r.report.nodes},
          {"entry_bytes_read", r.entry_bytes_read}, {"load_s", r.load_seconds}, {"plan_s", r.plan_seconds},
          {"lookup_s", r.lookup_seconds}, {"bake_s", r.bake_seconds}, {"assemble_s", r.assemble_seconds},
          {"write_s", r.write_seconds}, {"total_s", r.total_seconds},
          {"cpu_after_gather_s", r.cpu_after_gather_seconds},
          // Rank 0's serial CPU seconds between the gather and the layout's broadcast.
          {"rank0_cpu_s", {{"roots", r.collect_cpu_seconds}, {"assemble", r.assemble_cpu_seconds},
                           {"head", r.head_cpu_seconds}, {"top_rest", r.top_rest_cpu_seconds}}},
          // The top's samples no rank answered; whether rank 0 built the whole BVH.
          {"top_samples_left", r.top_samples_left}, {"rank0_whole_bvh", r.top_whole_surface},
          // The job's length on idle cores: the slowest rank's CPU time up to the gather, rank
          // 0's serial part, the slowest rank's write (each rank runs one thread; the machine
          // these figures come from is shared).
          {"critical_cpu_s", r.critical_cpu_seconds},
          {"malloc_huge_pages", cli::malloc_uses_huge_pages()},  // rank 0's (cli/huge_page_malloc.h)
          {"malloc_keeps_freed_memory", cli::malloc_keeps_freed_memory()},  // (cli/freed_memory.h)
          {"balance_cpu", sum > 0 ? slowest / (sum / double(r.ranks.size())) : 1.0}, {"per_rank", per_rank}};
}

const char* route_name(HlodModelRoute r) {
  switch (r) {
    case HlodModelRoute::cached: return "cached";
    case HlodModelRoute::whole: return "whole";
    case HlodModelRoute::split: return "split";
    case HlodModelRoute::failed: break;
  }
  return "failed";
}

nlohmann::json to_json(const HlodModelsResult& r, int ranks) {
  nlohmann::json models = nlohmann::json::array(), per_rank = nlohmann::json::array();
  for (const HlodModelFigures& m : r.models) {
    nlohmann::json one = {{"model", m.name}, {"mesh", m.mesh.string()}, {"route", route_name(m.route)},
                          {"rank", m.rank}, {"estimated_triangles", m.estimated_triangles},
                          {"source_triangles", m.source_triangles}, {"nodes", m.nodes}, {"bytes", m.bytes},
                          // whole: its rank's bake; split: the distributed bake's wall and critical CPU
                          {"bake_s", m.seconds}, {"bake_cpu_s", m.cpu_seconds}};
    if (!m.error.empty()) one["error"] = m.error;
    models.push_back(one);
  }
  for (const HlodModelsRankWork& w : r.ranks)
    per_rank.push_back({{"baked", w.baked}, {"checked", w.checked}, {"failed", w.failed},
                        {"triangles", w.triangles}, {"estimated_triangles", w.estimated},
                        {"check_cpu_s", w.check_cpu_seconds}, {"bake_s", w.bake_seconds},
                        {"bake_cpu_s", w.bake_cpu_seconds}, {"split_cpu_s", w.split_cpu_seconds},
                        {"until_report_s", w.total_seconds}, {"cpu_until_report_s", w.cpu_seconds},
                        {"bytes_stored", w.bytes_stored}});
  return {{"ranks", ranks}, {"models_total", r.models.size()}, {"cached", r.cached}, {"whole", r.whole},
          {"split", r.split}, {"failed", r.failed}, {"source_triangles", r.source_triangles},
          {"total_s", r.total_seconds},
          // The job on idle cores: the slowest rank's check and whole models + every split model's critical CPU.
          {"critical_cpu_s", r.critical_cpu_seconds},
          {"malloc_huge_pages", cli::malloc_uses_huge_pages()},
          {"malloc_keeps_freed_memory", cli::malloc_keeps_freed_memory()},
          // The slowest rank's bake CPU / the mean: whole and split models; whole ones only.
          {"balance_cpu", r.balance_cpu}, {"balance_whole_cpu", r.balance_whole_cpu},
          {"models", models}, {"per_rank", per_rank}};
}

// Several meshes: one .hlod each, the models handed out to the ranks.
int run_models(const std::vector<std::string>& meshes, const std::string& out_dir, HlodModelsSettings settings,
               bool json, bool quiet, const HlodRankComm& comm) {
#ifdef LOD_FAULT_INJECTION
  const long fail_after = env_number("LOD_MPI_FAIL_AFTER", -1);
  const long fail_rank = env_number("LOD_MPI_FAIL_RANK", comm.size - 1);
  if (fail_after >= 0 && (fail_rank == comm.rank || fail_rank < 0))
    settings.before_store = [rank = comm.rank, fail_after](const std::string& what, size_t stored) {
      if (long(stored) < fail_after) return;
      std::fprintf(stderr, "lod-bake-mpi: rank %d: injected failure (LOD_MPI_FAIL_AFTER=%ld) at %s\n", rank, fail_after,
                   what.c_str());
      std::fflush(stderr);
      std::_Exit(3);
    };
#endif
  const bool talk = !quiet && !json;
  auto log = [&](const std::string& line) {
    const bool progress = line.size() > 11 && line.compare(line.size() - 11, 11, "triangles/s") == 0;
    if (talk || !progress) std::fprintf(stderr, "lod-bake-mpi: %s\n", line.c_str());
  };
  std::vector<std::filesystem::path> files(meshes.begin(), meshes.end());
  if (Status names = hlod_model_names_unique(files); !names) {  // every rank refuses, rank 0 says so
    if (comm.rank == 0) std::fprintf(stderr, "lod-bake-mpi: %s\n", names.message.c_str());
    return 1;
  }
  HlodModelsResult r;
  const Status st = bake_hlod_models_distributed(files, out_dir, settings, comm, log, &r);
  if (comm.rank == 0 && json) std::printf("%s\n", to_json(r, comm.size).dump(1).c_str());
  if (!st) {
    std::fprintf(stderr, "lod-bake-mpi: %s\n", st.message.c_str());
    return 1;
  }
  if (comm.rank != 0 || json || quiet) return 0;
  std::printf("%zu models (%zu cached, %zu whole, %zu split over all ranks), %llu triangles on %d ranks in %s; total %.2f s\n",
              r.models.size(), r.cached, r.whole, r.split, (unsigned long long)r.source_triangles, comm.size,
              out_dir.c_str(), r.total_seconds);
  return 0;
}

int run(int argc, char** argv, const HlodRankComm& comm) {
  CLI::App app{"HLOD bake of one mesh or many over MPI ranks (byte-identical to lod bake --hlod)"};
  std::vector<std::string> meshes;
  std::string out_dir, cache_dir;
  int min_verts = 1000, threads = 0, subtrees = 0;
  uint64_t entry_memory_mb = 0;
  bool json = false, quiet = false;
  std::string mesh_copies = "auto";
  app.add_option("mesh", meshes, "mesh files, on paths every rank sees (one .hlod each)")->required();
  app.add_option("-o,--out", out_dir, "output directory (rank 0 writes <name>.hlod there)")->required();
  app.add_option("--cache", cache_dir, "subtree cache directory on shared storage")->required();
  app.add_option("--min-verts", min_verts, "a cell with more vertices splits (default 1000)")->check(CLI::Range(3, 100000000));
  app.add_option("--threads", threads, "threads per rank, 0 = all cores")->check(CLI::Range(0, 1024));
  app.add_option("--subtrees", subtrees, "subtrees to split into (default 8 per rank, at least 16)")->check(CLI::Range(0, 1 << 20));
  app.add_option("--entry-memory-mb", entry_memory_mb,
                 "MB of cache entries a rank holds for its write (default 0: each is read back when written)")
      ->check(CLI::Range(uint64_t{0}, uint64_t{1} << 40));
  app.add_option("--mesh-copies", mesh_copies,
                 "one copy of the mesh per node, in memory its ranks share, or per rank (auto: per node where a "
                 "node runs 8 ranks or more)")
      ->check(CLI::IsMember({"auto", "node", "rank"}));
  app.add_flag("--json", json, "rank 0 prints a JSON summary");
  app.add_flag("--quiet", quiet, "print nothing but errors");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return comm.rank == 0 ? app.exit(e) : (e.get_exit_code() == 0 ? 0 : 1);
  }
  HlodDistributedSettings settings;
  settings.share_mesh_from = mesh_copies == "node" ? 2 : mesh_copies == "rank" ? 0 : settings.share_mesh_from;
  settings.min_verts = uint32_t(min_verts);
  settings.threads = uint32_t(threads);
  settings.subtrees = uint32_t(subtrees);
  settings.cache_dir = cache_dir;
  settings.held_entry_bytes = entry_memory_mb << 20;
  if (meshes.size() > 1) {
    HlodModelsSettings models;
    models.min_verts = settings.min_verts;
    models.threads = settings.threads;
    models.subtrees = settings.subtrees;
    models.cache_dir = settings.cache_dir;
    models.held_entry_bytes = settings.held_entry_bytes;
    return run_models(meshes, out_dir, models, json, quiet, comm);
  }
  const std::string& mesh = meshes.front();
#ifdef LOD_FAULT_INJECTION
  const long fail_after = env_number("LOD_MPI_FAIL_AFTER", -1);
  const long fail_rank = env_number("LOD_MPI_FAIL_RANK", comm.size - 1);
  if (fail_after >= 0 && (fail_rank == comm.rank || fail_rank < 0))  // LOD_MPI_FAIL_RANK=-1: every rank
    settings.before_store = [rank = comm.rank, fail_after](size_t subtree, size_t stored) {
      if (long(stored) < fail_after) return;
      std::fprintf(stderr, "lod-bake-mpi: rank %d: injected failure (LOD_MPI_FAIL_AFTER=%ld) at subtree %zu\n", rank,
                   fail_after, subtree);
      std::fflush(stderr);
      std::_Exit(3);  // no MPI_Finalize: mpirun sees a dead rank and ends the job
    };
#endif
  const bool talk = !quiet && !json;
  auto log = [&](const std::string& line) {
    const bool progress = line.rfind("subtrees ", 0) == 0;  // the rest: refused entries, failures
    if (talk || !progress) std::fprintf(stderr, "lod-bake-mpi: %s\n", line.c_str());
  };
  const std::string name = std::filesystem::path(mesh).stem().string();
  HlodDistributedResult r;
  const Status st = bake_hlod_distributed(mesh, name, out_dir, settings, comm, log, &r);
  if (!st) {
    std::fprintf(stderr, "lod-bake-mpi: %s\n", st.message.c_str());
    return 1;
  }
  if (comm.rank != 0) return 0;
  if (json) std::printf("%s\n", to_json(r, comm.size).dump(1).c_str());
  else if (!quiet)
    std::printf("%s: %zu triangles -> %zu nodes, %zu subtrees (%zu cached) on %d ranks, %.2f MB in %s; total %.2f s\n",
                name.c_str(), r.input_triangles, r.report.nodes, r.subtrees, r.cached, comm.size, double(r.bytes) / 1e6,
                r.file.string().c_str(), r.total_seconds);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  lod::cli::restart_with_huge_page_malloc(argv);  // before MPI_Init: the rank starts again as itself
  lod::cli::keep_freed_memory();
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);  // MPI from the main thread only
  const int code = run(argc, argv, mpi_comm());
  MPI_Finalize();
  return code;
}
