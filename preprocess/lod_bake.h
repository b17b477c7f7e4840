// Baking one model: load, clean, simplify to every ratio, measure each level's error.
#pragma once
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "preprocess/mesh_clean.h"
#include "runtime/lod_chain.h"
#include "runtime/status.h"

namespace lod {

enum class SimplifyMethod : uint8_t { qem, extreme, automatic };

inline constexpr float kDefaultUvWeight = 0.2f;

// Runs body(0..count-1), possibly in parallel. preprocess/ owns no threads: jobs/ passes one in.
using BakeParallelFor = std::function<void(size_t count, const std::function<void(size_t)>& body)>;

struct BakeSettings {
  std::vector<float> ratios;  // fractions of the input triangles, 1.0 first; empty = defaults by size
  SimplifyMethod method = SimplifyMethod::automatic;
  uint64_t extreme_threshold = 1000000;  // auto: triangles above which the aggressive method is used
  // Weight of the texture-coordinate error in QEM's collapse cost (QemOptions::attribute_weight;
  // positions are in units of the model's power-of-two extent, uvs in texture units); 0 = only
  // the geometry ranks collapses (uvs still follow, seams still move only along themselves).
  float uv_weight = kDefaultUvWeight;
  // Optional: lets one model use several cores (the two halves of a QEM run, the levels'
  // error measurements). The output is byte-identical with or without it, so it is not
  // part of the cache key.
  BakeParallelFor parallel_for;
};

// progress(fraction in [0,1], what) is called from the baking thread.
using BakeProgress = std::function<void(float, const char*)>;

struct BakeReport {
  CleanReport cleaned;
  size_t input_triangles = 0;
  double seconds = 0;
  double morph_seconds = 0;  // of which: morph targets between consecutive levels
  std::string method;  // what actually ran
  std::vector<std::string> notes;  // e.g. a level that stopped above its target, and why
};

// The reference's ratios (Yu, Liang and Chen) by size: cow-sized 100/50/25/12/6 %, bunny-sized
// 100/50/25/12/6/3 %, armadillo/buddha-sized 100/25/12/6/3/1.5/0.75/0.37/0.18 %.
std::vector<float> default_ratios(size_t triangles);

// Content hash of the file's bytes and the settings: the bake cache key.
uint64_t bake_key(const std::filesystem::path& mesh_file, const BakeSettings& settings, Status* status);

Status bake_model(const std::filesystem::path& mesh_file, const std::string& name,
                  const BakeSettings& settings, LodChain& out, BakeReport* report,
                  const BakeProgress& progress);

}  // namespace lod
