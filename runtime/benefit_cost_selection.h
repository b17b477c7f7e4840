// Funkhouser-Sequin's benefit/cost greedy (Luebke's survey) as a selector (Selector::benefit_cost): from
// every visible object at its coarsest level, repeatedly raise the object whose next step
// has the most benefit per unit of extra cost, while the budget allows; then compare with the
// best single object raised alone (the check that guarantees >= 1/2 of the optimum).
// Benefit is the oracle's (runtime/selection_oracle.h): level k of object i is worth
//   b_i(k) = w_i * (e(L) - e(k)),   w_i = A_i * error_scale_i * focal / distance_i,
// e the level's object-space error, L the coarsest level; w_i is the object's benefit weight.
// Each object's steps follow the upper convex hull of its (cost, benefit) points (from the
// current level, the finer level of steepest slope that fits), so the greedy takes the same
// steps as the LP relaxation up to the first one that does not fit; that step alone is worth
// at most the best single object, hence the guarantee. A step that no longer fits is replaced
// by the object's best one that does, so the greedy keeps filling the budget.
// An object is never raised above its level on entry (its initial level: the pixel-error
// threshold and the object controls).
#pragma once
#include <cstdint>
#include <span>

#include "runtime/model_table.h"
#include "runtime/slc_selection.h"

namespace lod {

// w_i above; 0 where the object has no area.
inline float benefit_weight(float area, float distance, float error_scale, float focal_px) {
  return area * error_scale * focal_px / (distance > 1e-9f ? distance : 1e-9f);
}

struct BenefitCostResult {
  uint64_t triangles = 0, level_cost = 0;  // of the selected levels
  uint32_t pops = 0;                       // heap pops
  uint32_t levels_below_initial = 0;       // sum over objects of selected minus initial level
  bool single_won = false;                 // the best single object beat the greedy
};

// `level`: initial levels of visible objects on entry (never exceeded), selected on exit;
// invisible objects are left as they are. The coarsest levels must fit in `budget` (the caller
// checks). `heap` has room for every visible object. Deterministic (ties by object id).
BenefitCostResult raise_by_benefit_cost(std::span<uint8_t> level, std::span<const uint8_t> visible,
                                        std::span<const float> benefit_weight,
                                        std::span<const uint32_t> model, const ModelTable& models,
                                        BudgetCount count, uint64_t budget, std::span<HeapEntry> heap);

}  // namespace lod
