// Frame: what one pass of the per-frame graph publishes for a consumer (renderer, viewer).
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "runtime/view.h"

namespace lod {

enum class Stage : uint8_t { view, visibility, importance, selection, vdlod, geomorph, publish, count };
inline constexpr const char* kStageNames[] = {"view",     "visibility", "importance", "selection",
                                              "vdlod",    "geomorph",   "publish"};
inline constexpr size_t kStageCount = static_cast<size_t>(Stage::count);
inline constexpr size_t kHistogramLevels = 32;  // histogram bins by l = round(log2 tris)

struct Frame {
  uint64_t index = 0;  // frame number, increasing
  View view;

  // One entry per visible object, in object order.
  std::vector<uint32_t> objects;  // object ids
  std::vector<uint8_t> levels;    // chain level index (0 = full detail)
  std::vector<float> morph;       // geomorph factor in [0, 1] towards `levels` (1 = settled)

  uint32_t object_count = 0;
  uint32_t visible = 0;
  uint64_t tris_in_view = 0;    // visible objects at full detail
  uint64_t tris_selected = 0;
  uint64_t level_cost = 0;      // sum of 2^l over visible objects
  uint64_t budget = 0;          // M
  uint64_t coarsest_cost = 0;   // cost with all visible objects at their coarsest level
  bool over_budget = false;     // even the coarsest levels exceed M
  uint32_t lowered_steps = 0;   // heap pops in selection
  std::array<uint32_t, kHistogramLevels> level_histogram{};  // objects per l

  std::array<double, kStageCount> stage_ms{};  // per stage, milliseconds
  double total_ms = 0;
};

}  // namespace lod
