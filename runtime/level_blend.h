// Level blends (geomorphing of discrete levels): the per-object state machine that turns
// a level change into a blend over `seconds`. Per visible entry k (object ids[k]):
//   - a change from last frame's level restarts the blend from that level; going back to the
//     level it was leaving, mid-blend, runs the same blend backwards from where it is;
//   - an object not visible last frame appears settled;
//   - morph[k] = elapsed / seconds in [0, 1], from_level[k] = the level it blends from (its own
//     level when settled or when its model cannot blend);
//   - a change into or out of a culled level (0 triangles) never blends: nothing to morph to.
// Sub-range safe over entries (each entry touches only its own object's state).
#pragma once
#include <cstdint>
#include <span>

#include "runtime/model_table.h"

namespace lod {

struct BlendTotals {
  uint32_t morphing = 0;     // entries blending two levels
  uint64_t extra_tris = 0;   // what drawing their finer level adds to the selected triangles
};

struct LevelBlendState {     // per object (dense), carried across frames
  std::span<double> morph_start;
  std::span<uint8_t> morph_from;
  std::span<const uint8_t> prev_level;
  std::span<const uint8_t> was_visible;
};

BlendTotals advance_level_blends(std::span<float> morph, std::span<uint8_t> from_level,
                                 std::span<const uint32_t> ids, std::span<const uint8_t> level,
                                 std::span<const uint32_t> model, const LevelBlendState& state,
                                 std::span<const uint8_t> model_blends, const ModelTable& models, double now,
                                 float seconds);

// Strict budgets: keeps blends, in entry order, while what they add to the selected
// triangles fits `room` (M minus the selected triangles); every other blend is dropped (the
// object shows its new level at once and is settled). Serial: the budget is global. Returns
// the totals of the blends kept.
BlendTotals fit_blends_to_room(std::span<float> morph, std::span<uint8_t> from_level, std::span<const uint32_t> ids,
                               std::span<const uint8_t> level, std::span<const uint32_t> model,
                               const LevelBlendState& state, const ModelTable& models, uint64_t room);

}  // namespace lod
