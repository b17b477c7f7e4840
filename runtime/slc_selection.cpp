// SLC selection (Yu, Liang and Chen, Fig. 3): while the visible objects cost more than M, lower the
// object of highest importance f = (d / S) * SLC(l_cur -> l_next) by one level.
// Passes: (1) one branch-free streaming loop counts visible objects per chain level (the
// costs of the initial and of the coarsest levels follow from those counts) and writes each
// lowerable object's key into the caller's scratch; (2) only when over M: heapify, O(m);
// (3) pop-lower-reinsert with a replace-top sift-down, O(pops log m). No allocation.
// Selection is the serial part of a frame, so pass 1 is kept to a handful of instructions
// per object: per-level lookups are folded into small tables on the stack first.
#include "runtime/slc_selection.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <type_traits>

#include "runtime/benefit_cost_selection.h"
#include "runtime/importance.h"
#include "runtime/selection_heap.h"

namespace lod {

namespace {

using detail::make_heap;
using detail::sift_down;
constexpr size_t kArity = detail::kHeapArity;
inline uint64_t rank(const HeapEntry& e) { return detail::heap_rank(e); }

inline uint64_t pow2(int32_t l) { return uint64_t{1} << l; }

// SLC of lowering from chain level `at` to `at + 1`. The culled level (0 triangles, l = 0)
// counts as one level below the one before it: culling saves about what such a step saves,
// and Yu, Liang and Chen's l_i^2 span would make the heap cull objects before it lowers finer ones.
inline float step_slc(const int32_t* ls, const uint32_t* tris, uint32_t at) {
  const int32_t to = tris[at + 1] == 0 ? ls[at] - 1 : ls[at + 1];
  return static_cast<float>(span_of_level_changed(ls[at], to));
}

// gather_selection's entry for an object that cannot be lowered: rank 0, below every real
// entry (a real one has ~object > 0), so it sinks to the bottom and is never popped.
constexpr uint32_t kPlaceholder = 0xffffffffu;

struct Gathered {
  uint64_t tri_sum = 0, lev_sum = 0;        // initial levels
  uint64_t tri_coarse = 0, lev_coarse = 0;  // coarsest levels
  size_t heap_size = 0;                     // lowerable visible objects written to the heap
};

struct Columns {
  std::span<const uint8_t> level, visible;
  std::span<const float> weight;
  std::span<const uint32_t> model;
};

// Per-level lookup tables live on the stack when the chains fit, with room past the end so
// that a stale level of an invisible object (at most 255 past its chain's start) still
// indexes inside them without a clamp.
constexpr size_t kStaleLevelRoom = 256;
constexpr size_t kSlotTableSize = 2048;

Gathered gather_by_slots(const Columns& c, const ModelTable& models, HeapEntry* heap, size_t capacity) {
  const size_t levels = models.triangles.size();
  const size_t slots = levels + kStaleLevelRoom;
  assert(slots <= kSlotTableSize);
  uint32_t visible_at[kSlotTableSize];  // visible objects per chain level
  float slc_next[kSlotTableSize];       // SLC of lowering one step from this level
  uint8_t lowerable[kSlotTableSize];    // 1 unless this is its chain's coarsest level
  std::fill_n(visible_at, slots, 0u);
  std::fill_n(slc_next, slots, 0.f);
  std::fill_n(lowerable, slots, uint8_t{0});
  const uint32_t* first = models.first_level.data();
  const int32_t* ls = models.level_l.data();
  for (size_t m = 0; m < models.model_count(); ++m) {
    for (uint32_t k = first[m]; k + 1 < first[m] + models.level_count[m]; ++k) {
      slc_next[k] = step_slc(ls, models.triangles.data(), k);
      lowerable[k] = 1;
    }
  }

  const size_t n = c.visible.size();
  const uint8_t* __restrict visible = c.visible.data();
  const uint8_t* __restrict level = c.level.data();
  const uint32_t* __restrict model = c.model.data();
  const float* __restrict weight = c.weight.data();
  size_t size = 0;
  auto one = [&](size_t i, auto bounded) {
    assert(!visible[i] || level[i] < models.level_count[model[i]]);
    const uint32_t at = first[model[i]] + level[i];
    const uint32_t v = visible[i] != 0;
    visible_at[at] += v;
    const HeapEntry e{weight[i] * slc_next[at], static_cast<uint32_t>(i)};
    assert(!(v && lowerable[at]) || e.key >= 0.f);  // rank() needs keys >= 0 (and not NaN)
    if (!bounded || size < capacity) heap[size] = e;
    size += v & lowerable[at];
  };
  // With room for every object (the usual case) the write needs no bound check.
  if (capacity >= n) {
    for (size_t i = 0; i < n; ++i) one(i, std::false_type{});
  } else {
    for (size_t i = 0; i < n; ++i) one(i, std::true_type{});
  }

  Gathered g;
  g.heap_size = size;
  const uint32_t* tris = models.triangles.data();
  for (size_t m = 0; m < models.model_count(); ++m) {
    const uint32_t begin = first[m], last = begin + models.level_count[m] - 1u;
    uint64_t count = 0;
    for (uint32_t k = begin; k <= last; ++k) {
      count += visible_at[k];
      g.tri_sum += uint64_t{visible_at[k]} * tris[k];
      g.lev_sum += uint64_t{visible_at[k]} * pow2(ls[k]);
    }
    g.tri_coarse += count * tris[last];
    g.lev_coarse += count * pow2(ls[last]);
  }
  return g;
}

// The same without tables, for scenes with more chain levels than the stack tables hold.
Gathered gather_direct(const Columns& c, const ModelTable& models, HeapEntry* heap, size_t capacity) {
  const uint32_t* first = models.first_level.data();
  const uint8_t* counts = models.level_count.data();
  const uint32_t* tris = models.triangles.data();
  const int32_t* ls = models.level_l.data();
  Gathered g;
  size_t size = 0;
  for (size_t i = 0; i < c.visible.size(); ++i) {
    const uint64_t keep = c.visible[i] ? ~uint64_t{0} : 0;
    const uint32_t m = c.model[i];
    const uint32_t last = counts[m] - 1u;
    assert(!c.visible[i] || c.level[i] <= last);
    const uint32_t cur = std::min<uint32_t>(c.level[i], last);  // invisible levels may be stale
    const uint32_t at = first[m] + cur;
    const uint32_t coarse = first[m] + last;
    const uint32_t lowerable = cur < last;
    g.tri_sum += tris[at] & keep;
    g.lev_sum += pow2(ls[at]) & keep;
    g.tri_coarse += tris[coarse] & keep;
    g.lev_coarse += pow2(ls[coarse]) & keep;
    const HeapEntry e{lowerable ? c.weight[i] * step_slc(ls, tris, at) : 0.f, static_cast<uint32_t>(i)};
    assert(!(lowerable && keep) || e.key >= 0.f);
    if (size < capacity) heap[size] = e;
    size += lowerable & keep;
  }
  g.heap_size = size;
  return g;
}


// The runner-up's rank: the best of the root's children (0 when the root has none).
inline uint64_t runner_up_rank(const HeapEntry* h, size_t size) {
  uint64_t best = 0;
  for (size_t c = 1; c < std::min(size, kArity + 1); ++c) best = std::max(best, rank(h[c]));
  return best;
}

struct LowerParams {
  bool by_triangles = true;
  uint64_t budget = 0;
  Selector selector = Selector::greedy;
  float slack = 1;         // greedy_multi
  float exact_tail = 0;    // greedy_multi: share of the excess lowered with slack 1
};

struct Lowered {
  uint32_t pops = 0, levels = 0;
};

// Pass 3: lower the top until the budget holds (greedy: one level per pop; greedy_multi: while
// its next key, divided by the slack, still ranks above the runner-up). The coarsest levels fit,
// so with counts that describe the heap's objects it cannot run dry first (and placeholders,
// ranked below every real entry, are never reached); the loop stops there all the same, so
// that counts out of step with the objects give a wrong cost, never a read past the heap.
Lowered lower_from_heap(HeapEntry* h, size_t size, std::span<uint8_t> level, std::span<const float> weight,
                        std::span<const uint32_t> model, const ModelTable& models, const LowerParams& p,
                        uint64_t& cost, uint64_t& tri_sum, uint64_t& lev_sum) {
  const uint32_t* first = models.first_level.data();
  const uint8_t* counts = models.level_count.data();
  const uint32_t* tris = models.triangles.data();
  const int32_t* ls = models.level_l.data();
  const bool multi = p.selector == Selector::greedy_multi;
  assert(!multi || (p.slack > 0 && p.slack <= 1));
  // Below `relaxed_until` only the steps greedy itself would take next are taken in a row.
  const uint64_t relaxed_until = p.budget + uint64_t(double(cost - p.budget) * p.exact_tail);
  Lowered done;
  while (cost > p.budget && size > 0 && h[0].object != kPlaceholder) {
    const uint32_t obj = h[0].object;
    const uint32_t m = model[obj];
    const uint64_t runner_up = multi ? runner_up_rank(h, size) : 0;
    ++done.pops;
    for (;;) {
      const uint32_t cur = level[obj];
      const uint32_t at = first[m] + cur;
      const uint64_t tri_drop = tris[at] - tris[at + 1];
      const uint64_t lev_drop = pow2(ls[at]) - pow2(ls[at + 1]);
      tri_sum -= tri_drop;
      lev_sum -= lev_drop;
      cost -= p.by_triangles ? tri_drop : lev_drop;
      level[obj] = static_cast<uint8_t>(cur + 1u);
      ++done.levels;
      if (cur + 2u >= counts[m]) {  // at its coarsest: out of the heap
        --size;
        if (size > 0) sift_down(h, size, 0, h[size]);
        break;
      }
      const HeapEntry next{weight[obj] * step_slc(ls, tris, at + 1), obj};
      const float slack = cost > relaxed_until ? p.slack : 1.0f;
      const bool again = multi && cost > p.budget && rank(HeapEntry{next.key / slack, obj}) > runner_up;
      if (!again) {
        sift_down(h, size, 0, next);
        break;
      }
    }
  }
  return done;
}

LowerParams lower_params_of(const SelectionParams& p) {
  return {p.count == BudgetCount::triangles, p.budget, p.selector, p.multi_level_slack, p.multi_exact_tail};
}

// Pass 3 for the chosen selector: the heap lowers, benefit_cost raises from the coarsest.
void run_selector(SelectionResult& r, std::span<HeapEntry> heap, size_t heap_size, std::span<uint8_t> level,
                  std::span<const uint8_t> visible, std::span<const float> weight, std::span<const uint32_t> model,
                  const ModelTable& models, const SelectionParams& params, std::span<const float> benefit_weight,
                  uint64_t& cost, uint64_t& tri_sum, uint64_t& lev_sum) {
  if (params.selector == Selector::benefit_cost) {
    assert(benefit_weight.size() == level.size() && "benefit_cost needs every object's benefit weight");
    const BenefitCostResult b = raise_by_benefit_cost(level, visible, benefit_weight, model, models, params.count,
                                                      params.budget, heap);
    r.lowered_steps = b.pops;
    r.levels_lowered = b.levels_below_initial;
    tri_sum = b.triangles;
    lev_sum = b.level_cost;
    cost = params.count == BudgetCount::triangles ? tri_sum : lev_sum;
    return;
  }
  HeapEntry* h = heap.data();
  make_heap(h, heap_size);  // pass 2: heapify, O(m)
  const Lowered l = lower_from_heap(h, heap_size, level, weight, model, models, lower_params_of(params), cost,
                                    tri_sum, lev_sum);
  r.lowered_steps = l.pops;
  r.levels_lowered = l.levels;
}

}  // namespace

uint64_t level_cost(const ModelTable& models, uint32_t model, uint32_t level, BudgetCount count) {
  assert(model < models.model_count() && level < models.level_count[model]);
  const uint32_t at = models.first_level[model] + level;
  return count == BudgetCount::triangles ? uint64_t{models.triangles[at]} : pow2(models.level_l[at]);
}

SelectionResult select_under_budget(std::span<uint8_t> level, std::span<const uint8_t> visible,
                                    std::span<const float> weight, std::span<const uint32_t> model,
                                    const ModelTable& models, const SelectionParams& params,
                                    std::span<HeapEntry> heap, std::span<const float> benefit_weight) {
  const size_t n = visible.size();
  assert(level.size() == n && weight.size() == n && model.size() == n);
  const uint8_t* counts = models.level_count.data();
  const bool by_triangles = params.count == BudgetCount::triangles;

  // Pass 1: totals, and every lowerable visible object's key. Keys are written even when
  // the budget holds: in the frames where it binds (most of them) this saves a second pass.
  HeapEntry* h = heap.data();
  const Columns columns{level, visible, weight, model};
  const Gathered g = models.triangles.size() + kStaleLevelRoom <= kSlotTableSize
                         ? gather_by_slots(columns, models, h, heap.size())
                         : gather_direct(columns, models, h, heap.size());
  uint64_t tri_sum = g.tri_sum, lev_sum = g.lev_sum;

  SelectionResult r;
  r.coarsest_cost = by_triangles ? g.tri_coarse : g.lev_coarse;
  if (r.coarsest_cost > params.budget) {
    // Even the coarsest levels do not fit: use them and say so.
    for (size_t i = 0; i < n; ++i) {
      const uint8_t last = static_cast<uint8_t>(counts[model[i]] - 1u);
      level[i] = visible[i] ? last : level[i];
    }
    r.cost = r.coarsest_cost;
    r.triangles = g.tri_coarse;
    r.level_cost = g.lev_coarse;
    r.over_budget = true;
    return r;
  }
  uint64_t cost = by_triangles ? tri_sum : lev_sum;
  if (cost > params.budget) {
    assert(g.heap_size <= heap.size() && "heap scratch needs room for every visible object");
    run_selector(r, heap, g.heap_size, level, visible, weight, model, models, params, benefit_weight, cost, tri_sum,
                 lev_sum);
  }
  r.cost = cost;
  r.triangles = tri_sum;
  r.level_cost = lev_sum;
  return r;
}

SelectionTables build_selection_tables(const ModelTable& models) {
  SelectionTables t;
  // Room past the end: an invisible object's stale level may index past its chain.
  const size_t size = models.triangles.size() + kStaleLevelRoom;
  t.slc_next.assign(size, 0.f);
  t.lowerable.assign(size, 0);
  for (size_t m = 0; m < models.model_count(); ++m) {
    const uint32_t first = models.first_level[m];
    for (uint32_t k = first; k + 1 < first + models.level_count[m]; ++k) {
      t.slc_next[k] = step_slc(models.level_l.data(), models.triangles.data(), k);
      t.lowerable[k] = 1;
    }
  }
  return t;
}

void gather_selection(std::span<HeapEntry> heap, std::span<uint32_t> level_counts, std::span<const uint8_t> level,
                      std::span<const uint8_t> visible, std::span<const float> weight,
                      std::span<const uint32_t> model, uint32_t first_id, const ModelTable& models,
                      const SelectionTables& tables) {
  const size_t n = visible.size();
  assert(heap.size() == n && level.size() == n && weight.size() == n && model.size() == n);
  assert(level_counts.size() == models.triangles.size());
  assert(tables.slc_next.size() == models.triangles.size() + kStaleLevelRoom);
  const uint32_t* first = models.first_level.data();
  const float* slc_next = tables.slc_next.data();
  const uint8_t* lowerable = tables.lowerable.data();
  uint32_t* counts = level_counts.data();
  HeapEntry* __restrict out = heap.data();
  for (size_t i = 0; i < n; ++i) {
    const uint32_t v = visible[i] != 0;
    assert(!v || level[i] < models.level_count[model[i]]);
    const uint32_t at = first[model[i]] + level[i];
    counts[v ? at : 0] += v;  // an invisible object adds 0 at a valid index
    const bool keep = v & lowerable[at];
    const HeapEntry real{weight[i] * slc_next[at], first_id + static_cast<uint32_t>(i)};
    assert(!keep || real.key >= 0.f);
    out[i] = keep ? real : HeapEntry{0.f, kPlaceholder};
  }
}

SelectionResult lower_under_budget(std::span<uint8_t> level, std::span<const uint8_t> visible,
                                   std::span<const float> weight, std::span<const uint32_t> model,
                                   const ModelTable& models, const SelectionParams& params,
                                   std::span<const uint32_t> level_counts, std::span<HeapEntry> heap,
                                   std::span<const float> benefit_weight) {
  const size_t n = visible.size();
  assert(level.size() == n && weight.size() == n && model.size() == n && heap.size() == n);
  assert(level_counts.size() == models.triangles.size());
  if (n == 0) return {};  // nothing visible: nothing to select
  const uint32_t* tris = models.triangles.data();
  const int32_t* ls = models.level_l.data();
  uint64_t tri_sum = 0, lev_sum = 0, tri_coarse = 0, lev_coarse = 0;
  [[maybe_unused]] uint64_t counted = 0;
  for (size_t m = 0; m < models.model_count(); ++m) {
    const uint32_t begin = models.first_level[m], last = begin + models.level_count[m] - 1u;
    uint64_t count = 0;
    for (uint32_t k = begin; k <= last; ++k) {
      count += level_counts[k];
      tri_sum += uint64_t{level_counts[k]} * tris[k];
      lev_sum += uint64_t{level_counts[k]} * pow2(ls[k]);
    }
    tri_coarse += count * tris[last];
    lev_coarse += count * pow2(ls[last]);
    counted += count;
  }
  assert(counted == size_t(std::count_if(visible.begin(), visible.end(), [](uint8_t v) { return v != 0; })) &&
         "level_counts must count exactly the visible objects");
  const bool by_triangles = params.count == BudgetCount::triangles;
  SelectionResult r;
  r.coarsest_cost = by_triangles ? tri_coarse : lev_coarse;
  if (r.coarsest_cost > params.budget) {
    for (size_t i = 0; i < n; ++i) {
      const uint8_t last = static_cast<uint8_t>(models.level_count[model[i]] - 1u);
      level[i] = visible[i] ? last : level[i];
    }
    r.cost = r.coarsest_cost;
    r.triangles = tri_coarse;
    r.level_cost = lev_coarse;
    r.over_budget = true;
    return r;
  }
  uint64_t cost = by_triangles ? tri_sum : lev_sum;
  if (cost > params.budget) {
    run_selector(r, heap, n, level, visible, weight, model, models, params, benefit_weight, cost, tri_sum,
                 lev_sum);
  }
  r.cost = cost;
  r.triangles = tri_sum;
  r.level_cost = lev_sum;
  return r;
}

}  // namespace lod
