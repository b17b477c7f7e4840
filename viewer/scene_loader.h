// The viewer's way to a Scene, the same as `lod run`: parse the config, bake what it needs
// (cached by content hash), place the instances; models with hlod = true become streamed HLOD
// models (`hlod`) and the scene holds the rest.
#pragma once
#include <filesystem>
#include <memory>
#include <string>

#include "jobs/bake_jobs.h"
#include "jobs/hlod_models.h"
#include "runtime/scene_hlod_tree.h"
#include "jobs/scene.h"
#include "jobs/scene_config.h"
#include "runtime/status.h"
#include "runtime/terrain_lod.h"

namespace lod::viewer {

struct LoadedScene {
  SceneConfig config;                    // without its hlod models (discrete_part)
  Scene scene;
  std::shared_ptr<HlodModels> hlod;      // never null; empty when the config has none
  std::shared_ptr<SceneHlodTree> scene_hlod;  // never null; empty unless [scene_hlod] enabled
  std::shared_ptr<const TerrainModel> terrain;  // [[terrain]], null without; on_terrain objects stand on it
  BakeSummary bake;
  std::filesystem::path cache_dir;
};

// `data_dir` empty = lod::default_data_dir(); `cache_dir` empty = the config's [cache] dir, else cache_dir_for's default.
// On failure the status carries the config's or the baker's message unchanged.
Status load_scene(const std::filesystem::path& config_file, const std::filesystem::path& data_dir,
                  const std::filesystem::path& cache_dir, LoadedScene& out, const ProgressLog& log);

}  // namespace lod::viewer
