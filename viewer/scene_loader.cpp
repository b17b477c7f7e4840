#include "viewer/scene_loader.h"

#include <cstdlib>
#include <utility>
#include <vector>

#include "jobs/cache_folder.h"
#include "jobs/hlod_scene.h"
#include "jobs/scene_hlod_bake.h"
#include "jobs/terrain_scene.h"

namespace lod::viewer {

Status load_scene(const std::filesystem::path& config_file, const std::filesystem::path& data_dir,
                  const std::filesystem::path& cache_dir, LoadedScene& out, const ProgressLog& log) {
  const std::filesystem::path data = data_dir.empty() ? default_data_dir() : data_dir;
  if (Status st = load_scene_config(config_file, data, out.config); !st) return st;
  out.cache_dir = cache_dir_for(cache_dir, out.config.cache_dir);  // the rule lod run and the service follow
  out.hlod = std::make_shared<HlodModels>();
  size_t hlod_baked = 0, hlod_cached = 0;
  if (Status st = bake_hlod_models(out.config, out.cache_dir, log, *out.hlod, &hlod_baked, &hlod_cached); !st)
    return st;
  out.config = discrete_part(out.config);
  std::vector<LodChain> chains;
  if (Status st = bake_scene_models(out.config.models, out.cache_dir, out.config.threads, chains, out.bake, log); !st)
    return st;
  out.bake.baked += hlod_baked;
  out.bake.cached += hlod_cached;
  out.scene = make_scene(out.config, std::move(chains));
  if (Status st = load_scene_terrain(out.config, out.terrain); !st) return st;
  if (out.terrain) place_on_terrain(out.scene, out.config, *out.terrain);  // before the scene HLOD
  out.scene_hlod = std::make_shared<SceneHlodTree>();
  return bake_scene_hlod(out.config, out.scene, log, *out.scene_hlod);
}

}  // namespace lod::viewer
