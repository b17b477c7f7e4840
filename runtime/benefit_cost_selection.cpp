// Benefit/cost greedy: passes (1) every visible object to its coarsest level, its first hull
// step into the heap and its best single raise; (2) heapify; (3) pop, take the step if it still
// fits (else reinsert the best one that does), reinsert the next; (4) the best-single check.
#include "runtime/benefit_cost_selection.h"

#include <cassert>
#include <limits>
#include <vector>

#include "runtime/selection_heap.h"

namespace lod {
namespace {

struct Costs {
  const ModelTable& models;
  bool by_triangles;
  int64_t at(uint32_t index) const {
    return by_triangles ? int64_t{models.triangles[index]} : int64_t{1} << models.level_l[index];
  }
};

struct Step {
  uint8_t to;     // == the current level when there is none
  float key;      // benefit per unit of extra cost
  int64_t extra;  // extra cost
};

// From `cur`, the finer level in [finest, cur) of steepest benefit slope within `room`; ties
// go to the finer level (the hull's far vertex). Steps that add no benefit are never taken.
Step best_step(const Costs& c, uint32_t base, uint32_t finest, uint32_t cur, float w, int64_t room) {
  const float* err = c.models.error.data();
  const int64_t c0 = c.at(base + cur);
  Step s{static_cast<uint8_t>(cur), 0.f, 0};
  float best = -1.f;
  for (uint32_t k = cur; k-- > finest;) {  // coarser to finer
    const int64_t extra = c.at(base + k) - c0;
    const float gain = w * (err[base + cur] - err[base + k]);
    if (!(gain > 0.f) || extra > room) continue;
    const float slope = extra <= 0 ? std::numeric_limits<float>::infinity() : gain / float(extra);
    if (slope >= best) best = slope, s = {static_cast<uint8_t>(k), slope, extra};
  }
  return s;
}

struct Single {
  double benefit = 0;
  uint32_t object = std::numeric_limits<uint32_t>::max();
  uint8_t level = 0;
};

}  // namespace

BenefitCostResult raise_by_benefit_cost(std::span<uint8_t> level, std::span<const uint8_t> visible,
                                        std::span<const float> weight, std::span<const uint32_t> model,
                                        const ModelTable& models, BudgetCount count, uint64_t budget,
                                        std::span<HeapEntry> heap) {
  const size_t n = level.size();
  assert(visible.size() == n && weight.size() == n && model.size() == n);
  const Costs c{models, count == BudgetCount::triangles};
  const uint32_t* first = models.first_level.data();
  const uint8_t* counts = models.level_count.data();
  const float* err = models.error.data();
  const std::vector<uint8_t> finest(level.begin(), level.end());
  int64_t coarsest = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!visible[i]) continue;
    level[i] = static_cast<uint8_t>(counts[model[i]] - 1u);
    coarsest += c.at(first[model[i]] + level[i]);
  }
  assert(uint64_t(coarsest) <= budget);
  const int64_t room0 = int64_t(budget) - coarsest;

  // Pass 1: first steps and the best single raise (within the whole room: it fits alone).
  HeapEntry* h = heap.data();
  size_t size = 0;
  Single single;
  for (size_t i = 0; i < n; ++i) {
    if (!visible[i]) continue;
    const uint32_t base = first[model[i]], last = level[i];
    const Step s = best_step(c, base, finest[i], last, weight[i], room0);
    if (s.to == last) continue;
    assert(size < heap.size() && "heap scratch needs room for every visible object");
    h[size++] = {s.key, static_cast<uint32_t>(i)};
    for (uint32_t k = finest[i]; k < last; ++k) {
      const double b = double(weight[i]) * (err[base + last] - err[base + k]);
      if (c.at(base + k) - c.at(base + last) <= room0 && b > single.benefit)
        single = {b, static_cast<uint32_t>(i), static_cast<uint8_t>(k)};
    }
  }
  detail::make_heap(h, size);

  // Pass 3: the greedy.
  BenefitCostResult r;
  int64_t room = room0;
  while (size > 0) {
    const uint32_t obj = h[0].object, base = first[model[obj]];
    ++r.pops;
    const Step s = best_step(c, base, finest[obj], level[obj], weight[obj], room);
    if (s.to == level[obj]) {
      detail::pop_top(h, size);
    } else if (s.key < h[0].key) {  // its planned step no longer fits: the best that does, in order
      detail::sift_down(h, size, 0, {s.key, obj});
    } else {
      level[obj] = s.to;
      room -= s.extra;
      const Step next = best_step(c, base, finest[obj], s.to, weight[obj], room);
      if (next.to == s.to)
        detail::pop_top(h, size);
      else
        detail::sift_down(h, size, 0, {next.key, obj});
    }
  }

  // Pass 4: the best single raise alone, if it is worth more than the greedy's choice.
  double greedy = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!visible[i]) continue;
    const uint32_t base = first[model[i]], last = base + counts[model[i]] - 1u;
    greedy += double(weight[i]) * (err[last] - err[base + level[i]]);
  }
  if (single.benefit > greedy) {
    r.single_won = true;
    for (size_t i = 0; i < n; ++i)
      if (visible[i]) level[i] = static_cast<uint8_t>(counts[model[i]] - 1u);
    level[single.object] = single.level;
  }
  for (size_t i = 0; i < n; ++i) {
    if (!visible[i]) continue;
    const uint32_t at = first[model[i]] + level[i];
    r.triangles += models.triangles[at];
    r.level_cost += uint64_t{1} << models.level_l[at];
    r.levels_below_initial += level[i] - finest[i];
  }
  return r;
}

}  // namespace lod
