// A scene of many models over ranks: estimate (rank 0) -> broadcast -> check a share of the
// model cache -> gather / broadcast what is missing -> bake own whole models (local bake) ->
// split models with all ranks (bake_hlod_distributed) -> gather of statuses, work and figures.
#include "jobs/hlod_models_distributed.h"

#include <oneapi/tbb/task_arena.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <ctime>
#include <map>
#include <mutex>
#include <numeric>
#include <sstream>
#include <thread>

#include "jobs/annotated_parallel_for.h"
#include "jobs/cache_progress.h"
#include "jobs/hlod_model_cache.h"
#include "runtime/byte_order.h"
#include "runtime/file_write.h"
#include "runtime/regular_file.h"

namespace lod {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string hex(uint64_t v) {
  char s[20];
  std::snprintf(s, sizeof s, "%016llx", static_cast<unsigned long long>(v));
  return s;
}

// "element face N" of a PLY header (0 when absent).
uint64_t ply_faces(const std::string& head) {
  std::istringstream in(head);
  std::string line;
  while (std::getline(in, line) && line.rfind("end_header", 0) != 0) {
    std::istringstream words(line);
    std::string element, what;
    uint64_t n = 0;
    if (words >> element >> what >> n && element == "element" && what == "face") return n;
  }
  return 0;
}

// The F of an OFF header's "V F E" (0 when unreadable); '#' starts a comment.
uint64_t off_faces(const std::string& head) {
  std::istringstream in(head);
  std::string line, tokens;
  while (std::getline(in, line) && tokens.size() < 256) tokens += line.substr(0, line.find('#')) + " ";
  std::istringstream words(tokens);
  std::string magic;
  uint64_t v = 0, f = 0;
  if (!(words >> magic) || magic.size() < 3 || magic.compare(magic.size() - 3, 3, "OFF") != 0) return 0;
  return words >> v >> f ? f : 0;
}

// Bounds-checked reading of what a rank sent.
struct Reader {
  std::span<const uint8_t> b;
  size_t at = 0;
  bool ok = true;
  bool need(size_t n) {
    ok = ok && b.size() - at >= n;
    return ok;
  }
  uint8_t u8() { return need(1) ? b[at++] : 0; }
  uint64_t u64() {
    if (!need(8)) return 0;
    const uint64_t v = detail::load_u64(b.data() + at);
    at += 8;
    return v;
  }
  double f64() { return std::bit_cast<double>(u64()); }
  std::string str() {
    const uint64_t n = u64();
    if (!ok || n > b.size() - at) return ok = false, std::string();
    std::string s(b.begin() + std::ptrdiff_t(at), b.begin() + std::ptrdiff_t(at + n));
    at += size_t(n);
    return s;
  }
};

void put_str(detail::ByteWriter& w, const std::string& s) {
  w.u64(s.size());
  w.raw(s.data(), s.size());
}

// A model's state once rank 0 merged the checks.
enum : uint8_t { kNotMine = 0, kFound = 1, kMissing = 2, kFailed = 3 };

struct Model {
  std::filesystem::path mesh;
  std::string name;
  uint64_t estimate = 0, source_hash = 0, key = 0;
  uint8_t state = kMissing;
};

struct Job {
  Job(const HlodModelsSettings& s, const HlodRankComm& c, const HlodBakeLog& l, std::filesystem::path out)
      : settings(s), comm(c), log(l), out_dir(std::move(out)) {}
  const HlodModelsSettings& settings;
  const HlodRankComm& comm;
  const HlodBakeLog& log;
  std::filesystem::path out_dir;
  std::vector<Model> models;
  std::vector<HlodModelFigures> figures;  // of the models this rank handled
  std::vector<size_t> figure_model;        // each one's model index
  HlodModelsRankWork work;
  std::vector<double> split_cpu;          // rank 0: per rank, its CPU in split bakes
  std::atomic<size_t> stored{0};
  std::mutex log_mutex;
  std::string first_error;

  void say(const std::string& line) {
    std::lock_guard lock(log_mutex);
    if (log) log(line);
  }
  int ranks() const { return std::max(1, comm.size); }
  std::string label(size_t i) const { return "model " + models[i].name + " (" + models[i].mesh.string() + ")"; }
  void before_store(const std::string& what) {
    if (settings.before_store) settings.before_store(what, stored.load());
  }
  HlodModelFigures figures_of(size_t i, HlodModelRoute route) const {
    HlodModelFigures f;
    f.name = models[i].name;
    f.mesh = models[i].mesh;
    f.route = route;
    f.rank = route == HlodModelRoute::split ? -1 : comm.rank;
    f.estimated_triangles = models[i].estimate;
    return f;
  }
  // From any of the rank's threads.
  void failed(HlodModelFigures& f, const std::string& why) {
    f.route = HlodModelRoute::failed;
    f.error = "rank " + std::to_string(comm.rank) + ": model " + f.name + " (" + f.mesh.string() + "): " + why;
    std::lock_guard lock(log_mutex);
    ++work.failed;
    if (first_error.empty()) first_error = f.error;
    if (log) log(f.error);
  }
};

void take_tree(HlodModelFigures& f, const HlodTree& tree, size_t bytes) {
  f.source_triangles = tree.source_triangles;
  f.nodes = tree.nodes.size();
  f.bytes = bytes;
}

// Rank 0 estimates, every rank gets the same numbers (so every rank plans the same).
Status share_estimates(Job& j) {
  detail::ByteWriter w;
  if (j.comm.rank == 0)
    for (const Model& m : j.models) w.u64(estimate_mesh_triangles(m.mesh));
  j.comm.broadcast(w.bytes);
  if (w.bytes.size() != 8 * j.models.size())
    return Status::error("rank " + std::to_string(j.comm.rank) + ": rank 0 sent malformed estimates");
  for (size_t i = 0; i < j.models.size(); ++i) j.models[i].estimate = detail::load_u64(w.bytes.data() + 8 * i);
  return Status::success();
}

std::vector<uint64_t> costs(const Job& j) {
  std::vector<uint64_t> c;
  for (const Model& m : j.models) c.push_back(std::max<uint64_t>(1, m.estimate));
  return c;
}

// This rank's share of the cache (by estimated size, longest first): each model's source
// hashed, its entry checked in full; a found entry is copied to DIR, a refused one removed.
// Per model for rank 0: its state and source hash.
std::vector<uint8_t> check_share(Job& j, tbb::task_arena& arena) {
  const double cpu0 = process_cpu_seconds();
  const std::vector<int> checker = assign_subtrees(costs(j), j.ranks());
  std::vector<size_t> mine;
  for (size_t i = 0; i < j.models.size(); ++i)
    if (checker[i] == j.comm.rank) mine.push_back(i);
  std::vector<HlodModelFigures> found(mine.size());
  std::vector<uint8_t> state(mine.size(), kMissing);
  arena.execute([&] {
    detail::annotated_parallel_for(mine.size(), [&](size_t k) {
      Model& m = j.models[mine[k]];
      found[k] = j.figures_of(mine[k], HlodModelRoute::cached);
      if (Status s = hlod_source_hash(m.mesh, j.settings.min_verts, m.source_hash); !s) {
        state[k] = kFailed;
        return j.failed(found[k], s.message);
      }
      m.key = hlod_model_key(m.source_hash, m.name);
      std::vector<uint8_t> bytes;
      HlodTree tree;
      std::string why;
      const CacheLookup look = load_hlod_model(j.settings.cache_dir, m.key, m.name, m.source_hash, bytes, &tree, &why);
      if (look == CacheLookup::refused) {
        j.say(j.label(mine[k]) + ": " + why + ": baking it again");
        std::error_code ec;
        std::filesystem::remove(hlod_model_entry_path(j.settings.cache_dir, m.key), ec);
      }
      if (look != CacheLookup::found) return;
      if (Status s = write_file_atomic(j.out_dir / (m.name + ".hlod"), bytes); !s) {
        state[k] = kFailed;
        return j.failed(found[k], s.message);
      }
      state[k] = kFound;
      take_tree(found[k], tree, bytes.size());
    });
  });
  detail::ByteWriter w;
  std::vector<uint8_t> states(j.models.size(), kNotMine);
  for (size_t k = 0; k < mine.size(); ++k) {
    states[mine[k]] = state[k];
    if (state[k] == kFound) ++j.work.checked;
    if (state[k] != kMissing) j.figures.push_back(std::move(found[k])), j.figure_model.push_back(mine[k]);
  }
  for (size_t i = 0; i < j.models.size(); ++i) w.u8(states[i]), w.u64(j.models[i].source_hash);
  j.work.check_cpu_seconds = process_cpu_seconds() - cpu0;
  return std::move(w.bytes);
}

// Rank 0: every model's state from its checker; a trailing 1 when every rank could check.
std::vector<uint8_t> merge_checks(const Job& j, const std::vector<std::vector<uint8_t>>& checks) {
  const size_t n = j.models.size();
  std::vector<uint8_t> state(n, kFailed);
  std::vector<uint64_t> hash(n, 0);
  bool all = true;
  for (const std::vector<uint8_t>& c : checks) {
    if (c.size() != 9 * n + 1 || c.back() != 1) {
      all = false;
      continue;
    }
    for (size_t i = 0; i < n; ++i)
      if (c[9 * i] != kNotMine) state[i] = c[9 * i], hash[i] = detail::load_u64(c.data() + 9 * i + 1);
  }
  detail::ByteWriter w;
  for (size_t i = 0; i < n; ++i) w.u8(state[i]), w.u64(hash[i]);
  w.u8(all ? 1 : 0);
  return std::move(w.bytes);
}

// A folder of this process's (and rank's) own inside the cache, for one bake's output.
std::filesystem::path stage_dir(const Job& j, size_t i, bool shared) {
  std::string name = ".stage-" + hex(j.models[i].key);
  if (!shared) name += unique_temporary_suffix();  // unique across processes and hosts
  return j.settings.cache_dir / name;
}

// One model by the local bake, into the cache (checked, renamed) and then DIR.
void bake_whole(Job& j, size_t i) {
  const Model& m = j.models[i];
  HlodModelFigures f = j.figures_of(i, HlodModelRoute::whole);
  const auto t0 = Clock::now();
  const double cpu0 = process_cpu_seconds();
  const std::filesystem::path stage = stage_dir(j, i, false);
  std::error_code ec;
  std::filesystem::remove_all(stage, ec);
  Status st;
  std::vector<uint8_t> bytes;
  HlodTree tree;
  try {
    HlodBakeSettings bs;
    bs.min_verts = j.settings.min_verts;
    bs.threads = j.settings.threads;
    HlodBakeResult br;
    auto notes = [&](const std::string& line) {  // its own notes, not its percentages
      if (line.rfind("hlod " + m.name + " ", 0) != 0 || line.back() != '%') j.say(j.label(i) + ": " + line);
    };
    st = bake_hlod_file(m.mesh, m.name, stage, bs, notes, &br);
    if (st) j.before_store("model " + m.name);
    if (st) st = store_hlod_model(j.settings.cache_dir, m.key, br.file, m.name, m.source_hash, bytes, &tree);
    if (st) j.stored.fetch_add(1), j.work.bytes_stored += bytes.size();
    if (st) st = write_file_atomic(j.out_dir / (m.name + ".hlod"), bytes);
  } catch (const std::exception& e) {
    st = Status::error(e.what());
  }
  std::filesystem::remove_all(stage, ec);
  f.seconds = seconds_since(t0);
  f.cpu_seconds = process_cpu_seconds() - cpu0;
  j.work.bake_seconds += f.seconds;
  j.work.bake_cpu_seconds += f.cpu_seconds;
  if (!st) {
    j.failed(f, st.message);
  } else {
    take_tree(f, tree, bytes.size());
    ++j.work.baked;
    j.work.triangles += tree.source_triangles;
    j.work.estimated += m.estimate;
  }
  j.figures.push_back(std::move(f));
  j.figure_model.push_back(i);
}

// One model by all ranks together; rank 0 takes the file into the cache and copies it to DIR.
void bake_split(Job& j, size_t i) {
  const Model& m = j.models[i];
  HlodModelFigures f = j.figures_of(i, HlodModelRoute::split);
  HlodDistributedSettings ds;
  ds.min_verts = j.settings.min_verts;
  ds.threads = j.settings.threads;
  ds.subtrees = j.settings.subtrees;
  ds.cache_dir = j.settings.cache_dir;
  ds.held_entry_bytes = j.settings.held_entry_bytes;
  ds.before_store = [&j, name = m.name](size_t subtree, size_t) {
    j.before_store("model " + name + " subtree " + std::to_string(subtree));
    j.stored.fetch_add(1);
  };
  const std::filesystem::path stage = stage_dir(j, i, true);  // rank 0 writes there
  auto say = [&j, name = m.name](const std::string& line) { j.say("model " + name + ": " + line); };
  HlodDistributedResult dr;
  Status st = bake_hlod_distributed(m.mesh, m.name, stage, ds, j.comm, say, &dr);
  if (j.comm.rank != 0) {
    if (!st) {  // rank 0 has it too (the split bake gathers every rank's failure); count it here
      ++j.work.failed;
      if (j.first_error.empty()) j.first_error = "model " + m.name + ": " + st.message;
    }
    return;
  }
  std::vector<uint8_t> bytes;
  HlodTree tree;
  try {
    if (st) j.before_store("model " + m.name);
    if (st) st = store_hlod_model(j.settings.cache_dir, m.key, dr.file, m.name, m.source_hash, bytes, &tree);
    if (st) j.stored.fetch_add(1), j.work.bytes_stored += bytes.size();
    if (st) st = write_file_atomic(j.out_dir / (m.name + ".hlod"), bytes);
  } catch (const std::exception& e) {
    st = Status::error(e.what());
  }
  std::error_code ec;
  std::filesystem::remove_all(stage, ec);
  f.seconds = dr.total_seconds;
  f.cpu_seconds = dr.critical_cpu_seconds;
  for (size_t r = 0; r < dr.ranks.size() && r < j.split_cpu.size(); ++r) {
    const HlodRankWork& w = dr.ranks[r];
    j.split_cpu[r] += w.load_cpu_seconds + w.clean_cpu_seconds + w.plan_cpu_seconds + w.check_cpu_seconds +
                      w.bake_cpu_seconds + w.measure_cpu_seconds + w.write_cpu_seconds;
  }
  if (st) take_tree(f, tree, bytes.size());
  else j.failed(f, st.message);
  j.figures.push_back(std::move(f));
  j.figure_model.push_back(i);
}

// ---- the final report: status, work, the figures of the models a rank handled ----

template <class Work, class F>
void each_number(Work& w, F&& f) {
  f(w.baked), f(w.checked), f(w.failed), f(w.triangles), f(w.estimated), f(w.check_cpu_seconds), f(w.bake_seconds),
      f(w.bake_cpu_seconds), f(w.cpu_seconds), f(w.total_seconds), f(w.bytes_stored);
}

std::vector<uint8_t> encode_report(const Job& j) {
  detail::ByteWriter w;
  each_number(j.work, [&](const auto& v) {
    if constexpr (std::is_same_v<std::decay_t<decltype(v)>, double>) w.u64(std::bit_cast<uint64_t>(v));
    else w.u64(uint64_t(v));
  });
  w.u64(j.figures.size());
  for (size_t k = 0; k < j.figures.size(); ++k) {
    const HlodModelFigures& f = j.figures[k];
    w.u64(j.figure_model[k]);
    w.u8(uint8_t(f.route));
    w.u64(uint64_t(int64_t(f.rank)));
    w.u64(f.source_triangles), w.u64(f.nodes), w.u64(f.bytes);
    w.u64(std::bit_cast<uint64_t>(f.seconds)), w.u64(std::bit_cast<uint64_t>(f.cpu_seconds));
    put_str(w, f.error);
  }
  return std::move(w.bytes);
}

// Rank 0: one rank's report into the result; false when malformed.
bool decode_report(const std::vector<uint8_t>& b, size_t models, HlodModelsResult& r) {
  Reader in{b};
  HlodModelsRankWork work;
  each_number(work, [&](auto& v) {
    if constexpr (std::is_same_v<std::decay_t<decltype(v)>, double>) v = in.f64();
    else v = static_cast<std::decay_t<decltype(v)>>(in.u64());
  });
  const uint64_t count = in.u64();
  if (!in.ok || count > models) return false;
  for (uint64_t k = 0; k < count && in.ok; ++k) {
    const uint64_t i = in.u64();
    const uint8_t route = in.u8();
    HlodModelFigures f;
    f.rank = int32_t(int64_t(in.u64()));
    f.source_triangles = in.u64(), f.nodes = in.u64(), f.bytes = in.u64();
    f.seconds = in.f64(), f.cpu_seconds = in.f64();
    f.error = in.str();
    if (!in.ok || i >= models || route > uint8_t(HlodModelRoute::failed)) return false;
    f.route = HlodModelRoute(route);
    f.name = r.models[i].name, f.mesh = r.models[i].mesh, f.estimated_triangles = r.models[i].estimated_triangles;
    r.models[i] = std::move(f);
  }
  if (!in.ok || in.at != b.size()) return false;
  r.ranks.push_back(work);
  return true;
}

// Rank 0: the job's figures and status from every rank's report.
Status take_reports(Job& j, const std::vector<std::vector<uint8_t>>& reports, HlodModelsResult& r) {
  Status st;
  for (size_t i = 0; i < j.models.size(); ++i) {
    HlodModelFigures f = j.figures_of(i, HlodModelRoute::failed);
    f.rank = -1;
    f.error = "model " + f.name + " (" + f.mesh.string() + "): not baked (the job stopped before it)";
    r.models.push_back(std::move(f));
  }
  for (size_t k = 0; k < reports.size(); ++k)
    if (!decode_report(reports[k], j.models.size(), r)) {
      st = Status::error("rank " + std::to_string(k) + " sent a malformed report");
      r.ranks.resize(k + 1);
    }
  for (size_t k = 0; k < r.ranks.size() && k < j.split_cpu.size(); ++k) r.ranks[k].split_cpu_seconds = j.split_cpu[k];
  double slowest = 0, slowest_whole = 0, sum = 0, sum_whole = 0, critical = 0;
  for (const HlodModelsRankWork& w : r.ranks) {
    slowest = std::max(slowest, w.bake_cpu_seconds + w.split_cpu_seconds), sum += w.bake_cpu_seconds + w.split_cpu_seconds;
    slowest_whole = std::max(slowest_whole, w.bake_cpu_seconds), sum_whole += w.bake_cpu_seconds;
    critical = std::max(critical, w.check_cpu_seconds + w.bake_cpu_seconds);
  }
  const double n = double(std::max<size_t>(1, r.ranks.size()));
  r.balance_cpu = sum > 0 ? slowest / (sum / n) : 1.0;
  r.balance_whole_cpu = sum_whole > 0 ? slowest_whole / (sum_whole / n) : 1.0;
  std::string first;
  for (const HlodModelFigures& f : r.models) {
    r.cached += f.route == HlodModelRoute::cached, r.whole += f.route == HlodModelRoute::whole;
    r.split += f.route == HlodModelRoute::split, r.failed += f.route == HlodModelRoute::failed;
    if (f.route == HlodModelRoute::split) critical += f.cpu_seconds;
    if (f.route != HlodModelRoute::failed) r.source_triangles += f.source_triangles;
    else if (first.empty()) first = f.error;
  }
  r.critical_cpu_seconds = critical;
  if (!st) return st;
  if (r.failed == 0) return Status::success();
  return Status::error(std::to_string(r.failed) + " of " + std::to_string(r.models.size()) + " models failed (first: " +
                       first + "; the cache keeps every finished model: run again to resume)");
}

}  // namespace

uint64_t estimate_mesh_triangles(const std::filesystem::path& mesh_file) {
  RegularFile file;
  std::vector<uint8_t> first;
  if (!open_regular_file(mesh_file, kInputFileLimit, file) || file.size == 0 || !file.read_head(16 * 1024, first)) return 0;
  const uint64_t size = file.size;
  const std::string head(first.begin(), first.end());
  const std::string ext = lower(mesh_file.extension().string());
  uint64_t n = 0;
  if (ext == ".ply") n = ply_faces(head);
  if (ext == ".off") n = off_faces(head);
  if (ext == ".stl" && head.size() >= 84) {  // binary: 80 bytes, a count, 50 bytes a triangle
    const uint64_t count = detail::load_u32(reinterpret_cast<const uint8_t*>(head.data()) + 80);
    if (84 + 50 * count == size) n = count;
    else n = size / 250;  // ASCII: "facet normal ... endfacet" ~250 bytes
  }
  if (ext == ".obj") n = size / 36;  // ~half a "v x y z" and one "f a b c" line a triangle
  return n ? n : std::max<uint64_t>(1, uint64_t(size / 24));
}

Status hlod_model_names_unique(const std::vector<std::filesystem::path>& meshes) {
  std::map<std::string, size_t> first;
  for (size_t i = 0; i < meshes.size(); ++i) {
    const auto [at, added] = first.emplace(meshes[i].stem().string(), i);
    if (!added)
      return Status::error("two models named '" + at->first + "' (" + meshes[at->second].string() + ", " +
                           meshes[i].string() + ") would write one .hlod file");
  }
  return Status::success();
}

std::vector<int> plan_hlod_models(const std::vector<uint64_t>& costs, const std::vector<uint8_t>& missing, int ranks) {
  const int r = std::max(1, ranks);
  std::vector<int> plan(costs.size(), kHlodModelNotBaked);
  std::vector<size_t> left;
  unsigned __int128 total = 0;
  for (size_t i = 0; i < costs.size(); ++i)
    if (i < missing.size() && missing[i]) left.push_back(i), total += costs[i];
  std::vector<size_t> whole;
  for (size_t i : left) {
    if (left.size() == 1 || (unsigned __int128)costs[i] * unsigned(r) > total) plan[i] = kHlodModelSplit;
    else whole.push_back(i);
  }
  std::vector<uint64_t> whole_costs;
  for (size_t i : whole) whole_costs.push_back(costs[i]);
  const std::vector<int> owner = assign_subtrees(whole_costs, r);
  for (size_t k = 0; k < whole.size(); ++k) plan[whole[k]] = owner[k];
  return plan;
}

Status bake_hlod_models_distributed(const std::vector<std::filesystem::path>& meshes,
                                    const std::filesystem::path& out_dir, const HlodModelsSettings& settings,
                                    const HlodRankComm& comm, const HlodBakeLog& log, HlodModelsResult* result) {
  const auto t_start = Clock::now();
  const double cpu_start = process_cpu_seconds();
  if (result) *result = {};
  // The same on every rank, before any collective: one .hlod name per model.
  if (Status s = hlod_model_names_unique(meshes); !s) return s;
  Job j(settings, comm, log, out_dir);
  for (const auto& m : meshes) j.models.push_back({m, m.stem().string()});
  j.split_cpu.assign(size_t(j.ranks()), 0.0);
  tbb::task_arena arena(settings.threads == 0 ? tbb::task_arena::automatic : int(settings.threads));

  std::error_code ec;
  std::filesystem::create_directories(settings.cache_dir, ec);
  Status ready = ec ? Status::error(settings.cache_dir.string() + ": cannot create the cache directory: " + ec.message())
                    : Status::success();
  std::filesystem::create_directories(out_dir, ec);
  if (ready && ec) ready = Status::error(out_dir.string() + ": cannot create the output directory: " + ec.message());
  // Before any work: every rank must see rank 0's cache and output folders.
  if (Status shared = check_shared_folders({{"cache folder", settings.cache_dir}, {"output folder", out_dir}}, comm);
      ready && !shared)
    ready = shared;
  if (Status s = share_estimates(j); ready && !s) ready = s;
  if (!ready) ready.message = "rank " + std::to_string(comm.rank) + ": " + ready.message;
  std::vector<uint8_t> check = ready ? check_share(j, arena) : std::vector<uint8_t>{};
  check.push_back(ready ? 1 : 0);
  const std::vector<std::vector<uint8_t>> checks = comm.gather(check);
  std::vector<uint8_t> merged = comm.rank == 0 ? merge_checks(j, checks) : std::vector<uint8_t>{};
  comm.broadcast(merged);
  const size_t n = j.models.size();
  const bool go = ready && merged.size() == 9 * n + 1 && merged.back() == 1;
  if (ready && !go) ready = Status::error("rank " + std::to_string(comm.rank) + ": a rank could not check the cache");
  std::vector<int> plan(n, kHlodModelNotBaked);
  if (go) {
    std::vector<uint8_t> missing(n, 0);
    for (size_t i = 0; i < n; ++i) {
      Model& m = j.models[i];
      m.state = merged[9 * i];
      m.source_hash = detail::load_u64(merged.data() + 9 * i + 1);
      m.key = hlod_model_key(m.source_hash, m.name);
      missing[i] = m.state == kMissing;
    }
    plan = plan_hlod_models(costs(j), missing, j.ranks());
  }
  {
    std::unique_ptr<CacheProgress> progress;  // rank 0, until every model is baked
    if (go && comm.rank == 0 && log) {
      std::vector<std::filesystem::path> paths;
      std::vector<uint64_t> tris;
      size_t cached = 0;
      for (const Model& m : j.models) {
        cached += m.state == kFound;
        if (m.state == kMissing) paths.push_back(hlod_model_entry_path(settings.cache_dir, m.key)), tris.push_back(m.estimate);
      }
      progress = std::make_unique<CacheProgress>("models", std::move(paths), std::move(tris), n, cached,
                                                 [&j](const std::string& line) { j.say(line); });
    }
    for (size_t i = 0; i < n; ++i)
      if (plan[i] == comm.rank) bake_whole(j, i);
    for (size_t i = 0; i < n; ++i)  // every rank, in the same order
      if (plan[i] == kHlodModelSplit) bake_split(j, i);
  }
  j.work.total_seconds = seconds_since(t_start);
  j.work.cpu_seconds = process_cpu_seconds() - cpu_start;
  const std::vector<std::vector<uint8_t>> reports = comm.gather(encode_report(j));
  Status st = ready;
  if (comm.rank == 0) {
    HlodModelsResult r;
    const Status taken = take_reports(j, reports, r);
    if (st) st = taken;
    r.total_seconds = seconds_since(t_start);
    if (result) *result = std::move(r);
  } else if (st && j.work.failed) {
    st = Status::error("rank " + std::to_string(comm.rank) + ": " + std::to_string(j.work.failed) +
                       " models failed here (first: " + j.first_error + ")");
  }
  return st;
}

}  // namespace lod
