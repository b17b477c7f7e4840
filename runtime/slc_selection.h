// SLC (span of level changed) selection, Yu, Liang and Chen: while the visible objects cost more than M,
// take the object of highest importance f = weight * SLC(l_cur -> l_next) from a max-heap,
// lower it one level, recompute f for its next step and reinsert it. O(m log m).
// Two selectors share this interface (SelectionParams::selector):
//   greedy        as Yu, Liang and Chen publish it: one level per heap pop.
//   greedy_multi  the paper's future work ("more exploitatively"): a popped object keeps being lowered
//                 while its next step's f is at least `multi_level_slack` times the runner-up's
//                 f (the best key left in the heap), then goes back once. slack = 1 gives
//                 exactly greedy's levels with fewer pops; below 1 it trades a little benefit
//                 for far fewer pops (a cold start lowers most objects to the end in one pop).
//                 The last `multi_exact_tail` of the excess over M is lowered with slack 1:
//                 those steps decide who ends just above or below a level (measured: 5 % keeps
//                 a cold start under 1/4 of greedy's pops and most of the benefit lost without
//                 it, docs/performance.md).
//   benefit_cost  Funkhouser-Sequin's benefit/cost greedy (Luebke) with the best-single-object check
//                 (runtime/benefit_cost_selection.h): raises from the coarsest levels instead of
//                 lowering from the initial ones, >= 1/2 of the optimal benefit guaranteed. It
//                 needs each object's benefit weight (the `benefit_weight` argument).
// The heap selectors stop at the first step that brings the cost within M, benefit_cost
// never takes a step past M, so all three meet the same budget.
// Not sub-range safe: the budget is global, so it runs on the whole object range at once.
#pragma once
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "runtime/model_table.h"

namespace lod {

enum class BudgetCount : uint8_t {
  triangles,  // sum of selected triangle counts <= M
  levels,     // Yu, Liang and Chen: sum of 2^l <= M
};

enum class Selector : uint8_t {
  greedy,        // Yu, Liang and Chen: one level per pop
  greedy_multi,  // several levels per pop (see above)
  benefit_cost,  // Funkhouser-Sequin from the coarsest levels (see above)
};

struct SelectionParams {
  uint64_t budget = 2000000;  // M
  BudgetCount count = BudgetCount::triangles;
  Selector selector = Selector::greedy;
  // greedy_multi: keep lowering the popped object while f_next >= slack * f_runner_up, in (0, 1].
  float multi_level_slack = 0.5f;
  // greedy_multi: the last share of the excess (cost - M) is lowered with slack 1, where each
  // step decides which objects end just above or below their next level.
  float multi_exact_tail = 0.05f;
  // For the frame graph (triangle budgets): objects blending two levels draw the finer one,
  // so last frame's extra is held back from M (at most M / 2) to keep what is drawn near M.
  bool reserve_blends = true;
  // Strict (triangle budgets): what is drawn, blends included, stays within M whenever the
  // coarsest levels fit; a blend that does not fit is dropped (the level changes at once).
  bool strict = false;
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
  uint32_t levels_lowered = 0;  // levels lowered in all (= heap pops for greedy; benefit_cost:
                                // levels below the initial ones)
  bool over_budget = false;     // even the coarsest levels exceed M; they are used
};

// Cost of one level in the budget's unit.
uint64_t level_cost(const ModelTable& models, uint32_t model, uint32_t level, BudgetCount count);

// `level` holds the initial levels of visible objects on entry and the selected ones on
// exit. `heap` is caller-owned scratch with room for every visible object (room for every
// object saves a bound check per object). Invisible objects' levels are left as they are.
// Deterministic: equal keys are taken in increasing object id.
// The same selection in two parts, so that its streaming pass runs in parallel:
//
//   gather_selection    sub-range safe: writes one heap entry per object of its range (a
//                       placeholder that is never popped when the object is invisible or at
//                       its coarsest level) and adds its visible objects per chain level into
//                       `level_counts` (one counter per ModelTable level). Run it on chunks.
//   lower_under_budget  serial: from the summed counts and the whole heap array, the same
//                       result as select_under_budget on the same inputs.
//
// `tables` comes from build_selection_tables(models), once per ModelTable.
struct SelectionTables {
  std::vector<float> slc_next;     // per level: SLC of lowering one step from it (0 at coarsest)
  std::vector<uint8_t> lowerable;  // per level: 1 unless it is its chain's coarsest
};
SelectionTables build_selection_tables(const ModelTable& models);

// `first_id` is the id of the range's first object in the array lower_under_budget gets.
void gather_selection(std::span<HeapEntry> heap, std::span<uint32_t> level_counts, std::span<const uint8_t> level,
                      std::span<const uint8_t> visible, std::span<const float> weight,
                      std::span<const uint32_t> model, uint32_t first_id, const ModelTable& models,
                      const SelectionTables& tables);

// `heap` holds one entry per object (from gather_selection); it is reordered in place.
// `level_counts` must count exactly the visible objects of `visible` (summed over every range
// gather_selection ran on, and over nothing else). Total: no objects, none visible, one, or a
// budget below their coarsest levels each give a result, whatever an earlier call was given.
// `benefit_weight` (per object, benefit_weight() in runtime/benefit_cost_selection.h) is read
// only by Selector::benefit_cost, which needs it; the heap selectors ignore it.
SelectionResult lower_under_budget(std::span<uint8_t> level, std::span<const uint8_t> visible,
                                   std::span<const float> weight, std::span<const uint32_t> model,
                                   const ModelTable& models, const SelectionParams& params,
                                   std::span<const uint32_t> level_counts, std::span<HeapEntry> heap,
                                   std::span<const float> benefit_weight = {});

SelectionResult select_under_budget(std::span<uint8_t> level, std::span<const uint8_t> visible,
                                    std::span<const float> weight, std::span<const uint32_t> model,
                                    const ModelTable& models, const SelectionParams& params,
                                    std::span<HeapEntry> heap, std::span<const float> benefit_weight = {});

}  // namespace lod
