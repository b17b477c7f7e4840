// The distributed HLOD bake, one rank's side: load -> plan -> check a share of the cache ->
// gather / broadcast what is missing -> bake a share into the cache -> gather -> (rank 0) the
// subtrees' roots, the top's layers -> broadcast them -> measure a share -> gather -> (rank 0) the
// top's errors, the head -> broadcast the layout -> write own payloads -> gather -> (rank 0) rename.
#include "jobs/hlod_distributed_bake.h"


#include <oneapi/tbb/task_arena.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <numeric>
#include <thread>
#include <type_traits>
#include <ctime>

#include "jobs/annotated_parallel_for.h"
#include "jobs/cache_progress.h"
#include "jobs/hlod_mesh_cache.h"
#include "jobs/hlod_subtree_cache.h"
#include "preprocess/mesh_clean.h"
#include "preprocess/mesh_io.h"
#include "runtime/byte_order.h"
#include "runtime/file_write.h"
#include "runtime/hlod_asset.h"
#include "runtime/hlod_subtree_entry.h"
#include "runtime/lod_asset.h"  // hash_bytes

namespace lod {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// Kernel CPU time and peak memory of this process so far.
void take_usage(HlodRankWork& w) {
  rusage u{};
  if (getrusage(RUSAGE_SELF, &u) != 0) return;
  w.kernel_cpu_seconds = double(u.ru_stime.tv_sec) + 1e-6 * double(u.ru_stime.tv_usec);
  w.peak_rss_bytes = uint64_t(u.ru_maxrss) * 1024;  // Linux: kilobytes
}

// What a rank tells rank 0 at the end: its status and its work.
struct RankReport {
  Status status;
  HlodRankWork work;
};

// The report's numbers in one order for both sides.
template <class Work, class F>
void each_number(Work& w, F&& f) {
  f(w.subtrees), f(w.triangles), f(w.checked), f(w.bytes_checked), f(w.bake_seconds), f(w.bake_cpu_seconds),
      f(w.total_seconds), f(w.cpu_seconds), f(w.load_cpu_seconds), f(w.clean_cpu_seconds), f(w.plan_cpu_seconds),
      f(w.check_cpu_seconds), f(w.surface_cpu_seconds), f(w.measure_cpu_seconds), f(w.write_cpu_seconds),
      f(w.bytes_written), f(w.bytes_placed), f(w.bytes_read_back), f(w.part_triangles), f(w.whole_surface),
      f(w.mesh_loaded), f(w.kernel_cpu_seconds), f(w.peak_rss_bytes);
}

std::vector<uint8_t> encode_report(const RankReport& r) {
  detail::ByteWriter w;
  w.u8(r.status.ok ? 1 : 0);
  each_number(r.work, [&](const auto& v) {
    if constexpr (std::is_same_v<std::decay_t<decltype(v)>, double>) w.u64(std::bit_cast<uint64_t>(v));
    else w.u64(uint64_t(v));
  });
  w.u32(uint32_t(r.status.message.size()));
  w.raw(r.status.message.data(), r.status.message.size());
  return std::move(w.bytes);
}

RankReport decode_report(const std::vector<uint8_t>& b, int rank) {
  RankReport r;
  size_t numbers = 0;
  each_number(r.work, [&](auto&) { ++numbers; });
  const size_t fixed = 1 + 8 * numbers + 4;
  if (b.size() < fixed || b.size() != fixed + detail::load_u32(b.data() + fixed - 4)) {
    r.status = Status::error("rank " + std::to_string(rank) + " sent a malformed report");
    return r;
  }
  size_t at = 1;
  each_number(r.work, [&](auto& v) {
    const uint64_t word = detail::load_u64(b.data() + at);
    at += 8;
    if constexpr (std::is_same_v<std::decay_t<decltype(v)>, double>) v = std::bit_cast<double>(word);
    else v = static_cast<std::decay_t<decltype(v)>>(word);
  });
  r.status = b[0] ? Status::success() : Status::error(std::string(b.begin() + fixed, b.end()));
  return r;
}

// Measured on the 13.9M-triangle scan, one thread, 2 and 4 ranks on a 2-core VM: the node's load
// (parse, clean, the copy into shared memory: fresh pages cost most of it) cost its first rank
// 0.6-2.2 s more CPU than the others' view of it, against 33 s for the whole bake: 2-7 % of a
// bake's cost per triangle; 3.5 % is their middle.
constexpr double kNodeLoadShare = 0.035;

struct Job {
  Job(const HlodDistributedSettings& s, const HlodRankComm& c, const HlodBakeLog& l) : settings(s), comm(c), log(l) {}
  const HlodDistributedSettings& settings;
  const HlodRankComm& comm;
  const HlodBakeLog& log;
  HlodDistributedResult r;
  HlodRankWork work;                   // this rank's, reported to rank 0
  std::string source_name;
  MeshData mesh;                       // the mesh when this rank loaded its own copy
  MeshView view;                       // what the builder reads: `mesh`, or the node's copy
  std::span<const uint8_t> node_entry;  // the node's copy: the cleaned mesh's cache entry
  HlodMeshInPlace in_place;            // the node's copy's small parts
  HlodBuildOptions options;
  std::unique_ptr<HlodBuilder> builder;
  uint64_t source_hash = 0;
  std::vector<uint64_t> keys;
  std::vector<HlodSubtree> roots;      // rank 0: each subtree's nodes and root payload, once held
  std::vector<uint8_t> have;           // rank 0: per subtree, roots[i] holds it
  std::vector<uint8_t> missing;        // per subtree: not in the cache when the job began
  std::vector<int32_t> writer;         // per subtree: the rank writing its payloads into the .hlod
  std::vector<std::vector<uint8_t>> entries;  // per subtree: its entry's bytes, where this rank writes it and holds them
  std::unique_ptr<tbb::task_arena> arena;
  bool store_mesh = false;  // the mesh was cleaned here, not read from the cache: one rank stores it
  std::atomic<uint64_t> held{0};  // the entries' bytes held, at most settings.held_entry_bytes
  // Per subtree whose entry this rank let go: its size and hash, what reading it back must find.
  std::vector<std::pair<uint64_t, uint64_t>> let_go;

  void say(const std::string& line) const {
    if (log) log(line);
  }
  uint64_t vertices() const { return view.vertex_count(); }
  const std::vector<HlodSubtreeSpec>& specs() const { return builder->subtrees(); }
  int ranks() const { return std::max(1, comm.size); }
};

// What the levels above need of a subtree: its nodes and its root's payload.
HlodSubtree root_only(HlodSubtree&& s) {
  s.payloads.resize(std::min<size_t>(s.payloads.size(), 1));
  s.payloads.shrink_to_fit();
  return std::move(s);
}

// Keeps subtree i's entry bytes (checked: stored and read back from the disk, or decoded in
// full) for the write while the rank's budget allows; otherwise they go, their size and hash
// kept, and the write reads the entry back.
void hold_entry(Job& j, size_t i, std::vector<uint8_t>& entry) {
  const uint64_t size = entry.size();
  if (j.held.fetch_add(size) + size <= j.settings.held_entry_bytes) return;
  j.held.fetch_sub(size);
  j.let_go[i] = {size, hash_bytes(entry.data(), entry.size())};
  std::vector<uint8_t>().swap(entry);
}

// This rank's own copy of the cleaned mesh: from the cache when a run before stored it;
// otherwise loaded, cleaned and (one rank) stored for the reruns. The key is hashed in 1 MB
// pieces (no copy of the file in memory); a load hashes what it parses too, and the two must agree.
Status load_own(Job& j, const std::filesystem::path& mesh_file, const std::function<void(double&)>& lap) {
  if (Status s = hlod_source_hash(mesh_file, j.settings.min_verts, j.source_hash); !s) return s;
  uint64_t input_triangles = 0;
  std::string why;
  const CacheLookup cached =
      load_hlod_mesh(j.settings.cache_dir, j.source_hash, j.source_name, j.mesh, input_triangles, &why,
                     &j.options.surfaces);
  if (cached == CacheLookup::refused) j.say(why + ": loading the mesh again");
  if (cached == CacheLookup::found) {
    // The content is the source's; its folder is where it is now (add_chain_materials' base).
    std::error_code ec;
    if (!j.options.surfaces.materials.empty() && !j.options.surfaces.texture_base.empty())
      j.options.surfaces.texture_base = std::filesystem::absolute(mesh_file, ec).lexically_normal().parent_path().string();
    j.r.input_triangles = size_t(input_triangles);
    j.r.mesh_cached = true;
    lap(j.work.load_cpu_seconds);
  } else {
    uint64_t parsed = 0;
    if (Status s = load_mesh_hashed(mesh_file, j.mesh, parsed); !s) return s;
    if (hlod_source_hash_of(mesh_file, parsed, j.settings.min_verts) != j.source_hash)
      return Status::error(mesh_file.string() + ": changed while this rank read it (hashed, then loaded other bytes)");
    j.r.input_triangles = j.mesh.triangle_count();
    lap(j.work.load_cpu_seconds);
    std::vector<std::string> notes;
    prepare_hlod_input(mesh_file, j.mesh, j.options.surfaces, notes);
    if (j.comm.rank == 0)
      for (const std::string& note : notes) j.say("note: " + note);
    j.store_mesh = true;  // by store_cleaned_mesh, once the shares are known
    lap(j.work.clean_cpu_seconds);
  }
  j.view = j.mesh;
  j.work.mesh_loaded = 1;
  return Status::success();
}

// Ranks of a node share one copy of the cleaned mesh (its cache entry's bytes): the node's
// first rank loads it as load_own does and copies it into the node's memory; the others wait
// without spinning and read it in place. On 14M triangles that is 250 MB of fresh pages, a
// parse and a clean once per node rather than once per rank. Head: u64 source hash, u64 flags
// (bit 0: from the cache); empty: the first rank failed.
constexpr size_t kNodeHead = 16;

// Maps a shared buffer's pages into this process in one call (MADV_POPULATE_*, Linux 5.14)
// rather than one fault per 4 KB page as the first pass over them goes: 64k faults on 14M
// triangles. Where the kernel cannot, the faults happen as before.
void populate(std::span<const uint8_t> bytes, bool write) {
#if defined(MADV_POPULATE_READ) && defined(MADV_POPULATE_WRITE)
  const uintptr_t page = uintptr_t(::sysconf(_SC_PAGESIZE));
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(bytes.data()) + page - 1) / page * page;
  const uintptr_t end = (reinterpret_cast<uintptr_t>(bytes.data()) + bytes.size()) / page * page;
  if (end > begin) ::madvise(reinterpret_cast<void*>(begin), end - begin, write ? MADV_POPULATE_WRITE : MADV_POPULATE_READ);
#else
  (void)bytes, (void)write;
#endif
}

Status load_shared(Job& j, const std::filesystem::path& mesh_file, const std::function<void(double&)>& lap) {
  Status mine = Status::success();
  HlodMeshEntry entry;
  if (j.comm.node_first) {
    mine = load_own(j, mesh_file, lap);
    if (mine) entry = hlod_mesh_entry(j.source_hash, j.mesh, j.r.input_triangles, j.options.surfaces);
  }
  j.comm.node_barrier();
  const uint64_t entry_bytes = entry.size();
  const std::span<uint8_t> node = j.comm.node_buffer(mine && j.comm.node_first ? kNodeHead + entry_bytes : 0);
  if (j.comm.node_first && mine && node.size() == kNodeHead + entry.size()) {
    populate(node, true);
    const uint64_t head[2] = {j.source_hash, j.r.mesh_cached ? 1u : 0u};  // host order: one host reads it
    std::memcpy(node.data(), head, kNodeHead);
    entry.copy_to(node.data() + kNodeHead);
  }
  entry = {};
  j.mesh = {};  // the node's copy serves this rank too
  j.view = {};
  j.comm.node_barrier();
  if (!mine) return mine;
  if (node.size() < kNodeHead && j.comm.node_first)
    return Status::error(mesh_file.string() + ": could not get " + std::to_string((kNodeHead + entry_bytes) >> 20) +
                         " MB of memory this node's ranks share (/dev/shm full?): run with --mesh-copies rank");
  if (node.size() < kNodeHead)
    return Status::error(mesh_file.string() + ": this node's first rank could not load it or share it (its own message says why)");
  uint64_t head[2];
  std::memcpy(head, node.data(), kNodeHead);
  j.source_hash = head[0];
  j.r.mesh_cached = (head[1] & 1) != 0;
  j.store_mesh = !j.r.mesh_cached;
  j.node_entry = node.subspan(kNodeHead);
  if (!j.comm.node_first) populate(node, false);
  if (Status s = view_hlod_mesh(j.node_entry, j.source_hash, j.source_name, false, j.in_place); !s) return s;
  j.view = j.in_place.mesh;
  j.options.surfaces = std::move(j.in_place.surfaces);
  j.r.input_triangles = size_t(j.in_place.input_triangles);
  j.r.mesh_shared = true;
  if (!j.comm.node_first) lap(j.work.load_cpu_seconds);
  return Status::success();
}

// A rank that cannot load still meets its node's collectives (the others wait there); as the
// node's first, it leaves them an empty buffer, which they report.
void sit_out_node_load(Job& j) {
  j.comm.node_barrier();
  j.comm.node_buffer(0);
  j.comm.node_barrier();
}

// Nodes may share (the comm gives node memory; settings allow it), and a node of `ranks` does.
bool can_share(const Job& j) {
  return std::endian::native == std::endian::little && j.settings.share_mesh_from > 0 && j.comm.node_barrier &&
         j.comm.node_buffer && j.comm.node_release;
}
bool node_shares(const Job& j, int64_t ranks) { return ranks >= int64_t(std::max(2u, j.settings.share_mesh_from)); }
bool shares_node(const Job& j) { return can_share(j) && node_shares(j, j.comm.node_size); }

// Per rank: 1 where it loads a copy of the mesh (its node's first where the node shares one,
// every rank where it does not); empty when no node shares.
std::vector<uint8_t> mesh_loaders(const Job& j) {
  const std::vector<int32_t>& node_of = j.comm.node_of;
  if (!can_share(j) || node_of.size() != size_t(j.ranks())) return {};  // the same answer on every rank
  std::vector<uint8_t> loads(node_of.size(), 1);
  for (size_t r = 0; r < node_of.size(); ++r)
    if (node_shares(j, std::count(node_of.begin(), node_of.end(), node_of[r]))) loads[r] = node_of[r] == int32_t(r);
  return loads;
}

Status load_and_plan(Job& j, const std::filesystem::path& mesh_file) {
  auto t0 = Clock::now();
  double cpu = process_cpu_seconds();
  const std::function<void(double&)> lap = [&cpu](double& into) {
    const double now = process_cpu_seconds();
    into = now - cpu;
    cpu = now;
  };
  j.source_name = mesh_file.string();
  if (Status s = shares_node(j) ? load_shared(j, mesh_file, lap) : load_own(j, mesh_file, lap); !s) return s;
  j.r.load_seconds = seconds_since(t0);
  t0 = Clock::now();
  j.options.min_verts = j.settings.min_verts;
  // Few subtrees keep the top small (rank 0's serial part and everyone's measuring grow with
  // it); the cuts between the ranks' shares are refined instead, so that they still split evenly.
  j.options.subtrees = j.settings.subtrees ? j.settings.subtrees : default_subtrees(j.ranks());
  j.options.balance_parts = uint32_t(j.ranks());
  j.options.balance_cuts = node_loader_cuts(mesh_loaders(j));
  j.options.parallel_for = tbb_parallel_for();
  j.builder = std::make_unique<HlodBuilder>(j.view, j.options);
  Status planned;
  j.arena->execute([&] { planned = j.builder->plan(); });
  if (!planned) return planned;
  for (const HlodSubtreeSpec& spec : j.specs()) j.keys.push_back(hlod_subtree_key(j.source_hash, j.options, spec));
  j.r.subtrees = j.keys.size();
  const size_t n = j.keys.size();
  j.roots.resize(n);
  j.have.assign(n, 0);
  j.missing.assign(n, 1);
  j.writer.assign(n, -1);
  j.entries.resize(n);
  j.let_go.assign(n, {0, 0});
  lap(j.work.plan_cpu_seconds);
  j.r.plan_seconds = seconds_since(t0);
  return Status::success();
}

// The listed subtrees in contiguous runs of the top's depth-first order, by estimated cost, at
// the plan's cuts when it has them (node loaders bake less): by position in the list. All of
// them when `which` is null, in equal shares: the cache checks, which no load unbalances.
std::vector<int> spatial_share(const Job& j, const std::vector<size_t>* which) {
  std::vector<size_t> ids = which ? *which : std::vector<size_t>(j.specs().size());
  if (!which) std::iota(ids.begin(), ids.end(), size_t(0));
  std::vector<uint64_t> costs;
  for (size_t i : ids) costs.push_back(j.specs()[i].triangles);
  std::vector<size_t> order(ids.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return j.specs()[ids[a]].spatial < j.specs()[ids[b]].spatial; });
  return j.options.balance_cuts.empty() || which == nullptr ? assign_subtrees_spatially(costs, order, j.ranks())
                                                             : assign_subtrees_at_cuts(costs, order, j.options.balance_cuts);
}

// Every rank checks its share of the entries in full (the same split on every rank) and keeps
// the bytes of those found: it writes their payloads later. One byte per subtree for rank 0:
// 0 not this rank's, 1 found, 2 missing or refused (a refused entry is removed, so that
// progress counts only its replacement).
std::vector<uint8_t> check_share(Job& j) {
  const auto t0 = Clock::now();
  const double cpu0 = process_cpu_seconds();
  const size_t n = j.keys.size();
  const std::vector<int> checker = spatial_share(j, nullptr);
  std::vector<size_t> mine;
  for (size_t i = 0; i < n; ++i)
    if (checker[i] == j.comm.rank) mine.push_back(i);
  std::vector<std::string> why(mine.size());
  std::vector<uint64_t> bytes(mine.size(), 0);
  std::vector<CacheLookup> found(mine.size());
  std::vector<HlodSubtree> decoded(mine.size());
  j.arena->execute([&] {
    detail::annotated_parallel_for(mine.size(), [&](size_t k) {
      const size_t i = mine[k];
      found[k] = load_hlod_subtree(j.settings.cache_dir, j.keys[i], j.vertices(), decoded[k], &why[k], &bytes[k],
                                   &j.entries[i]);
      if (found[k] == CacheLookup::found) hold_entry(j, i, j.entries[i]);
      else std::vector<uint8_t>().swap(j.entries[i]);
      if (j.comm.rank == 0 && found[k] == CacheLookup::found) j.roots[i] = root_only(std::move(decoded[k]));
      decoded[k] = {};
    });
  });
  std::vector<uint8_t> bits(n, 0);
  for (size_t k = 0; k < mine.size(); ++k) {
    const size_t i = mine[k];
    bits[i] = found[k] == CacheLookup::found ? 1 : 2;
    if (found[k] == CacheLookup::refused) {
      j.say("subtree " + std::to_string(i) + ": " + why[k] + ": baking it again");
      std::error_code ec;
      std::filesystem::remove(hlod_subtree_entry_path(j.settings.cache_dir, j.keys[i]), ec);
    }
    if (found[k] != CacheLookup::found) continue;
    j.have[i] = j.comm.rank == 0;
    ++j.work.checked;
    j.work.bytes_checked += bytes[k];
  }
  j.work.check_cpu_seconds = process_cpu_seconds() - cpu0;
  j.r.lookup_seconds = seconds_since(t0);
  return bits;
}

// What a rank tells rank 0 after its check: one byte per subtree (check_share), the content
// hash of the input it read, whether it planned.
std::vector<uint8_t> encode_check(const Job& j, std::vector<uint8_t> bits, bool ready) {
  detail::ByteWriter w;
  w.bytes = std::move(bits);
  w.u64(j.source_hash);
  w.u8(ready ? 1 : 0);
  return std::move(w.bytes);
}

// Rank 0: every rank's check merged into the missing mask (a subtree is cached when its
// checker found it; a rank that could not plan found nothing). Ranks that read other bytes
// than rank 0 (the "shared" storage is not, or MESH changed as the job started) would bake
// subtrees of another mesh: the job stops, naming them.
Status merge_checks(const Job& j, const std::vector<std::vector<uint8_t>>& checks, std::vector<uint8_t>& missing) {
  missing.assign(j.keys.size(), 1);
  std::string differ;
  for (size_t r = 0; r < checks.size(); ++r) {
    const std::vector<uint8_t>& c = checks[r];
    if (c.size() < 9 || c.back() != 1) continue;  // could not plan: it says why itself
    if (detail::load_u64(c.data() + c.size() - 9) != j.source_hash || c.size() != missing.size() + 9) {
      differ += (differ.empty() ? "rank " : ", ") + std::to_string(r);
      continue;
    }
    for (size_t i = 0; i < missing.size(); ++i)
      if (c[i] == 1) missing[i] = 0;
  }
  if (differ.empty()) return Status::success();
  return Status::error(differ + " read another input than rank 0 (other bytes, or another number of subtrees): the mesh "
                       "must be the same file on every rank's storage, and unchanged while the job runs");
}

std::unique_ptr<CacheProgress> watch_progress(const Job& j) {
  std::vector<std::filesystem::path> paths;
  std::vector<uint64_t> tris;
  for (size_t i = 0; i < j.keys.size(); ++i)
    if (j.missing[i])
      paths.push_back(hlod_subtree_entry_path(j.settings.cache_dir, j.keys[i])), tris.push_back(j.specs()[i].triangles);
  return std::make_unique<CacheProgress>("subtrees", std::move(paths), std::move(tris), j.keys.size(), j.r.cached, j.log);
}

// Who writes each subtree's payloads: the rank that checked a cached entry, or bakes a missing
// one (the missing ones in contiguous runs of their own). A rank measures the top's samples in
// the cells of what it writes.
void assign_writers(Job& j) {
  const std::vector<int> checker = spatial_share(j, nullptr);
  std::vector<size_t> todo;
  for (size_t i = 0; i < j.missing.size(); ++i)
    if (j.missing[i]) todo.push_back(i);
    else j.writer[i] = checker[i];
  const std::vector<int> owner = spatial_share(j, &todo);
  for (size_t k = 0; k < todo.size(); ++k) j.writer[todo[k]] = owner[k];
  std::vector<size_t> region;
  for (size_t i = 0; i < j.writer.size(); ++i)
    if (j.writer[i] == j.comm.rank) region.push_back(i);
  j.builder->set_region(region);
}

// The cleaned mesh goes into the cache before any subtree is baked (a rerun after a kill skips
// the clean), by the rank with the least to do (its bake, and its node's load): it is a second
// of one rank's CPU on 14M triangles, on the critical path when that rank has as much as the others.
void store_cleaned_mesh(Job& j) {
  if (!j.store_mesh) return;
  std::vector<uint64_t> load(size_t(j.ranks()), 0);
  for (size_t i = 0; i < j.missing.size(); ++i)
    if (j.missing[i] && j.writer[i] >= 0 && j.writer[i] < j.ranks()) load[size_t(j.writer[i])] += j.specs()[i].triangles;
  const std::vector<uint8_t> loaders = mesh_loaders(j);
  for (size_t r = 0; r < loaders.size() && r < load.size(); ++r)
    if (loaders[r]) load[r] += uint64_t(kNodeLoadShare * double(j.r.input_triangles));
  const int storer = int(std::min_element(load.begin(), load.end()) - load.begin());
  if (j.comm.rank != storer) return;
  const double cpu0 = process_cpu_seconds();
  const Status s = j.node_entry.empty()
                       ? store_hlod_mesh(j.settings.cache_dir, j.source_hash, j.mesh, j.r.input_triangles, j.options.surfaces)
                       : store_hlod_mesh_bytes(j.settings.cache_dir, j.source_hash, j.node_entry);
  if (!s)
    j.say("rank " + std::to_string(j.comm.rank) + ": " + s.message + " (the cleaned mesh is not cached; the bake goes on)");
  j.work.clean_cpu_seconds += process_cpu_seconds() - cpu0;
}

std::vector<size_t> my_share(const Job& j) {
  std::vector<size_t> mine;
  for (size_t i = 0; i < j.missing.size(); ++i)
    if (j.missing[i] && j.writer[i] == j.comm.rank) mine.push_back(i);
  return mine;
}

// Stores a finished subtree; the rank keeps the entry's bytes to write, rank 0 the root too.
Status keep_baked(Job& j, size_t i, HlodSubtree&& s, std::mutex& mutex, uint64_t* bytes) {
  std::vector<uint8_t> entry;
  if (Status st = store_hlod_subtree(j.settings.cache_dir, j.keys[i], j.vertices(), s, bytes, &entry); !st) return st;
  hold_entry(j, i, entry);
  std::lock_guard lock(mutex);
  j.entries[i] = std::move(entry);
  if (j.comm.rank == 0) j.roots[i] = root_only(std::move(s)), j.have[i] = 1;
  return Status::success();
}

// This rank's share, each result stored as soon as it is finished.
RankReport bake_share(Job& j, const std::vector<size_t>& mine) {
  RankReport rep;
  std::mutex mutex;
  std::atomic<size_t> stored{0};
  const auto t0 = Clock::now();
  const double cpu0 = process_cpu_seconds();
  auto done = [&](size_t i, HlodSubtree&& s) -> Status {
    if (j.settings.before_store) j.settings.before_store(i, stored.load());
    uint64_t bytes = 0;
    if (Status st = keep_baked(j, i, std::move(s), mutex, &bytes); !st) return st;
    stored.fetch_add(1);
    std::lock_guard lock(mutex);
    ++j.work.subtrees;
    j.work.triangles += j.specs()[i].triangles;
    j.work.bytes_written += bytes;
    return Status::success();
  };
  j.arena->execute([&] {
    try {
      rep.status = j.builder->bake_subtrees(mine, done);
    } catch (const std::exception& e) {
      rep.status = Status::error(std::string("rank ") + std::to_string(j.comm.rank) + ": " + e.what());
    }
  });
  j.work.bake_seconds = seconds_since(t0);
  j.work.bake_cpu_seconds = process_cpu_seconds() - cpu0;
  j.work.surface_cpu_seconds = j.builder->surface_cpu_seconds();
  j.work.part_triangles = j.builder->part_triangles();
  j.work.whole_surface = j.builder->whole_surface_built() ? 1 : 0;
  if (!rep.status) rep.status.message = "rank " + std::to_string(j.comm.rank) + ": " + rep.status.message;
  return rep;
}

// Rank 0: the roots it does not hold, from the entries' first bytes; a subtree whose entry is
// refused now is baked here (and written by rank 0).
Status collect_roots(Job& j) {
  const size_t n = j.keys.size();
  std::vector<CacheLookup> found(n, CacheLookup::found);
  std::vector<std::string> why(n);
  std::vector<uint64_t> bytes(n, 0);
  j.arena->execute([&] {
    detail::annotated_parallel_for(n, [&](size_t i) {
      if (!j.have[i])
        found[i] = load_hlod_subtree_root(j.settings.cache_dir, j.keys[i], j.vertices(), j.roots[i], &why[i], &bytes[i]);
    });
  });
  std::vector<size_t> refused;
  for (size_t i = 0; i < n; ++i) {
    j.r.entry_bytes_read += bytes[i];
    if (j.have[i] || found[i] == CacheLookup::found) {
      j.have[i] = 1;
      continue;
    }
    j.say("subtree " + std::to_string(i) + ": " + (why[i].empty() ? "entry missing" : why[i]) + ": baking it again on rank 0");
    refused.push_back(i);
  }
  if (refused.empty()) return Status::success();
  j.r.rebaked = refused.size();
  std::mutex mutex;
  Status st;
  j.arena->execute([&] {
    st = j.builder->bake_subtrees(refused, [&](size_t i, HlodSubtree&& s) {
      if (Status kept = keep_baked(j, i, std::move(s), mutex, nullptr); !kept) return kept;
      j.writer[i] = 0;
      return Status::success();
    });
  });
  return st;
}

// Where every subtree node's payload goes in the file: (offset, size) by the subtree's own
// node order, and who writes it; the temporary file's name. Rank 0 sends it to every rank.
struct Layout {
  bool ok = false;
  std::filesystem::path temp;
  std::vector<int32_t> writer;
  std::vector<std::vector<std::pair<uint64_t, uint64_t>>> pieces;  // by subtree, by local node
};

std::vector<uint8_t> encode_layout(const Layout& l) {
  detail::ByteWriter w;
  w.u8(l.ok ? 1 : 0);
  const std::string path = l.temp.string();
  w.u32(uint32_t(path.size()));
  w.raw(path.data(), path.size());
  w.u32(uint32_t(l.pieces.size()));
  for (size_t i = 0; i < l.pieces.size(); ++i) {
    w.u32(uint32_t(l.writer[i]));
    w.u32(uint32_t(l.pieces[i].size()));
    for (const auto& [offset, size] : l.pieces[i]) w.u64(offset), w.u64(size);
  }
  return std::move(w.bytes);
}

// Every count checked against the bytes left before it is used.
bool decode_layout(const std::vector<uint8_t>& b, Layout& l) {
  size_t at = 0;
  auto has = [&](uint64_t n) { return n <= b.size() - at; };
  if (!has(5)) return false;
  l.ok = b[at++] == 1;
  const uint32_t path_bytes = detail::load_u32(b.data() + at);
  at += 4;
  if (!has(uint64_t(path_bytes) + 4)) return false;
  l.temp = std::string(b.begin() + std::ptrdiff_t(at), b.begin() + std::ptrdiff_t(at + path_bytes));
  at += path_bytes;
  const uint32_t count = detail::load_u32(b.data() + at);
  at += 4;
  if (!has(8ull * count)) return false;
  l.writer.resize(count);
  l.pieces.resize(count);
  for (uint32_t i = 0; i < count; ++i) {
    if (!has(8)) return false;
    l.writer[i] = int32_t(detail::load_u32(b.data() + at));
    const uint32_t nodes = detail::load_u32(b.data() + at + 4);
    at += 8;
    if (!has(16ull * nodes)) return false;
    l.pieces[i].resize(nodes);
    for (auto& [offset, size] : l.pieces[i]) {
      offset = detail::load_u64(b.data() + at), size = detail::load_u64(b.data() + at + 8);
      at += 16;
    }
  }
  return at == b.size();
}

// The top's layers to measure, sent by rank 0 to every rank (ok = 0: nothing to measure, the
// job has failed), and the share of them each rank measures (by sample count, longest first).
std::vector<uint8_t> encode_probes(bool ok, const std::vector<HlodLayerProbe>& probes) {
  detail::ByteWriter w;
  w.u8(ok ? 1 : 0);
  w.u32(uint32_t(probes.size()));
  for (const HlodLayerProbe& p : probes) {
    w.u32(uint32_t(p.source.size())), w.u32(uint32_t(p.indices.size())), w.u32(uint32_t(p.reference.size()));
    w.words(p.positions.data(), p.positions.size());
    w.words(p.indices.data(), p.indices.size());
    w.words(p.source.data(), p.source.size());
    w.words(p.reference.data(), p.reference.size());
  }
  return std::move(w.bytes);
}

template <class T>
bool take_words(const std::vector<uint8_t>& b, size_t& at, uint64_t count, std::vector<T>& out) {
  if (count > (b.size() - at) / 4) return false;
  out.resize(size_t(count));
  for (T& v : out) v = std::bit_cast<T>(detail::load_u32(b.data() + at)), at += 4;
  return true;
}

bool decode_probes(const std::vector<uint8_t>& b, bool& ok, std::vector<HlodLayerProbe>& probes) {
  if (b.size() < 5) return false;
  ok = b[0] == 1;
  const uint32_t count = detail::load_u32(b.data() + 1);
  size_t at = 5;
  if (count > (b.size() - at) / 12) return false;
  probes.resize(count);
  for (HlodLayerProbe& p : probes) {
    if (b.size() - at < 12) return false;
    const uint32_t nv = detail::load_u32(b.data() + at), ni = detail::load_u32(b.data() + at + 4),
                   nr = detail::load_u32(b.data() + at + 8);
    at += 12;
    if (!take_words(b, at, 3ull * nv, p.positions) || !take_words(b, at, ni, p.indices) ||
        !take_words(b, at, nv, p.source) || !take_words(b, at, nr, p.reference))
      return false;
  }
  return at == b.size();
}

std::vector<int> probe_owners(const std::vector<HlodLayerProbe>& probes, int ranks) {
  std::vector<uint64_t> costs;
  for (const HlodLayerProbe& p : probes) costs.push_back(p.source.size() + p.indices.size() / 3 + p.reference.size());
  return assign_subtrees(costs, ranks);
}

// Every rank: the top's layers measured by sample, each rank those in the cells it writes
// (the original's side of its share of the layers as well). The reply: a status, then per
// layer the largest distance found, the other side's errors of its share, and per layer which
// samples it answered (bits).
std::vector<uint8_t> measure_share(Job& j, const std::vector<HlodLayerProbe>& probes) {
  const double cpu0 = process_cpu_seconds();
  const std::vector<int> owner = probe_owners(probes, j.ranks());
  std::vector<size_t> mine;
  for (size_t i = 0; i < probes.size(); ++i)
    if (owner[i] == j.comm.rank) mine.push_back(i);
  std::vector<float> to_max, from_max;
  std::vector<std::vector<uint8_t>> answered;
  Status st;
  j.arena->execute([&] { st = j.builder->measure_probes_part(probes, mine, to_max, answered, from_max); });
  detail::ByteWriter w;
  w.u8(st ? 1 : 0);
  if (st) {
    w.u32(uint32_t(to_max.size()));
    w.words(to_max.data(), to_max.size());
    w.u32(uint32_t(from_max.size()));
    w.words(from_max.data(), from_max.size());
    for (const std::vector<uint8_t>& flags : answered) {
      w.u32(uint32_t(flags.size()));
      for (size_t i = 0; i < flags.size(); i += 8) {
        uint8_t byte = 0;
        for (size_t b = 0; b < 8 && i + b < flags.size(); ++b) byte |= uint8_t(flags[i + b] ? 1u << b : 0u);
        w.u8(byte);
      }
    }
  } else {
    const std::string message = "rank " + std::to_string(j.comm.rank) + ": " + st.message;
    w.raw(message.data(), message.size());
  }
  j.work.measure_cpu_seconds = process_cpu_seconds() - cpu0;
  return std::move(w.bytes);
}

// Rank 0: every rank's answers merged (largest distances, answered samples, the other side's
// errors in probe order), the samples nobody answered measured here, the errors made.
Status merge_errors(Job& j, const std::vector<HlodLayerProbe>& probes,
                    const std::vector<std::vector<uint8_t>>& replies, std::vector<float>& errors) {
  const double cpu0 = process_cpu_seconds();
  const std::vector<int> owner = probe_owners(probes, j.ranks());
  const size_t n = probes.size();
  std::vector<float> to_max(n, 0.0f), from_max(n, 0.0f);
  std::vector<std::vector<uint8_t>> answered(n);
  for (size_t r = 0; r < replies.size(); ++r) {
    const std::vector<uint8_t>& b = replies[r];
    const std::string from = "rank " + std::to_string(r);
    if (b.empty()) return Status::error(from + " sent no top errors");
    if (b[0] != 1) return Status::error(std::string(b.begin() + 1, b.end()));
    size_t at = 1;
    auto count = [&](uint32_t& c) {
      if (b.size() - at < 4) return false;
      c = detail::load_u32(b.data() + at);
      at += 4;
      return true;
    };
    const Status bad = Status::error(from + " sent malformed top errors");
    uint32_t nt = 0, nf = 0;
    std::vector<float> to, fr;
    if (!count(nt) || nt != n || !take_words(b, at, nt, to) || !count(nf) || !take_words(b, at, nf, fr)) return bad;
    size_t k = 0;
    for (size_t i = 0; i < n; ++i) {
      to_max[i] = std::max(to_max[i], to[i]);
      if (owner[i] != int(r)) continue;
      if (k >= fr.size()) return Status::error(from + " sent too few top errors");
      from_max[i] = fr[k++];
    }
    if (k != fr.size()) return Status::error(from + " sent too many top errors");
    for (size_t i = 0; i < n; ++i) {
      uint32_t samples = 0;
      if (!count(samples) || (uint64_t(samples) + 7) / 8 > b.size() - at) return bad;
      if (r == 0) answered[i].assign(samples, 0);
      if (answered[i].size() != samples) return Status::error(from + " sent another sample count for top layer " + std::to_string(i));
      for (size_t s = 0; s < samples; ++s) answered[i][s] |= (b[at + s / 8] >> (s % 8)) & 1;
      at += (size_t(samples) + 7) / 8;
    }
    if (at != b.size()) return bad;
  }
  for (const std::vector<uint8_t>& flags : answered)
    for (uint8_t f : flags) j.r.top_samples_left += f == 0;
  Status st;
  j.arena->execute([&] { st = j.builder->measure_probes_rest(probes, answered, to_max); });
  if (!st) return st;
  j.r.top_whole_surface = j.builder->whole_surface_built();
  errors.resize(n);
  for (size_t i = 0; i < n; ++i) errors[i] = std::max(to_max[i], from_max[i]);
  j.r.top_rest_cpu_seconds = process_cpu_seconds() - cpu0;
  return Status::success();
}

// Rank 0: the top finished from the errors, the head and the top's payloads written into the
// temporary at the file's full size; the subtrees' places in it.
Status finish_and_lay_out(Job& j, const std::vector<float>& errors, const std::string& name,
                          const std::filesystem::path& out_dir, Layout& layout) {
  auto t0 = Clock::now();
  double cpu = process_cpu_seconds();
  HlodAssembly assembly;
  Status st;
  j.arena->execute([&] { st = j.builder->finish_top(j.roots, errors, assembly, &j.r.report); });
  if (!st) return st;
  HlodTree& tree = assembly.model.tree;
  tree.name = name;
  tree.source_hash = j.source_hash;
  j.roots.clear();
  j.r.assemble_seconds += seconds_since(t0);
  j.r.assemble_cpu_seconds += process_cpu_seconds() - cpu;
  t0 = Clock::now();
  cpu = process_cpu_seconds();
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) return Status::error(out_dir.string() + ": cannot create the output directory: " + ec.message());
  j.r.file = out_dir / (name + ".hlod");
  const size_t count = tree.nodes.size();
  std::vector<std::vector<uint8_t>> top(count);
  std::vector<uint64_t> sizes(count);
  for (size_t i = 0; i < count; ++i) {
    if (assembly.origin[i].subtree < 0) top[i] = encode_hlod_payload(assembly.model.payloads[i]);
    sizes[i] = assembly.origin[i].subtree < 0 ? top[i].size() : hlod_payload_bytes(tree.nodes[i]);
  }
  const std::vector<uint8_t> head = encode_hlod_head(tree, sizes);
  layout.writer = j.writer;
  layout.pieces.assign(j.keys.size(), {});
  std::vector<FilePiece> mine{{0, head}};
  uint64_t at = head.size();
  for (size_t i = 0; i < count; ++i) {
    const HlodAssembly::Origin o = assembly.origin[i];
    if (o.subtree < 0) {
      mine.push_back({at, top[i]});
    } else {
      auto& pieces = layout.pieces[size_t(o.subtree)];
      if (pieces.size() <= o.local) pieces.resize(o.local + 1);
      pieces[o.local] = {at, sizes[i]};
    }
    at += sizes[i];
  }
  j.r.bytes = at;
  if (Status s = create_sized_temporary(j.r.file, at, layout.temp); !s) return s;
  if (Status s = write_pieces(layout.temp, mine, j.r.file.string()); !s) {
    std::filesystem::remove(layout.temp, ec);
    return s;
  }
  layout.ok = true;
  j.r.write_seconds = seconds_since(t0);
  j.r.head_cpu_seconds = process_cpu_seconds() - cpu;
  return Status::success();
}

// An entry this rank writes but let go: read back, its size checked before the read and its
// bytes against the hash of those it checked. The cache is shared storage: an entry changed
// since is removed (the rerun bakes it anew) and fails the write.
Status read_back_entry(Job& j, size_t i, const std::string& entry, std::vector<uint8_t>& bytes) {
  const auto [size, hash] = j.let_go[i];
  const std::string again = " (run again: it is baked anew)";
  if (Status s = read_hlod_subtree_entry(j.settings.cache_dir, j.keys[i], size, bytes); !s)
    return Status::error(s.message + ": reading back an entry this rank stored or checked" + again);
  j.work.bytes_read_back += size;
  if (hash_bytes(bytes.data(), bytes.size()) == hash) return Status::success();
  std::error_code ec;
  std::filesystem::remove(hlod_subtree_entry_path(j.settings.cache_dir, j.keys[i]), ec);
  return Status::error(entry + ": changed on the storage since this rank stored or checked it, found reading it back" +
                       again);
}

// Subtree i's payloads in `entry` and where they go (each piece's size checked against the
// entry's own record of it).
Status place_entry(Job& j, const Layout& layout, size_t i, const std::vector<uint8_t>& bytes, const std::string& entry,
                   std::vector<FilePiece>& pieces) {
  std::vector<std::span<const uint8_t>> payloads;
  if (Status s = hlod_subtree_entry_payloads(bytes, entry, payloads); !s) return s;
  if (payloads.size() != layout.pieces[i].size())
    return Status::error(entry + ": " + std::to_string(payloads.size()) + " nodes, the assembled tree has " +
                         std::to_string(layout.pieces[i].size()));
  for (size_t k = 0; k < payloads.size(); ++k) {
    if (payloads[k].size() != layout.pieces[i][k].second)
      return Status::error(entry + ": node " + std::to_string(k) + "'s payload is " + std::to_string(payloads[k].size()) +
                           " bytes, its record says " + std::to_string(layout.pieces[i][k].second));
    pieces.push_back({layout.pieces[i][k].first, payloads[k]});
    j.work.bytes_placed += payloads[k].size();
  }
  return Status::success();
}

// Every rank: the payloads of the subtrees it writes, at the places rank 0 gave: those of the
// entries it holds in one pass at the end, each entry read back written on its own and let go.
RankReport write_share(Job& j, const Layout& layout, const std::string& what) {
  RankReport rep;
  const auto t0 = Clock::now();
  const double cpu0 = process_cpu_seconds();
  std::vector<FilePiece> held;
  std::vector<uint8_t> bytes;  // each entry read back, in one buffer (no fresh memory per entry)
  uint64_t largest = 0;
  for (size_t i = 0; i < layout.writer.size(); ++i)
    if (layout.writer[i] == j.comm.rank && j.entries[i].empty()) largest = std::max(largest, j.let_go[i].first);
  bytes.reserve(size_t(largest));
  for (size_t i = 0; i < layout.writer.size() && rep.status; ++i) {
    if (layout.writer[i] != j.comm.rank) continue;
    const std::string entry = hlod_subtree_entry_path(j.settings.cache_dir, j.keys[i]).string();
    if (!j.entries[i].empty()) {
      rep.status = place_entry(j, layout, i, j.entries[i], entry, held);
      continue;
    }
    std::vector<FilePiece> pieces;
    rep.status = read_back_entry(j, i, entry, bytes);
    if (rep.status) rep.status = place_entry(j, layout, i, bytes, entry, pieces);
    if (rep.status) rep.status = write_pieces(layout.temp, pieces, what);
  }
  if (rep.status) rep.status = write_pieces(layout.temp, held, what);
  if (!rep.status) rep.status.message = "rank " + std::to_string(j.comm.rank) + ": " + rep.status.message;
  j.entries.clear();
  j.work.write_cpu_seconds = process_cpu_seconds() - cpu0;
  if (j.comm.rank == 0) j.r.write_seconds += seconds_since(t0);
  take_usage(j.work);
  rep.work = j.work;
  return rep;
}

// Rank 0: every rank's report; the first failure (others' logged), every rank's work.
Status take_reports(Job& j, const std::vector<std::vector<uint8_t>>& reports, bool keep_work) {
  Status failed;
  for (size_t r = 0; r < reports.size(); ++r) {
    const RankReport other = decode_report(reports[r], int(r));
    if (keep_work) j.r.ranks.push_back(other.work);
    else if (r < j.r.ranks.size()) {
      j.r.ranks[r].write_cpu_seconds = other.work.write_cpu_seconds;
      j.r.ranks[r].measure_cpu_seconds = other.work.measure_cpu_seconds;
      j.r.ranks[r].bytes_placed = other.work.bytes_placed;
      j.r.ranks[r].bytes_read_back = other.work.bytes_read_back;
      j.r.ranks[r].kernel_cpu_seconds = other.work.kernel_cpu_seconds;
      j.r.ranks[r].peak_rss_bytes = other.work.peak_rss_bytes;
    }
    if (!other.status && failed) failed = other.status;
    if (!other.status && r != 0) j.say(other.status.message);
  }
  return failed;
}

}  // namespace

Status check_shared_folders(const std::vector<SharedFolder>& folders, const HlodRankComm& comm) {
  std::string name;
  Status placed;
  if (comm.rank == 0) placed = place_probes(folders, name);
  std::vector<uint8_t> sent(name.begin(), name.end());
  if (!placed) sent.clear();
  comm.broadcast(sent);  // empty: rank 0 could not place them (it says why)
  const std::string seen_name(sent.begin(), sent.end());
  const std::vector<std::vector<uint8_t>> answers =
      comm.gather(sent.empty() ? std::vector<uint8_t>{} : sees_probes(folders, seen_name));
  std::vector<uint8_t> verdict;  // why the job cannot go on; empty: every rank saw every probe
  if (comm.rank == 0) {
    const std::string unseen = placed ? unseen_message(folders, answers) : placed.message;
    verdict.assign(unseen.begin(), unseen.end());
    if (!name.empty()) remove_probes(folders, name);  // also those placed before a failure
  }
  comm.broadcast(verdict);
  if (!verdict.empty()) return Status::error(std::string(verdict.begin(), verdict.end()));
  if (sent.empty()) return Status::error("rank 0 sent no folder probe");
  return Status::success();
}

HlodRankComm single_rank_comm() {
  HlodRankComm c;
  c.broadcast = [](std::vector<uint8_t>&) {};
  c.gather = [](const std::vector<uint8_t>& mine) { return std::vector<std::vector<uint8_t>>{mine}; };
  return c;
}

std::vector<int> assign_subtrees_at_cuts(const std::vector<uint64_t>& costs, const std::vector<size_t>& order,
                                         const std::vector<double>& cuts) {
  const uint64_t total = std::accumulate(costs.begin(), costs.end(), uint64_t(0));
  std::vector<int> owner(costs.size(), 0);
  uint64_t before = 0;
  for (size_t i : order) {
    if (i >= costs.size()) continue;
    const double middle = (double(before) + 0.5 * double(costs[i])) / double(std::max<uint64_t>(1, total));
    owner[i] = int(std::upper_bound(cuts.begin(), cuts.end(), middle) - cuts.begin());
    before += costs[i];
  }
  return owner;
}

std::vector<double> node_loader_cuts(const std::vector<uint8_t>& loads) {
  const size_t ranks = loads.size();
  const size_t loaders = size_t(std::count(loads.begin(), loads.end(), uint8_t(1)));
  if (ranks < 2 || loaders == 0 || loaders == ranks) return {};
  // Rank r bakes (1 + e * loaders) / ranks - e of the whole when it loads, its plain share else.
  std::vector<double> share(ranks);
  double sum = 0;
  for (size_t r = 0; r < ranks; ++r) {
    const double even = (1 + kNodeLoadShare * double(loaders)) / double(ranks);
    share[r] = std::max(0.1 * even, loads[r] ? even - kNodeLoadShare : even);
    sum += share[r];
  }
  std::vector<double> cuts;
  double at = 0;
  for (size_t r = 0; r + 1 < ranks; ++r) cuts.push_back(at += share[r] / sum);
  return cuts;
}

std::vector<int> assign_subtrees_spatially(const std::vector<uint64_t>& costs, const std::vector<size_t>& order,
                                           int ranks) {
  const uint64_t total = std::accumulate(costs.begin(), costs.end(), uint64_t(0));
  const int r = std::max(1, ranks);
  std::vector<int> owner(costs.size(), 0);
  uint64_t before = 0;
  for (size_t i : order) {
    if (i >= costs.size()) continue;
    // The middle of its cost, as a fraction of the total, picks the rank (doubled: no halves).
    const unsigned __int128 middle = (unsigned __int128)(2 * before + costs[i]) * unsigned(r);
    const uint64_t of = std::max<uint64_t>(1, 2 * total);
    owner[i] = int(std::min<unsigned __int128>(middle / of, unsigned(r - 1)));
    before += costs[i];
  }
  return owner;
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
  Job j{settings, comm, log};
  j.arena = std::make_unique<tbb::task_arena>(settings.threads == 0 ? tbb::task_arena::automatic : int(settings.threads));
  std::error_code ec;
  std::filesystem::create_directories(settings.cache_dir, ec);
  // A rank that cannot load or plan still takes part in the collectives (others wait there).
  Status ready = ec ? Status::error(settings.cache_dir.string() + ": cannot create the cache directory: " + ec.message())
                    : Status::success();
  // Before any work: every rank must see rank 0's cache and output folders.
  if (Status shared = check_shared_folders({{"cache folder", settings.cache_dir}, {"output folder", out_dir}}, comm);
      !shared && ready)
    ready = shared;
  if (ready) ready = load_and_plan(j, mesh_file);
  else if (shares_node(j)) sit_out_node_load(j);
  if (!ready) ready.message = "rank " + std::to_string(comm.rank) + ": " + ready.message;
  const std::vector<std::vector<uint8_t>> checks =
      comm.gather(encode_check(j, ready ? check_share(j) : std::vector<uint8_t>{}, bool(ready)));
  // The missing mask and 1; or why nobody bakes and 0 (nothing when rank 0 could not plan).
  std::vector<uint8_t> mask;
  Status agreed = ready;
  if (comm.rank == 0 && ready) agreed = merge_checks(j, checks, mask);
  if (!agreed && ready) mask.assign(agreed.message.begin(), agreed.message.end());
  mask.push_back(agreed ? 1 : 0);
  comm.broadcast(mask);
  const bool go = !mask.empty() && mask.back() == 1 && ready && mask.size() == j.keys.size() + 1;
  RankReport rep;
  rep.status = ready;
  if (ready && !mask.empty() && mask.back() == 0 && mask.size() > 1)
    rep.status = Status::error("rank " + std::to_string(comm.rank) + ": " + std::string(mask.begin(), mask.end() - 1));
  std::unique_ptr<CacheProgress> watch;  // rank 0, until every rank has reported
  if (go) {
    mask.pop_back();
    j.missing = mask;
    for (uint8_t m : j.missing) j.r.cached += m == 0;
    assign_writers(j);
    store_cleaned_mesh(j);
    if (comm.rank == 0) watch = watch_progress(j);
    rep = bake_share(j, my_share(j));
    j.r.bake_seconds = j.work.bake_seconds;  // a failure: the caller prints it, rank 0 gathers it
  } else if (ready && rep.status) {
    rep.status = Status::error("rank " + std::to_string(comm.rank) + ": rank 0 could not plan the build");
  }
  j.work.total_seconds = seconds_since(t_start);
  j.work.cpu_seconds = process_cpu_seconds() - cpu_start;
  take_usage(j.work);
  rep.work = j.work;
  const std::vector<std::vector<uint8_t>> reports = comm.gather(encode_report(rep));
  watch.reset();
  if (result) *result = {};

  // Rank 0 assembles and lays the file out; every rank then writes its part.
  Layout layout;
  Status st = rep.status;
  double cpu_gathered = process_cpu_seconds();
  std::vector<HlodLayerProbe> probes;
  double serial_cpu = 0;  // rank 0's own, while the others wait
  if (comm.rank == 0) {
    st = take_reports(j, reports, true);
    if (!st && go) st.message += " (the cache keeps every finished subtree: run again to resume)";
    const double cpu0 = process_cpu_seconds();
    if (st) st = collect_roots(j);
    const double cpu1 = process_cpu_seconds();
    j.r.collect_cpu_seconds = cpu1 - cpu0;
    const auto t0 = Clock::now();
    if (st) j.arena->execute([&] { st = j.builder->build_top(j.roots, probes); });
    j.r.assemble_seconds = seconds_since(t0);
    j.r.assemble_cpu_seconds = process_cpu_seconds() - cpu1;
    serial_cpu += process_cpu_seconds() - cpu_gathered;
  }
  // The top's layers are measured by every rank (each holds the mesh and its BVH).
  std::vector<uint8_t> sent = comm.rank == 0 ? encode_probes(bool(st), probes) : std::vector<uint8_t>{};
  comm.broadcast(sent);
  bool measuring = false;
  if (!decode_probes(sent, measuring, probes)) {
    measuring = false;
    if (st) st = Status::error("rank " + std::to_string(comm.rank) + ": rank 0 sent malformed top layers");
  }
  if (measuring) {
    const std::vector<std::vector<uint8_t>> replies = comm.gather(st ? measure_share(j, probes) : std::vector<uint8_t>{});
    if (comm.rank == 0) {
      const double cpu0 = process_cpu_seconds();
      std::vector<float> errors;
      st = merge_errors(j, probes, replies, errors);
      probes.clear();
      if (st) st = finish_and_lay_out(j, errors, name, out_dir, layout);
      serial_cpu += process_cpu_seconds() - cpu0;
    }
  }
  std::vector<uint8_t> plan = comm.rank == 0 ? encode_layout(layout) : std::vector<uint8_t>{};
  comm.broadcast(plan);
  if (comm.rank != 0 && !decode_layout(plan, layout)) {
    // Every rank got these bytes, so every rank still meets the write's gather: this one
    // writes nothing and reports the failure there.
    layout.writer.clear();
    st = Status::error("rank " + std::to_string(comm.rank) + ": rank 0 sent a malformed file layout");
  }
  if (layout.ok) {
    RankReport wrote = write_share(j, layout, (out_dir / (name + ".hlod")).string());
    if (!st && wrote.status) wrote.status = st;
    const std::vector<std::vector<uint8_t>> written = comm.gather(encode_report(wrote));
    if (comm.rank == 0) {
      st = take_reports(j, written, false);
      if (st) st = commit_temporary(layout.temp, j.r.file);
      else std::filesystem::remove(layout.temp, ec);
    } else if (st) {
      st = wrote.status;
    }
  }
  if (comm.rank == 0) {
    j.r.cpu_after_gather_seconds = process_cpu_seconds() - cpu_gathered;
    double slowest = 0, slowest_measure = 0, slowest_write = 0;
    for (const HlodRankWork& w : j.r.ranks) {
      slowest = std::max(slowest, w.cpu_seconds);
      slowest_measure = std::max(slowest_measure, w.measure_cpu_seconds);
      slowest_write = std::max(slowest_write, w.write_cpu_seconds);
    }
    j.r.critical_cpu_seconds = slowest + serial_cpu + slowest_measure + slowest_write;
  }
  j.r.total_seconds = seconds_since(t_start);
  if (shares_node(j)) {  // every rank of the node gets here, as it took part in the load
    j.builder.reset();
    j.view = {};
    j.node_entry = {};
    comm.node_release();
  }
  if (result) *result = std::move(j.r);
  return st;
}

}  // namespace lod
