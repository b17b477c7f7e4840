// Bake jobs: one task per model on oneTBB; an asset named by the bake key is a cache hit.
#include "jobs/bake_jobs.h"

#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <mutex>

#include "jobs/annotated_parallel_for.h"
#include "preprocess/position_copies.h"
#include "preprocess/vertex_hierarchy.h"
#include "runtime/lod_asset.h"

namespace lod {
namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::string hex64(uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

// Serialises log lines from the bake tasks.
class LogLines {
 public:
  explicit LogLines(const ProgressLog& log) : log_(log) {}
  void line(const std::string& text) {
    if (!log_) return;
    std::lock_guard lock(mutex_);
    log_(text);
  }

 private:
  const ProgressLog& log_;
  std::mutex mutex_;
};

struct BakeTask {
  LodChain chain;
  BakeJobResult result;
  Status status;
};

// Level 0 as the hierarchy's input: positions, indices, uvs (both sets), colours, material runs
// and its normals when they are authored (computed ones are left out: the front computes its
// own from the shown faces, which follow the coarser shapes better).
MeshData level0_mesh(const LodChain& chain, const std::string& source) {
  const LodLevel& l0 = chain.levels.at(0);
  MeshData mesh;
  mesh.source = source;
  mesh.positions.assign(chain.positions.begin() + 3 * size_t(l0.first_vertex),
                        chain.positions.begin() + 3 * size_t(l0.first_vertex + l0.vertex_count));
  mesh.indices.assign(chain.indices.begin() + l0.first_index,
                      chain.indices.begin() + l0.first_index + l0.index_count);
  auto level0 = [&](const std::vector<float>& column, size_t width, std::vector<float>& out) {
    if (!column.empty())
      out.assign(column.begin() + width * size_t(l0.first_vertex),
                 column.begin() + width * size_t(l0.first_vertex + l0.vertex_count));
  };
  level0(chain.uvs, 2, mesh.uvs);
  level0(chain.uvs1, 2, mesh.uvs1);
  level0(chain.colors, 4, mesh.colors);
  if (chain.authored_normals) level0(chain.normals, 3, mesh.normals);
  for (const LevelSubmesh& run : level_submeshes(chain, 0))
    mesh.submeshes.push_back({run.first_index / 3, run.index_count / 3, run.material});  // level-local
  return mesh;
}

// A tree built before attribute seams were pinned collapsed each side of a seam alone (cracks,
// smeared uvs) and carries no uvs: rebuilt wherever level 0 has seams, uvs or materials.
bool hierarchy_predates_seams(const LodChain& chain, const MeshData& level0) {
  if (chain.hierarchy.seams_pinned) return false;
  if (!level0.uvs.empty() || !chain.materials.empty()) return true;
  std::vector<uint32_t> first(level0.vertex_count());
  find_position_copies(first, {}, level0.positions.data(), first.size());
  for (size_t v = 0; v < first.size(); ++v)
    if (first[v] != v) return true;
  return false;
}

// A tree (seams pinned) from a build that kept only uvs, where level 0 has a second uv set,
// colours or authored normals (format 10's named assets): rebuilt, so nothing is dropped from
// the hierarchy.
bool hierarchy_lacks_attributes(const LodChain& chain) {
  const VertexTree& t = chain.hierarchy;
  return (!chain.uvs1.empty() && t.uvs1.empty()) || (!chain.colors.empty() && t.colors.empty()) ||
         (chain.authored_normals && t.normals.empty());
}

std::string hierarchy_attribute_names(const VertexTree& t) {
  std::string s;
  if (!t.uvs.empty()) s += ", uvs";
  if (!t.uvs1.empty()) s += ", TEXCOORD_1";
  if (!t.colors.empty()) s += ", colours";
  if (!t.normals.empty()) s += ", normals";
  return s.empty() ? s : ", with" + s.substr(1);
}

// View-dependent models need level 0's vertex hierarchy (built once, then kept in the cached
// asset); other models drop one a shared cache file may carry.
Status ensure_hierarchy(const ModelConfig& model, const std::filesystem::path* rewrite, LogLines& log,
                        LodChain& chain) {
  if (!model.view_dependent) {
    chain.hierarchy = VertexTree{};
    return Status::success();
  }
  if (chain.hierarchy.seams_pinned && !hierarchy_lacks_attributes(chain)) return Status::success();
  const MeshData mesh = level0_mesh(chain, model.file.string());
  if (!chain.hierarchy.empty()) {
    if (chain.hierarchy.seams_pinned)
      log.line("bake " + model.name +
               ": vertex hierarchy built before it kept TEXCOORD_1, colours and normals, rebuilding");
    else if (hierarchy_predates_seams(chain, mesh))
      log.line("bake " + model.name +
               ": vertex hierarchy built before attribute seams were pinned, rebuilding");
    else
      return Status::success();
  }
  const auto t0 = std::chrono::steady_clock::now();
  HierarchyOptions options;
  options.parts = model.vd_parts;
  if (Status s = build_vertex_hierarchy(chain.hierarchy, mesh, options); !s) return s;
  char ms[32];
  std::snprintf(ms, sizeof ms, "%.0f", ms_since(t0));
  log.line("bake " + model.name + ": vertex hierarchy of " + std::to_string(chain.hierarchy.node_count()) +
           " nodes in " + ms + " ms" + hierarchy_attribute_names(chain.hierarchy));
  return rewrite ? write_lod_asset(*rewrite, chain) : Status::success();
}

// "model NAME (FILE): message", without naming the file twice when preprocess/ already did.
std::string model_error(const ModelConfig& model, const std::string& message) {
  // Messages from the bake already name the file, or the model and the file: name each once.
  const std::string file = model.file.string();
  const std::string both = model.name + " (" + file + ")";
  if (message.compare(0, both.size(), both) == 0) return "model " + message;
  if (message.compare(0, file.size(), file) == 0) return "model " + model.name + ": " + message;
  return "model " + both + ": " + message;
}

bool names_lod_asset(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".lod";
}

// A model whose file is an asset already baked: read as it is, never rebaked or cached (its
// own bake settings decided its levels). Counted with the cached ones: nothing was baked.
void load_baked_asset(const ModelConfig& model, LogLines& log, BakeTask& task) {
  const auto t0 = std::chrono::steady_clock::now();
  LodChain chain;
  if (Status s = read_lod_asset(model.file, chain); !s) {
    task.status = Status::error(model_error(model, s.message));
    return;
  }
  if (Status h = ensure_hierarchy(model, nullptr, log, chain); !h) {
    task.status = Status::error(model_error(model, h.message));
    return;
  }
  chain.name = model.name;  // the scene's name for it, as for every other model
  task.chain = std::move(chain);
  task.result.from_cache = true;
  task.result.levels = task.chain.levels.size();
  task.result.input_triangles = task.chain.levels.empty() ? 0 : task.chain.levels[0].triangles();
  task.result.ms = ms_since(t0);
  log.line("bake " + model.name + ": baked asset " + model.file.string() + " loaded as is");
}

void bake_one(const ModelConfig& model, const std::filesystem::path& cache_dir, LogLines& log,
              BakeTask& task) {
  const auto t0 = std::chrono::steady_clock::now();
  task.result.model = model.name;
  if (names_lod_asset(model.file)) return load_baked_asset(model, log, task);

  Status key_status;
  const uint64_t key = bake_key(model.file, model.bake, &key_status);
  if (!key_status) {
    task.status = Status::error(model_error(model, key_status.message));
    return;
  }
  // A hierarchy cut into parts is another asset (the levels are the same; the tree is not).
  const std::string parts = model.view_dependent && model.vd_parts > 1 ? "-p" + std::to_string(model.vd_parts) : "";
  const std::filesystem::path asset = cache_dir / (model.name + "-" + hex64(key) + parts + ".lod");

  std::error_code ec;
  if (std::filesystem::exists(asset, ec)) {
    LodChain cached;
    const Status read = read_lod_asset(asset, cached);
    if (read && cached.source_hash == key) {
      if (Status h = ensure_hierarchy(model, &asset, log, cached); !h) {
        task.status = Status::error(model_error(model, h.message));
        return;
      }
      task.chain = std::move(cached);
      task.result.from_cache = true;
      task.result.levels = task.chain.levels.size();
      task.result.input_triangles = task.chain.levels.empty() ? 0 : task.chain.levels[0].triangles();
      task.result.ms = ms_since(t0);
      log.line("bake " + model.name + ": cached " + asset.string());
      return;
    }
    log.line("bake " + model.name + ": cache file " + asset.string() + " unusable (" +
             (read ? std::string("hash mismatch") : read.message) + "), rebaking");
  }

  // Progress lines every 10 %, from whichever thread bake_model reports on.
  std::atomic<int> last_decile{-1};
  const BakeProgress progress = [&](float fraction, const char* what) {
    const int decile = static_cast<int>(std::clamp(fraction, 0.f, 1.f) * 10);
    int seen = last_decile.load();
    do {
      if (decile <= seen) return;
    } while (!last_decile.compare_exchange_weak(seen, decile));
    log.line("bake " + model.name + " " + std::to_string(decile * 10) + "% " + (what ? what : ""));
  };
  LodChain chain;
  BakeReport report;
  // Inside one model too, idle cores help (QEM halves, level measurements); results are the
  // same as serially. Runs in the caller's arena, so the configured thread count holds.
  BakeSettings settings = model.bake;
  settings.parallel_for = [](size_t count, const std::function<void(size_t)>& body) {
    detail::annotated_parallel_for(count, body);
  };
  const Status baked = bake_model(model.file, model.name, settings, chain, &report, progress);
  if (!baked) {
    task.status = Status::error(model_error(model, baked.message));
    return;
  }
  if (Status h = ensure_hierarchy(model, nullptr, log, chain); !h) {
    task.status = Status::error(model_error(model, h.message));
    return;
  }
  const Status written = write_lod_asset(asset, chain);
  if (!written) {
    task.status = Status::error("model " + model.name + ": cannot write its cache: " + written.message);
    return;
  }
  task.result.levels = chain.levels.size();
  task.result.input_triangles = report.input_triangles;
  task.result.report = std::move(report);
  task.chain = std::move(chain);
  task.result.ms = ms_since(t0);
  char ms[32];
  std::snprintf(ms, sizeof ms, "%.0f", task.result.ms);
  log.line("bake " + model.name + ": " + std::to_string(task.result.levels) + " levels in " + ms + " ms -> " +
           asset.string());
}

}  // namespace

Status bake_scene_models(const std::vector<ModelConfig>& models, const std::filesystem::path& cache_dir,
                         uint32_t threads, std::vector<LodChain>& chains, BakeSummary& summary,
                         const ProgressLog& log) {
  const auto t0 = std::chrono::steady_clock::now();
  std::error_code ec;
  std::filesystem::create_directories(cache_dir, ec);
  if (ec)
    return Status::error(cache_dir.string() + ": cannot create the bake cache directory: " + ec.message());

  std::vector<BakeTask> tasks(models.size());
  LogLines lines(log);
  tbb::task_arena arena(threads == 0 ? tbb::task_arena::automatic : static_cast<int>(threads));
  arena.execute([&] {
    detail::annotated_parallel_for(models.size(), [&](size_t i) {
      try {
        bake_one(models[i], cache_dir, lines, tasks[i]);
      } catch (const std::exception& e) {  // e.g. bad_alloc on a huge mesh: a status, not a crash
        tasks[i].status = Status::error("model " + models[i].name + " (" + models[i].file.string() + "): " + e.what());
      }
    });
  });

  BakeSummary s;
  std::vector<LodChain> out;
  for (BakeTask& t : tasks) {
    if (!t.status) return t.status;
    (t.result.from_cache ? s.cached : s.baked) += 1;
    s.jobs.push_back(std::move(t.result));
    out.push_back(std::move(t.chain));
  }
  s.ms = ms_since(t0);
  chains = std::move(out);
  summary = std::move(s);
  return Status::success();
}

}  // namespace lod
