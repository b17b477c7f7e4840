// Bake jobs: every model of a scene baked in parallel on oneTBB, cached by content hash.
#pragma once
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "jobs/scene_config.h"
#include "preprocess/lod_bake.h"
#include "runtime/lod_chain.h"
#include "runtime/status.h"

namespace lod {

struct BakeJobResult {
  std::string model;
  bool from_cache = false;
  double ms = 0;
  size_t input_triangles = 0;
  size_t levels = 0;
  BakeReport report;  // empty when from_cache
};

struct BakeSummary {
  double ms = 0;                 // wall time of the whole bake step
  size_t baked = 0;              // models actually baked (not from cache)
  size_t cached = 0;
  std::vector<BakeJobResult> jobs;
};

// Progress lines ("bake bunny 40% simplify") go to `log` from one thread at a time.
using ProgressLog = std::function<void(const std::string&)>;

// Loads `cache_dir/<name>-<key>.lod` when present and valid, otherwise bakes and writes it; a
// model whose file is a .lod asset is read as it is (counted as cached).
// `threads` = 0 uses all cores. On failure the status names the model and file; nothing
// is written for a model that failed.
Status bake_scene_models(const std::vector<ModelConfig>& models, const std::filesystem::path& cache_dir,
                         uint32_t threads, std::vector<LodChain>& chains, BakeSummary& summary,
                         const ProgressLog& log);

}  // namespace lod
