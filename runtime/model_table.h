// ModelTable: the per-level facts selection needs, flattened across all models so the
// per-frame stages read contiguous arrays instead of chasing LodChain pointers.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "runtime/lod_chain.h"

namespace lod {

inline constexpr uint32_t kMaxLevels = 16;  // levels per chain, a uint8_t per object holds one

struct ModelTable {
  // Per model.
  std::vector<uint32_t> first_level;   // offset into the per-level arrays
  std::vector<uint8_t> level_count;    // >= 1
  std::vector<float> radius;           // object-space bounding radius of level 0
  // Per level, all models back to back; index = first_level[model] + level.
  std::vector<uint32_t> triangles;
  std::vector<int32_t> level_l;        // round(log2(triangles))
  std::vector<float> error;            // object-space geometric error

  size_t model_count() const { return first_level.size(); }
};

ModelTable build_model_table(std::span<const LodChain> chains);

}  // namespace lod
