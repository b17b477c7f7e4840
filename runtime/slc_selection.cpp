// Budgeted selection (R0, Fig. 3): while the visible objects cost more than M, lower the
// object of highest importance f = (d / S) * SLC(l_cur -> l_next) by one level.
// Passes: (1) cost of the initial and of the coarsest levels, one streaming loop;
// (2) only when over M: gather lowerable objects into the caller's scratch and heapify, O(m);
// (3) pop-lower-reinsert with a replace-top sift-down, O(pops log m). No allocation.
#include "runtime/slc_selection.h"

#include <cassert>
#include <cmath>

#include "runtime/importance.h"

namespace lod {

namespace {

// Max-heap order on f; equal keys go to the lower object id so runs are reproducible.
inline bool before(const HeapEntry& a, const HeapEntry& b) {
  return a.key > b.key || (a.key == b.key && a.object < b.object);
}

// Moves `e` down from `hole` until the heap property holds again (hole technique: one
// write per level instead of a swap).
void sift_down(HeapEntry* heap, size_t size, size_t hole, HeapEntry e) {
  for (;;) {
    size_t child = 2 * hole + 1;
    if (child >= size) break;
    if (child + 1 < size && before(heap[child + 1], heap[child])) ++child;
    if (!before(heap[child], e)) break;
    heap[hole] = heap[child];
    hole = child;
  }
  heap[hole] = e;
}

void make_heap(HeapEntry* heap, size_t size) {
  for (size_t i = size / 2; i-- > 0;) sift_down(heap, size, i, heap[i]);
}

inline uint64_t pow2(int32_t l) { return uint64_t{1} << l; }

}  // namespace

uint64_t level_cost(const ModelTable& models, uint32_t model, uint32_t level, BudgetCount count) {
  assert(model < models.model_count() && level < models.level_count[model]);
  const uint32_t at = models.first_level[model] + level;
  return count == BudgetCount::triangles ? uint64_t{models.triangles[at]} : pow2(models.level_l[at]);
}

SelectionResult select_under_budget(std::span<uint8_t> level, std::span<const uint8_t> visible,
                                    std::span<const float> weight, std::span<const uint32_t> model,
                                    const ModelTable& models, const SelectionParams& params,
                                    std::span<HeapEntry> heap) {
  const size_t n = visible.size();
  assert(level.size() == n && weight.size() == n && model.size() == n);
  const uint32_t* first = models.first_level.data();
  const uint8_t* counts = models.level_count.data();
  const uint32_t* tris = models.triangles.data();
  const int32_t* ls = models.level_l.data();
  const bool by_triangles = params.count == BudgetCount::triangles;

  // Pass 1: totals of the initial and of the coarsest levels, in both units.
  uint64_t tri_sum = 0, lev_sum = 0, tri_coarse = 0, lev_coarse = 0;
  size_t lowerable = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!visible[i]) continue;
    const uint32_t m = model[i];
    const uint32_t last = counts[m] - 1u;
    assert(level[i] <= last);
    const uint32_t at = first[m] + level[i];
    const uint32_t coarse = first[m] + last;
    tri_sum += tris[at];
    lev_sum += pow2(ls[at]);
    tri_coarse += tris[coarse];
    lev_coarse += pow2(ls[coarse]);
    lowerable += level[i] < last;
  }
  SelectionResult r;
  r.coarsest_cost = by_triangles ? tri_coarse : lev_coarse;
  if (r.coarsest_cost > params.budget) {
    // Even the coarsest levels do not fit: use them and say so.
    for (size_t i = 0; i < n; ++i) {
      if (visible[i]) level[i] = static_cast<uint8_t>(counts[model[i]] - 1u);
    }
    r.cost = r.coarsest_cost;
    r.triangles = tri_coarse;
    r.level_cost = lev_coarse;
    r.over_budget = true;
    return r;
  }
  uint64_t cost = by_triangles ? tri_sum : lev_sum;
  if (cost > params.budget) {
    // Pass 2: every object that can still be lowered, keyed by f of its next step.
    assert(heap.size() >= lowerable);
    HeapEntry* h = heap.data();
    size_t size = 0;
    for (size_t i = 0; i < n; ++i) {
      if (!visible[i]) continue;
      const uint32_t m = model[i];
      const uint32_t cur = level[i];
      if (cur + 1u >= counts[m]) continue;
      const uint32_t at = first[m] + cur;
      h[size++] = {weight[i] * static_cast<float>(span_of_level_changed(ls[at], ls[at + 1])),
                   static_cast<uint32_t>(i)};
    }
    assert(size == lowerable);
    make_heap(h, size);

    // Pass 3: lower the top one level at a time until the budget holds. The coarsest levels
    // fit, so the heap cannot run dry first.
    uint32_t steps = 0;
    while (cost > params.budget) {
      assert(size > 0);
      const uint32_t obj = h[0].object;
      const uint32_t m = model[obj];
      const uint32_t cur = level[obj];
      const uint32_t at = first[m] + cur;
      const uint64_t tri_drop = tris[at] - tris[at + 1];
      const uint64_t lev_drop = pow2(ls[at]) - pow2(ls[at + 1]);
      tri_sum -= tri_drop;
      lev_sum -= lev_drop;
      cost -= by_triangles ? tri_drop : lev_drop;
      level[obj] = static_cast<uint8_t>(cur + 1u);
      ++steps;
      if (cur + 2u < counts[m]) {
        const HeapEntry next{weight[obj] * static_cast<float>(span_of_level_changed(ls[at + 1], ls[at + 2])),
                             obj};
        sift_down(h, size, 0, next);
      } else {
        --size;
        if (size > 0) sift_down(h, size, 0, h[size]);
      }
    }
    r.lowered_steps = steps;
  }
  r.cost = cost;
  r.triangles = tri_sum;
  r.level_cost = lev_sum;
  return r;
}

}  // namespace lod
