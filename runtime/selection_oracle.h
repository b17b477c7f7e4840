// Selection measured: a benefit per object and level, the exact optimum of the multiple-choice
// knapsack that selection approximates (Luebke's LOD survey), and Funkhouser-Sequin's benefit/cost greedy, so
// that Yu, Liang and Chen's heap can be compared with both on the same scenes.
//
// Benefit of object i at level k: its projected area A_i (pixels^2) times the screen-space
// error the level removes against its coarsest level L,
//   b_i(k) = A_i * (s_i(L) - s_i(k)),   s_i(k) = error_k * scale_i * focal / distance_i (pixels),
// so a level is worth more the larger the object looks and the more error it takes away; the
// coarsest level is worth 0. Cost: the level's triangles. The problem: one level per object,
// sum of costs <= M, maximise the sum of benefits.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "runtime/model_table.h"

namespace lod {

// One problem instance, flattened: object i's levels are [first[i], first[i + 1]).
struct KnapsackProblem {
  std::vector<uint32_t> first;     // objects + 1 offsets
  std::vector<uint64_t> cost;      // per level
  std::vector<double> benefit;     // per level
  uint64_t capacity = 0;           // M
  size_t objects() const { return first.empty() ? 0 : first.size() - 1; }
};

// The problem selection solves for `visible` objects (levels of their models' chains).
KnapsackProblem knapsack_of(std::span<const uint32_t> model, std::span<const float> distance,
                            std::span<const float> area, std::span<const float> scale, const ModelTable& models,
                            float focal_px, uint64_t budget);

// Sum of benefits of a choice (level index per object, relative to the object's chain); its
// cost through `cost_out`.
double benefit_of(const KnapsackProblem& p, std::span<const uint8_t> levels, uint64_t* cost_out = nullptr);

// The exact optimum by dynamic programming over costs divided by `unit` (every cost and the
// capacity must be multiples of it, checked): O(objects x capacity / unit x levels). Returns
// false when the coarsest levels do not fit or capacity / unit exceeds `max_cells`.
bool optimal_choice(const KnapsackProblem& p, uint64_t unit, std::span<uint8_t> levels, size_t max_cells = 50000000);

// Funkhouser-Sequin: from every object at its coarsest level, take the upgrade of best
// benefit gain per extra triangle while it fits, then compare with the best single upgrade
// alone (the check that makes the greedy >= 1/2 of the optimum). Returns false when the
// coarsest levels do not fit.
bool greedy_choice(const KnapsackProblem& p, std::span<uint8_t> levels);

// The optimum of one frame's selection, for Frame::benefit_optimum: objects i (all of the
// spans) with candidate levels [initial_i, coarsest] of their rows, benefit w_i * (e(L) - e(k))
// (w_i = benefit_weight), the budget selection had. Exact when every object's most valuable
// candidate fits together (then that is the optimum), or when the room above the cheapest
// candidates is at most `max_cells` - 1 cost units; otherwise costs are divided by
// unit = ceil(room / (max_cells - 1)) and rounded down, which can only enlarge the feasible set:
// `benefit` is then an upper bound of the optimum (within n x unit of cost of it), so a fraction
// against it never overstates. O(n x max_cells x levels), value only. Returns false when the
// coarsest levels do not fit.
struct SelectionOptimum {
  double benefit = 0;
  bool exact = false;
};
bool selection_optimum(std::span<const uint8_t> initial, std::span<const float> benefit_weight,
                       std::span<const uint32_t> model, const ModelTable& models, bool by_triangles, uint64_t budget,
                       size_t max_cells, SelectionOptimum& out);

// The same benefit of chosen levels.
double selection_benefit(std::span<const uint8_t> level, std::span<const float> benefit_weight,
                         std::span<const uint32_t> model, const ModelTable& models);

}  // namespace lod
