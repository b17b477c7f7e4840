// What needs the bake side of lodkit (lodkit::lodkit): services made from scene configs, and
// the mesh baker that add_model uses for mesh files.
#include <cstdio>
#include <filesystem>

#include "jobs/bake_jobs.h"
#include "jobs/cache_folder.h"
#include "jobs/hlod_scene.h"
#include "jobs/scene_hlod_bake.h"
#include "jobs/scene.h"
#include "jobs/scene_config.h"
#include "jobs/service.h"
#include "jobs/service_impl.h"
#include "preprocess/embree_occlusion.h"
#include "jobs/terrain_scene.h"
#include "runtime/lod_asset.h"
#include "runtime/view.h"

namespace lod {

FrameGraphOptions frame_graph_options(const SceneConfig& config) {
  FrameGraphOptions g;
  g.threads = config.threads;
  g.selection = config.selection;
  g.pixel_error = config.pixel_error;
  g.hysteresis = config.hysteresis;
  g.max_distance = config.max_distance;
  g.measure_quality = true;  // services from configs (lod run) report benefit and pixel error
  g.occlusion.enabled = config.occlusion;
  g.occlusion.occluders = config.occluders;
  if (config.occlusion_embree) g.occlusion.make_tracer = make_embree_occlusion_tracer;
  return g;
}

ModelBaker mesh_baker(std::vector<float> ratios) {
  return [ratios](const std::filesystem::path& mesh, const std::filesystem::path& cache_dir,
                  std::vector<uint8_t>& asset, std::string& error) {
    for (size_t i = 0; i < ratios.size(); ++i) {
      const bool culled = i > 0 && i + 1 == ratios.size() && ratios[i] == 0;  // the culled level
      if (!(culled || (ratios[i] > 0 && ratios[i] <= 1)) || (i == 0 && ratios[i] != 1) ||
          (i > 0 && !(ratios[i] < ratios[i - 1]))) {
        error = mesh.string() + ": baker ratios must start at 1 and decrease within (0, 1] (a last 0 culls)";
        return false;
      }
    }
    ModelConfig model;
    model.name = mesh.stem().string();
    model.file = mesh;
    model.bake.ratios = ratios;
    const std::filesystem::path cache =
        cache_dir.empty() ? std::filesystem::temp_directory_path() / "lodkit-cache" : cache_dir;
    std::vector<LodChain> chains;
    BakeSummary summary;
    if (auto st = bake_scene_models({model}, cache, 0, chains, summary, nullptr); !st) {
      error = st.message;
      return false;
    }
    asset = encode_lod_asset(chains.at(0));
    return true;
  };
}

std::unique_ptr<Service> Service::from_config(const std::filesystem::path& config, std::string* error,
                                              const std::filesystem::path& data_dir,
                                              const std::filesystem::path& cache_dir) {
  auto failed = [&](const std::string& message) {
    if (error) *error = message;
    return std::unique_ptr<Service>();
  };
  const std::filesystem::path data = data_dir.empty() ? default_data_dir() : data_dir;
  SceneConfig sc;
  if (auto st = load_scene_config(config, data, sc, /*objects_optional=*/true); !st) return failed(st.message);
  const std::filesystem::path cache = cache_dir_for(cache_dir, sc.cache_dir);
  auto hlod = std::make_shared<HlodModels>();
  if (auto st = bake_hlod_models(sc, cache, nullptr, *hlod); !st) return failed(st.message);
  sc = discrete_part(sc);  // hlod models are drawn by the hlod node, not as objects
  std::vector<LodChain> chains;
  BakeSummary summary;
  if (auto st = bake_scene_models(sc.models, cache, sc.threads, chains, summary, nullptr); !st)
    return failed(st.message);
  Scene scene = make_scene(sc, std::move(chains));
  FrameGraphOptions options = frame_graph_options(sc);
  if (auto st = load_scene_terrain(sc, options.terrain); !st) return failed(st.message);
  if (options.terrain) place_on_terrain(scene, sc, *options.terrain);  // before the scene HLOD
  if (!hlod->empty()) options.hlod = hlod;
  auto scene_hlod = std::make_shared<SceneHlodTree>();
  if (auto st = bake_scene_hlod(sc, scene, nullptr, *scene_hlod); !st) return failed(st.message);
  if (!scene_hlod->empty()) options.scene_hlod = scene_hlod;
  std::unique_ptr<Service> s = make_service(scene, options, sc.rate_hz);
  Impl& m = s->impl();
  m.options.cache_dir = cache;
  m.options.baker = mesh_baker();
  lod::set_view(*s, 0, view_at(sc.camera, 0));
  return s;
}

}  // namespace lod
