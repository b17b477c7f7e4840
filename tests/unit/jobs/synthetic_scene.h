// Hand-built scenes for the frame graph, service, stress test and benchmark: LOD chains with
// level metadata only (no geometry; the per-frame graph never reads vertices), placed by the
// real place_instances so that scenes are what a config would give.
#pragma once
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "jobs/scene.h"
#include "runtime/camera_path.h"
#include "runtime/frame.h"
#include "runtime/lod_chain.h"

namespace lod::test {

// Level k has triangles[k]; error doubles per level from `base_error`; sphere of `radius`
// centred a little off the origin so that the world-sphere transform matters.
inline LodChain synthetic_chain(const std::string& name, const std::vector<uint32_t>& triangles,
                                float base_error, float radius) {
  LodChain c;
  c.name = name;
  uint32_t first_index = 0;
  for (size_t k = 0; k < triangles.size(); ++k) {
    LodLevel l;
    l.first_index = first_index;
    l.index_count = triangles[k] * 3;
    first_index += l.index_count;
    l.level = level_of_triangles(triangles[k]);
    l.error = k == 0 ? 0.f : base_error * std::ldexp(1.f, static_cast<int>(k) - 1);
    l.error_rms = l.error * 0.5f;
    l.bounds.center[0] = 0.1f * radius;
    l.bounds.center[1] = 0.5f * radius;
    l.bounds.radius = radius;
    c.levels.push_back(l);
  }
  return c;
}

// Three model types of different sizes and chain lengths, like a cow, a bunny and a scan.
inline std::vector<LodChain> synthetic_chains() {
  return {
      synthetic_chain("cowlike", {5804, 2902, 1451, 725, 362}, 0.02f, 1.0f),
      synthetic_chain("bunnylike", {69451, 34725, 17362, 8681, 4340, 2170}, 0.01f, 1.2f),
      synthetic_chain("scanlike", {345944, 86486, 41513, 20756, 10378, 5189, 2594, 1297, 648}, 0.008f, 1.5f),
  };
}

// `count` objects of the three types, seeded random in a square field of half size `extent`
// (one in ten on a grid), scales 2..6.
inline SceneConfig synthetic_config(uint32_t count, float extent, uint64_t seed = 1) {
  SceneConfig c;
  for (const char* n : {"cowlike", "bunnylike", "scanlike"}) c.models.push_back(ModelConfig{n, {}, {}});
  const uint32_t grid = count / 10;
  const uint32_t rest = count - grid;
  const uint32_t per[3] = {rest / 2, rest / 3, rest - rest / 2 - rest / 3};
  for (uint32_t m = 0; m < 3; ++m) {
    if (per[m] == 0) continue;
    InstanceConfig i;
    i.model = m;
    i.count = per[m];
    i.box_min[0] = -extent, i.box_min[1] = 0, i.box_min[2] = -extent;
    i.box_max[0] = extent, i.box_max[1] = 4, i.box_max[2] = extent;
    i.scale_min = 2, i.scale_max = 6;
    i.seed = seed + m;
    c.instances.push_back(i);
  }
  if (grid > 0) {
    InstanceConfig i;
    i.model = 0;
    i.count = grid;
    i.grid = true;
    i.box_min[0] = -extent / 4, i.box_min[2] = -extent / 4;
    i.box_max[0] = extent / 4, i.box_max[2] = extent / 4;
    i.scale_min = i.scale_max = 3;
    i.seed = seed + 7;
    c.instances.push_back(i);
  }
  c.camera.kind = PathKind::orbit;
  c.camera.radius = extent * 0.6f;
  c.camera.height_above = 15;
  c.camera.period_frames = 200;
  c.camera.lens.far_plane = extent * 4;
  return c;
}

inline Scene synthetic_scene(uint32_t count, float extent, uint64_t seed = 1) {
  return make_scene(synthetic_config(count, extent, seed), synthetic_chains());
}

// One synthetic object (model 0) and one view-dependent `chain` (model 1) at the origin,
// scaled 40: the view-dependent frame graph tests' scene.
inline Scene one_vd_object_scene(LodChain chain) {
  SceneConfig c = synthetic_config(300, 200);
  c.models.resize(1);
  c.instances.resize(1);
  c.instances[0].model = 0;
  c.models.push_back(ModelConfig{chain.name, {}, {}});
  c.models.back().view_dependent = true;
  InstanceConfig i;
  i.model = 1;
  i.count = 1;
  i.grid = true;
  i.box_min[0] = i.box_min[1] = i.box_min[2] = 0;
  i.box_max[0] = i.box_max[1] = i.box_max[2] = 0;
  i.scale_min = i.scale_max = 40;
  c.instances.push_back(i);
  std::vector<LodChain> chains = {synthetic_chains()[0], std::move(chain)};
  return make_scene(c, std::move(chains));
}

// Field size that keeps object density the same at every count (about 10k objects per 1 km^2).
inline float extent_for(uint32_t count) {
  return 500.f * std::sqrt(static_cast<float>(count) / 10000.f) + 50.f;
}

}  // namespace lod::test
