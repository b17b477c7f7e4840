// Scene: placing every [[instances]] block and building the model table.
#include "jobs/scene.h"

#include "runtime/world_bounds.h"

#include <cassert>
#include <cmath>
#include <numbers>
#include <random>

namespace lod {
namespace {

// Uniform in [0, 1) from the top 53 bits: unlike std::uniform_real_distribution, the
// sequence is the same on every standard library, so a seed names one scene everywhere.
double unit(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

float lerp(float a, float b, double t) { return static_cast<float>(a + (static_cast<double>(b) - a) * t); }

}  // namespace

std::vector<Placement> place_block(const InstanceConfig& inst) {
  std::vector<Placement> out(inst.count);
  std::mt19937_64 rng(inst.seed);
  // Grid: ceil(sqrt(n)) columns along x, as many rows along z as needed, one object per
  // cell centre; y at the middle of the box.
  const uint32_t cols = std::max<uint32_t>(1, static_cast<uint32_t>(std::ceil(std::sqrt(double(inst.count)))));
  const uint32_t rows = std::max<uint32_t>(1, (inst.count + cols - 1) / cols);
  for (uint32_t i = 0; i < inst.count; ++i) {
    Placement& p = out[i];
    if (inst.grid) {
      p.position[0] = lerp(inst.box_min[0], inst.box_max[0], (i % cols + 0.5) / cols);
      p.position[1] = lerp(inst.box_min[1], inst.box_max[1], 0.5);
      p.position[2] = lerp(inst.box_min[2], inst.box_max[2], (i / cols + 0.5) / rows);
    } else {
      for (int a = 0; a < 3; ++a) p.position[a] = lerp(inst.box_min[a], inst.box_max[a], unit(rng));
    }
    p.yaw = static_cast<float>(2 * std::numbers::pi * unit(rng));
    p.scale = lerp(inst.scale_min, inst.scale_max, unit(rng));
  }
  return out;
}

Transform transform_of(const Placement& p) {
  Transform t;
  for (int a = 0; a < 3; ++a) t.position[a] = p.position[a];
  t.rotation[1] = std::sin(0.5f * p.yaw);
  t.rotation[3] = std::cos(0.5f * p.yaw);
  t.scale = p.scale;
  return t;
}

ObjectSet place_instances(const SceneConfig& config, const std::vector<LodChain>& chains) {
  size_t total = 0;
  for (const InstanceConfig& inst : config.instances) total += inst.count;
  ObjectSet objects;
  objects.resize(total);

  size_t o = 0;
  for (const InstanceConfig& inst : config.instances) {
    assert(inst.model < chains.size());
    const Sphere sphere = chain_sphere(chains[inst.model]);
    for (const Placement& p : place_block(inst)) {
      objects.model[o] = inst.model;
      objects.x[o] = p.position[0];
      objects.y[o] = p.position[1];
      objects.z[o] = p.position[2];
      objects.yaw[o] = p.yaw;
      objects.scale[o] = p.scale;
      // The world sphere as every frame computes it (runtime/world_bounds.h).
      const Sphere w = world_sphere(transform_of(objects, o), sphere);
      objects.cx[o] = w.center[0];
      objects.cy[o] = w.center[1];
      objects.cz[o] = w.center[2];
      objects.radius[o] = w.radius;
      ++o;
    }
  }
  return objects;
}

Scene make_scene(const SceneConfig& config, std::vector<LodChain> chains) {
  Scene scene;
  scene.objects = place_instances(config, chains);
  scene.models = build_model_table(chains);
  scene.chains = std::move(chains);
  return scene;
}

}  // namespace lod
