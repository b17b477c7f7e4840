#include "jobs/scene_hlod_bake.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>

#include "jobs/hlod_bake.h"  // tbb_parallel_for
#include "preprocess/scene_hlod_build.h"
#include "runtime/world_bounds.h"

namespace lod {

namespace {

// Scene objects of blocks without motion, in scene order (place_instances: block by block).
std::vector<uint32_t> static_objects(const SceneConfig& config, size_t object_count) {
  std::vector<uint32_t> ids;
  uint32_t at = 0;
  for (const InstanceConfig& block : config.instances) {
    for (uint32_t k = 0; k < block.count && at < object_count; ++k, ++at)
      if (block.motion.kind == MotionKind::none) ids.push_back(at);
  }
  return ids;
}

// Per depth: proxies, their triangles, objects per proxy, error range (world units).
void log_depths(const SceneHlodTree& t, const ProgressLog& log) {
  for (uint32_t d = 0; d <= kSceneHlodMaxDepth; ++d) {
    size_t n = 0, tris = 0, objects = 0;
    float lo = INFINITY, hi = 0;
    for (const SceneHlodNode& node : t.nodes) {
      if (node.depth != d) continue;
      ++n, tris += node.triangles(), objects += node.object_count;
      lo = std::min(lo, node.error), hi = std::max(hi, node.error);
    }
    if (n == 0) break;
    char buf[200];
    std::snprintf(buf, sizeof buf, "  depth %2u: %6zu proxies, %9zu triangles, %7.1f objects each, error %.3g..%.3g",
                  d, n, tris, double(objects) / double(n), double(lo), double(hi));
    log(buf);
  }
}

}  // namespace

Status bake_scene_hlod(const SceneConfig& config, const Scene& scene, const ProgressLog& log, SceneHlodTree& out) {
  out = SceneHlodTree{};
  if (!config.scene_hlod.enabled) return Status::success();
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<uint32_t> ids = static_objects(config, scene.objects.size());
  std::vector<Sphere> model_spheres;
  for (const LodChain& c : scene.chains) model_spheres.push_back(chain_sphere(c));
  std::vector<uint32_t> model(ids.size());
  std::vector<Transform> transform(ids.size());
  std::vector<Sphere> sphere(ids.size());
  for (size_t j = 0; j < ids.size(); ++j) {
    model[j] = scene.objects.model[ids[j]];
    transform[j] = transform_of(scene.objects, ids[j]);
    sphere[j] = world_sphere(transform[j], model_spheres[model[j]]);  // as the store computes it
  }
  SceneHlodSettings settings;
  settings.min_objects = config.scene_hlod.min_objects;
  settings.reduction = config.scene_hlod.reduction;
  SceneHlodObjectsIn in{scene.chains, model, transform, sphere, ids};
  std::mutex m;
  size_t told = 0;
  auto progress = [&](size_t done, size_t total) {
    if (!log) return;
    std::lock_guard lock(m);
    if (done * 10 / total == told * 10 / total && done != total) return;
    told = done;
    log("scene hlod: " + std::to_string(done) + " / " + std::to_string(total) + " proxies");
  };
  if (Status st = build_scene_hlod(in, settings, tbb_parallel_for(), progress, out); !st) return st;
  if (log) {
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    char buf[256];
    std::snprintf(buf, sizeof buf, "scene hlod: %zu proxies over %zu static objects, %zu proxy triangles, in %.0f ms",
                  out.nodes.size(), ids.size(), out.indices.size() / 3, ms);
    log(buf);
    log_depths(out, log);
  }
  return Status::success();
}

}  // namespace lod
