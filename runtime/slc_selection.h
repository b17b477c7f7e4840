// Time-critical selection under a budget (R0): while the visible objects cost more than M,
// take the object of highest importance f = weight * SLC(l_cur -> l_next) from a max-heap,
// lower it one level, recompute f for its next step and reinsert it. O(m log m).
// Not sub-range safe: the budget is global, so it runs on the whole object range at once.
#pragma once
#include <cstddef>
#include <cstdint>
#include <span>

#include "runtime/model_table.h"

namespace lod {

enum class BudgetCount : uint8_t {
  triangles,  // sum of selected triangle counts <= M
  levels,     // R0: sum of 2^l <= M
};

struct SelectionParams {
  uint64_t budget = 2000000;  // M
  BudgetCount count = BudgetCount::triangles;
};

struct HeapEntry {
  float key;       // importance f of lowering this object one more level
  uint32_t object;
};

struct SelectionResult {
  uint64_t cost = 0;            // in the budget's unit, after selection
  uint64_t triangles = 0;       // selected triangles
  uint64_t level_cost = 0;      // sum of 2^l
  uint64_t coarsest_cost = 0;   // cost with every visible object at its coarsest level
  uint32_t lowered_steps = 0;   // heap pops
  bool over_budget = false;     // even the coarsest levels exceed M; they are used
};

// Cost of one level in the budget's unit.
uint64_t level_cost(const ModelTable& models, uint32_t model, uint32_t level, BudgetCount count);

// `level` holds the initial levels of visible objects on entry and the selected ones on
// exit. `heap` is caller-owned scratch with room for every visible object (room for every
// object saves a bound check per object). Invisible objects' levels are left as they are.
// Deterministic: equal keys are taken in increasing object id.
SelectionResult select_under_budget(std::span<uint8_t> level, std::span<const uint8_t> visible,
                                    std::span<const float> weight, std::span<const uint32_t> model,
                                    const ModelTable& models, const SelectionParams& params,
                                    std::span<HeapEntry> heap);

}  // namespace lod
