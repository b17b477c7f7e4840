// HLOD models of a scene config: bake or reuse each .hlod, place its one object.
#include "jobs/hlod_scene.h"

#include <cstdio>

#include "jobs/hlod_bake.h"
#include "jobs/hlod_read_failures.h"
#include "jobs/scene.h"
#include "runtime/hlod_asset.h"

namespace lod {
namespace {

std::string hex64(uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

// The cached tree when it is current, else a fresh bake; `path` is the file either way.
Status cached_or_baked(const ModelConfig& m, const std::filesystem::path& cache_dir,
                       const std::function<void(const std::string&)>& log, HlodTree& tree,
                       std::filesystem::path& path, bool& from_cache) {
  if (m.file.extension() == ".hlod") {  // named directly: used as it is
    path = m.file;
    from_cache = true;
    if (Status s = read_hlod_tree(path, tree); !s) return Status::error("model " + m.name + ": " + s.message);
    if (log) log("model " + m.name + ": " + path.string() + " (" + std::to_string(tree.nodes.size()) + " nodes)");
    return Status::success();
  }
  uint64_t key = 0;
  if (Status s = hlod_source_hash(m.file, m.min_verts, key); !s) return Status::error("model " + m.name + ": " + s.message);
  const std::string stem = m.name + "-" + hex64(key);
  path = cache_dir / (stem + ".hlod");
  std::error_code ec;
  std::string bad;
  if (entry_marked_bad(path, &bad)) {
    // The head checks out, a payload behind it did not (found while streaming it).
    if (log) log("bake " + m.name + ": cache file " + path.string() + " was marked bad (" + bad + "), rebaking");
  } else if (std::filesystem::exists(path, ec)) {
    const Status read = read_hlod_tree(path, tree);
    if (read && tree.source_hash == key) {
      from_cache = true;
      if (log) log("bake " + m.name + ": cached " + path.string());
      return Status::success();
    }
    if (log) log("bake " + m.name + ": cache file " + path.string() + " unusable (" +
                 (read ? std::string("hash mismatch") : read.message) + "), rebaking");
  }
  HlodBakeSettings settings;
  settings.min_verts = m.min_verts;
  HlodBakeResult result;
  if (Status s = bake_hlod_file(m.file, stem, cache_dir, settings, log, &result); !s)
    return Status::error("model " + m.name + ": " + s.message);
  from_cache = false;
  clear_bad_mark(path);  // the fresh entry has replaced the bad one
  if (Status s = read_hlod_tree(path, tree); !s) return Status::error("model " + m.name + ": " + s.message);
  if (log) log("bake " + m.name + ": hlod of " + std::to_string(tree.nodes.size()) + " nodes -> " + path.string());
  return Status::success();
}

}  // namespace

SceneConfig discrete_part(const SceneConfig& config) {
  SceneConfig d = config;
  d.models.clear();
  d.instances.clear();
  std::vector<int64_t> renumber(config.models.size(), -1);
  for (size_t i = 0; i < config.models.size(); ++i) {
    if (config.models[i].hlod) continue;
    renumber[i] = int64_t(d.models.size());
    d.models.push_back(config.models[i]);
  }
  for (InstanceConfig inst : config.instances) {
    if (renumber[inst.model] < 0) continue;
    inst.model = uint32_t(renumber[inst.model]);
    d.instances.push_back(inst);
  }
  return d;
}

Status bake_hlod_models(const SceneConfig& config, const std::filesystem::path& cache_dir,
                        const std::function<void(const std::string&)>& log, HlodModels& out, size_t* baked,
                        size_t* cached) {
  HlodModels h;
  h.stream.budget_bytes = uint64_t(config.stream.budget_mb) << 20;
  h.stream.loader_threads = config.stream.loader_threads;
  size_t n_baked = 0, n_cached = 0;
  for (size_t i = 0; i < config.models.size(); ++i) {
    const ModelConfig& m = config.models[i];
    if (!m.hlod) continue;
    std::vector<Placement> placed;
    for (const InstanceConfig& inst : config.instances)
      if (inst.model == i) {
        const std::vector<Placement> block = place_block(inst);
        placed.insert(placed.end(), block.begin(), block.end());
      }
    if (placed.size() != 1)
      return Status::error("model " + m.name + ": hlod = true needs exactly one [[instances]] block with count = 1");
    HlodTree tree;
    std::filesystem::path path;
    bool from_cache = false;
    if (Status s = cached_or_baked(m, cache_dir, log, tree, path, from_cache); !s) return s;
    ++(from_cache ? n_cached : n_baked);
    h.names.push_back(m.name);
    h.trees.push_back(std::move(tree));
    h.files.push_back(path);
    h.cache_entry.push_back(m.file.extension() == ".hlod" ? 0 : 1);
    h.transforms.push_back(transform_of(placed[0]));
  }
  out = std::move(h);
  if (baked) *baked = n_baked;
  if (cached) *cached = n_cached;
  return Status::success();
}

}  // namespace lod
