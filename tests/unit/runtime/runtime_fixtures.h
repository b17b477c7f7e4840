// Small hand-built inputs shared by the runtime tests: model tables without meshes, valid
// chains with real (tiny) index buffers, and seeded random scenes.
#pragma once
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "runtime/lod_chain.h"
#include "runtime/model_table.h"
#include "runtime/object_set.h"

namespace lod::test {

struct LevelSpec {
  uint32_t triangles;
  float error;
};

// A table straight from per-level facts, so selection can be tested at paper-sized counts.
inline ModelTable table_of(const std::vector<std::vector<LevelSpec>>& models) {
  ModelTable t;
  for (const auto& levels : models) {
    t.first_level.push_back(static_cast<uint32_t>(t.triangles.size()));
    t.level_count.push_back(static_cast<uint8_t>(levels.size()));
    t.radius.push_back(1.0f);
    for (const LevelSpec& s : levels) {
      t.triangles.push_back(s.triangles);
      t.level_l.push_back(level_of_triangles(s.triangles));
      t.error.push_back(s.error);
    }
  }
  return t;
}

// A valid chain whose level k is a fan of `triangles[k]` triangles around vertex 0.
inline LodChain fan_chain(const std::string& name, const std::vector<uint32_t>& triangles) {
  LodChain c;
  c.name = name;
  c.source_hash = 0x1234abcd5678ef90ull;
  for (size_t k = 0; k < triangles.size(); ++k) {
    LodLevel lv;
    const uint32_t t = triangles[k];
    lv.first_index = static_cast<uint32_t>(c.indices.size());
    lv.index_count = 3 * t;
    lv.first_vertex = static_cast<uint32_t>(c.positions.size() / 3);
    lv.vertex_count = t + 2;
    lv.level = level_of_triangles(t);
    lv.error = 0.125f * static_cast<float>(k);
    lv.error_rms = 0.0625f * static_cast<float>(k);
    lv.bounds = {{0.5f, -0.25f, 1.0f / 3.0f}, 1.75f};
    for (uint32_t v = 0; v < t + 2; ++v) {
      const float a = 0.1f * static_cast<float>(v) + 0.01f * static_cast<float>(k);
      c.positions.insert(c.positions.end(), {a, 1.0f - a, a * a});
      c.normals.insert(c.normals.end(), {0.f, 1.f, -0.f});
    }
    for (uint32_t f = 0; f < t; ++f) c.indices.insert(c.indices.end(), {0u, f + 1, f + 2});
    c.levels.push_back(lv);
  }
  return c;
}

// `n` spheres uniformly in [-extent, extent]^3 with radii in [0.1, max_radius].
inline ObjectSet random_spheres(size_t n, float extent, float max_radius, uint32_t models, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-extent, extent), rad(0.1f, max_radius), sc(0.5f, 2.0f);
  std::uniform_int_distribution<uint32_t> mod(0, models - 1);
  ObjectSet o;
  o.resize(n);
  for (size_t i = 0; i < n; ++i) {
    o.model[i] = mod(rng);
    o.x[i] = o.cx[i] = pos(rng);
    o.y[i] = o.cy[i] = pos(rng);
    o.z[i] = o.cz[i] = pos(rng);
    o.radius[i] = rad(rng);
    o.scale[i] = sc(rng);
  }
  return o;
}

}  // namespace lod::test
