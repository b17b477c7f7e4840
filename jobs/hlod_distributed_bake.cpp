// The distributed HLOD bake, one rank's side: load -> plan -> (rank 0) lookup -> broadcast ->
// bake this rank's share into the cache -> gather -> (rank 0) read the rest, assemble, write.
#include "jobs/hlod_distributed_bake.h"

#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <numeric>
#include <thread>
#include <ctime>

#include "jobs/hlod_subtree_cache.h"
#include "preprocess/mesh_clean.h"
#include "preprocess/mesh_io.h"
#include "runtime/byte_order.h"
#include "runtime/file_write.h"
#include "runtime/hlod_asset.h"

namespace lod {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// What a rank tells rank 0 at the end: its status and its work.
struct RankReport {
  Status status;
  HlodRankWork work;
};

std::vector<uint8_t> encode_report(const RankReport& r) {
  detail::ByteWriter w;
  w.u8(r.status.ok ? 1 : 0);
  w.u32(r.work.subtrees);
  w.u64(r.work.triangles);
  w.u64(std::bit_cast<uint64_t>(r.work.bake_seconds));
  w.u64(std::bit_cast<uint64_t>(r.work.bake_cpu_seconds));
  w.u64(std::bit_cast<uint64_t>(r.work.total_seconds));
  w.u64(std::bit_cast<uint64_t>(r.work.cpu_seconds));
  w.u64(r.work.bytes_written);
  w.u32(uint32_t(r.status.message.size()));
  w.raw(r.status.message.data(), r.status.message.size());
  return std::move(w.bytes);
}

RankReport decode_report(const std::vector<uint8_t>& b, int rank) {
  RankReport r;
  constexpr size_t fixed = 1 + 4 + 8 + 8 + 8 + 8 + 8 + 8 + 4;
  if (b.size() < fixed || b.size() != fixed + detail::load_u32(b.data() + fixed - 4)) {
    r.status = Status::error("rank " + std::to_string(rank) + " sent a malformed report");
    return r;
  }
  r.work.subtrees = detail::load_u32(b.data() + 1);
  r.work.triangles = detail::load_u64(b.data() + 5);
  r.work.bake_seconds = std::bit_cast<double>(detail::load_u64(b.data() + 13));
  r.work.bake_cpu_seconds = std::bit_cast<double>(detail::load_u64(b.data() + 21));
  r.work.total_seconds = std::bit_cast<double>(detail::load_u64(b.data() + 29));
  r.work.cpu_seconds = std::bit_cast<double>(detail::load_u64(b.data() + 37));
  r.work.bytes_written = detail::load_u64(b.data() + 45);
  r.status = b[0] ? Status::success() : Status::error(std::string(b.begin() + fixed, b.end()));
  return r;
}

// Rank 0's view of the job while the ranks bake: entries appearing in the cache (every rank
// writes there, so nothing needs sending), as "subtrees done / total, triangles per second".
class ProgressWatch {
 public:
  ProgressWatch(std::vector<std::filesystem::path> paths, std::vector<uint64_t> triangles, size_t total, size_t cached,
                const HlodBakeLog& log)
      : paths_(std::move(paths)), triangles_(std::move(triangles)), total_(total), cached_(cached), log_(log) {
    if (log_) thread_ = std::thread([this] { watch(); });
  }
  ~ProgressWatch() { stop(); }
  void stop() {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
  }

 private:
  void watch() {
    const auto t0 = Clock::now();
    std::vector<uint8_t> seen(paths_.size(), 0);
    size_t done = 0, reported = SIZE_MAX;
    uint64_t tris = 0;
    std::unique_lock lock(mutex_);
    for (bool last = false; !last;) {
      last = stopping_;
      lock.unlock();
      for (size_t i = 0; i < paths_.size(); ++i) {
        std::error_code ec;
        if (!seen[i] && std::filesystem::is_regular_file(paths_[i], ec)) seen[i] = 1, ++done, tris += triangles_[i];
      }
      if (done != reported) {
        reported = done;
        char line[160];
        std::snprintf(line, sizeof line, "subtrees %zu/%zu (%zu cached), %.2f M triangles/s", cached_ + done, total_,
                      cached_, 1e-6 * double(tris) / std::max(1e-3, seconds_since(t0)));
        log_(line);
      }
      lock.lock();
      if (!last) wake_.wait_for(lock, std::chrono::milliseconds(250), [this] { return stopping_; });
    }
  }

  std::vector<std::filesystem::path> paths_;
  std::vector<uint64_t> triangles_;
  size_t total_, cached_;
  HlodBakeLog log_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::thread thread_;
};

struct Job {
  const HlodDistributedSettings& settings;
  const HlodRankComm& comm;
  const HlodBakeLog& log;
  HlodDistributedResult r;
  MeshData mesh;
  HlodBuildOptions options;
  std::unique_ptr<HlodBuilder> builder;
  std::vector<uint64_t> keys;
  std::vector<HlodSubtree> baked;      // rank 0: every result it holds
  std::vector<uint8_t> have;           // rank 0: per subtree, baked[i] holds it
  std::vector<uint8_t> missing;        // per subtree: not in the cache when the job began
  std::unique_ptr<tbb::task_arena> arena;

  void say(const std::string& line) const {
    if (log) log(line);
  }
  uint64_t vertices() const { return mesh.vertex_count(); }
  const std::vector<HlodSubtreeSpec>& specs() const { return builder->subtrees(); }
};

Status load_and_plan(Job& j, const std::filesystem::path& mesh_file) {
  auto t0 = Clock::now();
  if (Status s = load_mesh(mesh_file, j.mesh); !s) return s;
  j.r.input_triangles = j.mesh.triangle_count();
  clean_mesh(j.mesh);
  uint64_t source_hash = 0;
  if (Status s = hlod_source_hash(mesh_file, j.settings.min_verts, source_hash); !s) return s;
  j.r.load_seconds = seconds_since(t0);
  t0 = Clock::now();
  j.options.min_verts = j.settings.min_verts;
  j.options.subtrees = j.settings.subtrees ? j.settings.subtrees : 16 * uint32_t(std::max(1, j.comm.size));
  j.options.parallel_for = tbb_parallel_for();
  j.builder = std::make_unique<HlodBuilder>(j.mesh, j.options);
  Status planned;
  j.arena->execute([&] { planned = j.builder->plan(); });
  if (!planned) return planned;
  for (const HlodSubtreeSpec& spec : j.specs()) j.keys.push_back(hlod_subtree_key(source_hash, j.options, spec));
  j.r.subtrees = j.keys.size();
  j.r.plan_seconds = seconds_since(t0);
  return Status::success();
}

// Rank 0: every entry read and checked now; what is missing or refused is baked this run.
void look_up(Job& j) {
  const auto t0 = Clock::now();
  const size_t n = j.keys.size();
  j.baked.resize(n);
  j.have.assign(n, 0);
  j.missing.assign(n, 1);
  std::vector<std::string> why(n);
  std::vector<uint64_t> bytes(n, 0);
  std::vector<CacheLookup> found(n);
  j.arena->execute([&] {
    tbb::parallel_for(size_t(0), n, [&](size_t i) {
      found[i] = load_hlod_subtree(j.settings.cache_dir, j.keys[i], j.vertices(), j.baked[i], &why[i], &bytes[i]);
    });
  });
  for (size_t i = 0; i < n; ++i) {
    if (found[i] == CacheLookup::refused) {  // gone, so that progress counts only its replacement
      j.say("subtree " + std::to_string(i) + ": " + why[i] + ": baking it again");
      std::error_code ec;
      std::filesystem::remove(hlod_subtree_entry_path(j.settings.cache_dir, j.keys[i]), ec);
    }
    if (found[i] != CacheLookup::found) continue;
    j.have[i] = 1, j.missing[i] = 0, ++j.r.cached;
    j.r.entry_bytes_read += bytes[i];
  }
  j.r.lookup_seconds = seconds_since(t0);
}

std::unique_ptr<ProgressWatch> watch_progress(const Job& j) {
  std::vector<std::filesystem::path> paths;
  std::vector<uint64_t> tris;
  for (size_t i = 0; i < j.keys.size(); ++i)
    if (j.missing[i])
      paths.push_back(hlod_subtree_entry_path(j.settings.cache_dir, j.keys[i])), tris.push_back(j.specs()[i].triangles);
  return std::make_unique<ProgressWatch>(std::move(paths), std::move(tris), j.keys.size(), j.r.cached, j.log);
}

std::vector<size_t> my_share(const Job& j) {
  std::vector<size_t> todo;
  std::vector<uint64_t> costs;
  for (size_t i = 0; i < j.missing.size(); ++i)
    if (j.missing[i]) todo.push_back(i), costs.push_back(j.specs()[i].triangles);
  const std::vector<int> owner = assign_subtrees(costs, std::max(1, j.comm.size));
  std::vector<size_t> mine;
  for (size_t k = 0; k < todo.size(); ++k)
    if (owner[k] == j.comm.rank) mine.push_back(todo[k]);
  return mine;
}

// This rank's share, each result stored as soon as it is finished (rank 0 keeps its own too).
RankReport bake_share(Job& j, const std::vector<size_t>& mine) {
  RankReport rep;
  std::mutex mutex;
  std::atomic<size_t> stored{0};
  const auto t0 = Clock::now();
  const double cpu0 = process_cpu_seconds();
  auto done = [&](size_t i, HlodSubtree&& s) -> Status {
    if (j.settings.before_store) j.settings.before_store(i, stored.load());
    uint64_t bytes = 0;
    if (Status st = store_hlod_subtree(j.settings.cache_dir, j.keys[i], j.vertices(), s, &bytes); !st) return st;
    stored.fetch_add(1);
    std::lock_guard lock(mutex);
    ++rep.work.subtrees;
    rep.work.triangles += j.specs()[i].triangles;
    rep.work.bytes_written += bytes;
    if (j.comm.rank == 0) j.baked[i] = std::move(s), j.have[i] = 1;
    return Status::success();
  };
  j.arena->execute([&] {
    try {
      rep.status = j.builder->bake_subtrees(mine, done);
    } catch (const std::exception& e) {
      rep.status = Status::error(std::string("rank ") + std::to_string(j.comm.rank) + ": " + e.what());
    }
  });
  rep.work.bake_seconds = seconds_since(t0);
  rep.work.bake_cpu_seconds = process_cpu_seconds() - cpu0;
  if (!rep.status) rep.status.message = "rank " + std::to_string(j.comm.rank) + ": " + rep.status.message;
  return rep;
}

// Rank 0: the other ranks' entries; one that is refused now is baked here.
Status collect(Job& j) {
  std::vector<size_t> refused;
  for (size_t i = 0; i < j.keys.size(); ++i) {
    if (j.have[i]) continue;
    std::string why;
    uint64_t bytes = 0;
    if (load_hlod_subtree(j.settings.cache_dir, j.keys[i], j.vertices(), j.baked[i], &why, &bytes) == CacheLookup::found) {
      j.have[i] = 1;
      j.r.entry_bytes_read += bytes;
      continue;
    }
    j.say("subtree " + std::to_string(i) + ": " + (why.empty() ? "entry missing" : why) + ": baking it again on rank 0");
    refused.push_back(i);
  }
  if (refused.empty()) return Status::success();
  j.r.rebaked = refused.size();
  Status st;
  j.arena->execute([&] {
    st = j.builder->bake_subtrees(refused, [&](size_t i, HlodSubtree&& s) {
      if (Status stored = store_hlod_subtree(j.settings.cache_dir, j.keys[i], j.vertices(), s); !stored) return stored;
      j.baked[i] = std::move(s);
      return Status::success();
    });
  });
  return st;
}

Status assemble_and_write(Job& j, const std::filesystem::path& mesh_file, const std::string& name,
                          const std::filesystem::path& out_dir) {
  auto t0 = Clock::now();
  HlodModel model;
  Status st;
  j.arena->execute([&] { st = j.builder->assemble(j.baked, model, &j.r.report); });
  if (!st) return st;
  model.tree.name = name;
  if (Status s = hlod_source_hash(mesh_file, j.settings.min_verts, model.tree.source_hash); !s) return s;
  j.r.assemble_seconds = seconds_since(t0);
  t0 = Clock::now();
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) return Status::error(out_dir.string() + ": cannot create the output directory: " + ec.message());
  j.r.file = out_dir / (name + ".hlod");
  const std::vector<uint8_t> bytes = encode_hlod_asset(model.tree, model.payloads);
  if (Status s = write_file_atomic(j.r.file, bytes); !s) return s;
  j.r.bytes = bytes.size();
  j.r.write_seconds = seconds_since(t0);
  return Status::success();
}

}  // namespace

HlodRankComm single_rank_comm() {
  HlodRankComm c;
  c.broadcast = [](std::vector<uint8_t>&) {};
  c.gather = [](const std::vector<uint8_t>& mine) { return std::vector<std::vector<uint8_t>>{mine}; };
  return c;
}

std::vector<int> assign_subtrees(const std::vector<uint64_t>& costs, int ranks) {
  std::vector<size_t> order(costs.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return costs[a] > costs[b]; });
  std::vector<uint64_t> load(size_t(std::max(1, ranks)), 0);
  std::vector<int> owner(costs.size(), 0);
  for (size_t i : order) {
    const size_t r = size_t(std::min_element(load.begin(), load.end()) - load.begin());
    owner[i] = int(r);
    load[r] += costs[i];
  }
  return owner;
}

Status bake_hlod_distributed(const std::filesystem::path& mesh_file, const std::string& name,
                             const std::filesystem::path& out_dir, const HlodDistributedSettings& settings,
                             const HlodRankComm& comm, const HlodBakeLog& log, HlodDistributedResult* result) {
  const auto t_start = Clock::now();
  const double cpu_start = process_cpu_seconds();
  Job j{settings, comm, log, {}, {}, {}, {}, {}, {}, {}, {}, {}};
  j.arena = std::make_unique<tbb::task_arena>(settings.threads == 0 ? tbb::task_arena::automatic : int(settings.threads));
  std::error_code ec;
  std::filesystem::create_directories(settings.cache_dir, ec);
  // A rank that cannot load or plan still takes part in the collectives (others wait there).
  Status ready = ec ? Status::error(settings.cache_dir.string() + ": cannot create the cache directory: " + ec.message())
                    : load_and_plan(j, mesh_file);
  if (!ready) ready.message = "rank " + std::to_string(comm.rank) + ": " + ready.message;
  if (comm.rank == 0 && ready) look_up(j);
  std::vector<uint8_t> mask = j.missing;
  mask.push_back(ready ? 1 : 0);  // rank 0 could not plan: nobody bakes
  comm.broadcast(mask);
  const bool go = !mask.empty() && mask.back() == 1 && ready && mask.size() == j.keys.size() + 1;
  RankReport rep;
  rep.status = ready;
  std::unique_ptr<ProgressWatch> watch;  // rank 0, until every rank has reported
  if (go) {
    mask.pop_back();
    j.missing = mask;
    if (comm.rank == 0) watch = watch_progress(j);
    rep = bake_share(j, my_share(j));
    j.r.bake_seconds = rep.work.bake_seconds;  // a failure: the caller prints it, rank 0 gathers it
  } else if (ready) {
    rep.status = Status::error("rank " + std::to_string(comm.rank) + ": rank 0 could not plan the build");
  }
  rep.work.total_seconds = seconds_since(t_start);
  rep.work.cpu_seconds = process_cpu_seconds() - cpu_start;
  const std::vector<std::vector<uint8_t>> reports = comm.gather(encode_report(rep));
  watch.reset();
  if (result) *result = {};
  if (comm.rank != 0) {
    j.r.total_seconds = seconds_since(t_start);
    if (result) *result = std::move(j.r);
    return rep.status;
  }
  Status failed;
  for (size_t r = 0; r < reports.size(); ++r) {
    const RankReport other = decode_report(reports[r], int(r));
    j.r.ranks.push_back(other.work);
    if (!other.status && failed) failed = other.status;
    if (!other.status && r != 0) j.say(other.status.message);
  }
  if (!failed) failed.message += " (the cache keeps every finished subtree: run again to resume)";
  Status st = failed;
  const double cpu_gathered = process_cpu_seconds();
  if (st) st = collect(j);
  if (st) st = assemble_and_write(j, mesh_file, name, out_dir);
  j.r.cpu_after_gather_seconds = process_cpu_seconds() - cpu_gathered;
  j.r.total_seconds = seconds_since(t_start);
  if (result) *result = std::move(j.r);
  return st;
}

}  // namespace lod
