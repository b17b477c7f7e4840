// Selection measured: benefits, the exact MCKP optimum by dynamic programming, and the
// benefit/cost greedy.
#include "runtime/selection_oracle.h"

#include <algorithm>
#include <cassert>
#include <limits>

namespace lod {

KnapsackProblem knapsack_of(std::span<const uint32_t> model, std::span<const float> distance,
                            std::span<const float> area, std::span<const float> scale, const ModelTable& models,
                            float focal_px, uint64_t budget) {
  KnapsackProblem p;
  p.capacity = budget;
  p.first.push_back(0);
  for (size_t i = 0; i < model.size(); ++i) {
    const uint32_t m = model[i], base = models.first_level[m], count = models.level_count[m];
    const double px = double(scale[i]) * focal_px / std::max(double(distance[i]), 1e-9);
    const double coarsest = models.error[base + count - 1] * px;
    for (uint32_t k = 0; k < count; ++k) {
      p.cost.push_back(models.triangles[base + k]);
      p.benefit.push_back(double(area[i]) * std::max(0.0, coarsest - models.error[base + k] * px));
    }
    p.first.push_back(static_cast<uint32_t>(p.cost.size()));
  }
  return p;
}

double benefit_of(const KnapsackProblem& p, std::span<const uint8_t> levels, uint64_t* cost_out) {
  assert(levels.size() == p.objects());
  double b = 0;
  uint64_t c = 0;
  for (size_t i = 0; i < p.objects(); ++i) {
    const uint32_t at = p.first[i] + levels[i];
    assert(at < p.first[i + 1]);
    b += p.benefit[at];
    c += p.cost[at];
  }
  if (cost_out) *cost_out = c;
  return b;
}

namespace {

uint64_t coarsest_cost(const KnapsackProblem& p) {
  uint64_t c = 0;
  for (size_t i = 0; i < p.objects(); ++i) c += p.cost[p.first[i + 1] - 1];
  return c;
}

}  // namespace

bool optimal_choice(const KnapsackProblem& p, uint64_t unit, std::span<uint8_t> levels, size_t max_cells) {
  const size_t n = p.objects();
  assert(levels.size() == n && unit > 0);
  if (p.capacity % unit != 0) return false;
  for (uint64_t c : p.cost)
    if (c % unit != 0) return false;
  if (coarsest_cost(p) > p.capacity) return false;
  const size_t cells = size_t(p.capacity / unit) + 1;
  if (n * cells > max_cells) return false;
  constexpr double kNone = -std::numeric_limits<double>::infinity();
  // best[c]: the best benefit of the objects so far within cost c units; choice per object.
  std::vector<double> best(cells, 0.0), next(cells);
  std::vector<uint8_t> choice(n * cells, 0);
  for (size_t i = 0; i < n; ++i) {
    std::fill(next.begin(), next.end(), kNone);
    for (uint32_t at = p.first[i]; at < p.first[i + 1]; ++at) {
      const size_t w = size_t(p.cost[at] / unit);
      for (size_t c = w; c < cells; ++c) {
        if (best[c - w] == kNone) continue;
        const double v = best[c - w] + p.benefit[at];
        if (v > next[c]) {
          next[c] = v;
          choice[i * cells + c] = static_cast<uint8_t>(at - p.first[i]);
        }
      }
    }
    best.swap(next);
  }
  // Walk back from the full capacity.
  size_t c = cells - 1;
  for (size_t i = n; i-- > 0;) {
    levels[i] = choice[i * cells + c];
    c -= size_t(p.cost[p.first[i] + levels[i]] / unit);
  }
  return true;
}

bool greedy_choice(const KnapsackProblem& p, std::span<uint8_t> levels) {
  const size_t n = p.objects();
  assert(levels.size() == n);
  uint64_t used = coarsest_cost(p);
  if (used > p.capacity) return false;
  for (size_t i = 0; i < n; ++i) levels[i] = static_cast<uint8_t>(p.first[i + 1] - p.first[i] - 1);
  // Repeatedly the upgrade (any object, to any finer level) of best gain per extra triangle
  // that still fits.
  for (;;) {
    double best_ratio = 0;
    size_t best_i = n;
    uint8_t best_k = 0;
    for (size_t i = 0; i < n; ++i) {
      const uint32_t cur = p.first[i] + levels[i];
      for (uint32_t at = p.first[i]; at < cur; ++at) {
        const uint64_t extra = p.cost[at] - p.cost[cur];
        const double gain = p.benefit[at] - p.benefit[cur];
        if (gain <= 0 || used + extra > p.capacity) continue;
        const double ratio = extra == 0 ? std::numeric_limits<double>::infinity() : gain / double(extra);
        if (ratio > best_ratio) best_ratio = ratio, best_i = i, best_k = static_cast<uint8_t>(at - p.first[i]);
      }
    }
    if (best_i == n) break;
    used += p.cost[p.first[best_i] + best_k] - p.cost[p.first[best_i] + levels[best_i]];
    levels[best_i] = best_k;
  }
  // The best single upgrade from all-coarsest, if it alone is worth more.
  const double greedy = benefit_of(p, levels);
  const uint64_t base = coarsest_cost(p);
  double base_benefit = 0;
  for (size_t i = 0; i < n; ++i) base_benefit += p.benefit[p.first[i + 1] - 1];
  double single = 0;
  size_t single_i = n;
  uint8_t single_k = 0;
  for (size_t i = 0; i < n; ++i) {
    const uint32_t last = p.first[i + 1] - 1;
    for (uint32_t at = p.first[i]; at < last; ++at) {
      if (base - p.cost[last] + p.cost[at] > p.capacity) continue;
      const double v = base_benefit - p.benefit[last] + p.benefit[at];
      if (v > single) single = v, single_i = i, single_k = static_cast<uint8_t>(at - p.first[i]);
    }
  }
  if (single > greedy && single_i < n) {
    for (size_t i = 0; i < n; ++i) levels[i] = static_cast<uint8_t>(p.first[i + 1] - p.first[i] - 1);
    levels[single_i] = single_k;
  }
  return true;
}

namespace {

// One object's candidates as (cost, benefit), its cheapest cost, and its most valuable one.
struct Candidates {
  uint32_t base = 0, from = 0, last = 0;  // levels [from, last] of the row at base
  int64_t cheapest = 0;
  uint32_t most_valuable = 0;
};

int64_t cost_at(const ModelTable& t, uint32_t at, bool by_triangles) {
  return by_triangles ? int64_t{t.triangles[at]} : int64_t{1} << t.level_l[at];
}

double value_at(const ModelTable& t, const Candidates& c, uint32_t k, float w) {
  return double(w) * std::max(0.0, double(t.error[c.base + c.last]) - double(t.error[c.base + k]));
}

}  // namespace

double selection_benefit(std::span<const uint8_t> level, std::span<const float> w, std::span<const uint32_t> model,
                         const ModelTable& models) {
  double b = 0;
  for (size_t i = 0; i < level.size(); ++i) {
    const uint32_t base = models.first_level[model[i]], last = models.level_count[model[i]] - 1u;
    b += double(w[i]) * std::max(0.0, double(models.error[base + last]) - double(models.error[base + level[i]]));
  }
  return b;
}

bool selection_optimum(std::span<const uint8_t> initial, std::span<const float> w, std::span<const uint32_t> model,
                       const ModelTable& models, bool by_triangles, uint64_t budget, size_t max_cells,
                       SelectionOptimum& out) {
  const size_t n = initial.size();
  assert(w.size() == n && model.size() == n && max_cells >= 2);
  std::vector<Candidates> objects(n);
  int64_t base_cost = 0, coarsest = 0, valuable_cost = 0;
  double valuable = 0;
  for (size_t i = 0; i < n; ++i) {
    Candidates& c = objects[i];
    c.base = models.first_level[model[i]];
    c.last = models.level_count[model[i]] - 1u;
    c.from = std::min<uint32_t>(initial[i], c.last);
    c.cheapest = cost_at(models, c.base + c.last, by_triangles);
    c.most_valuable = c.last;
    for (uint32_t k = c.from; k <= c.last; ++k) {
      c.cheapest = std::min(c.cheapest, cost_at(models, c.base + k, by_triangles));
      if (value_at(models, c, k, w[i]) > value_at(models, c, c.most_valuable, w[i])) c.most_valuable = k;
    }
    base_cost += c.cheapest;
    coarsest += cost_at(models, c.base + c.last, by_triangles);
    valuable_cost += cost_at(models, c.base + c.most_valuable, by_triangles);
    valuable += value_at(models, c, c.most_valuable, w[i]);
  }
  const int64_t capacity = int64_t(std::min<uint64_t>(budget, uint64_t(std::numeric_limits<int64_t>::max())));
  if (coarsest > capacity) return false;
  if (valuable_cost <= capacity) {  // every object's best fits: nothing to choose
    out = {valuable, true};
    return true;
  }
  const uint64_t room = uint64_t(capacity - base_cost);
  const uint64_t unit = std::max<uint64_t>(1, (room + max_cells - 2) / (max_cells - 1));
  const size_t cells = size_t(room / unit) + 1;
  // best[c]: the most benefit of the objects so far with rounded extra cost <= c.
  std::vector<double> best(cells, 0.0), next(cells);
  for (size_t i = 0; i < n; ++i) {
    const Candidates& c = objects[i];
    std::fill(next.begin(), next.end(), 0.0);
    for (uint32_t k = c.from; k <= c.last; ++k) {
      const size_t extra = size_t(uint64_t(cost_at(models, c.base + k, by_triangles) - c.cheapest) / unit);
      const double v = value_at(models, c, k, w[i]);
      for (size_t x = extra; x < cells; ++x) next[x] = std::max(next[x], best[x - extra] + v);
    }
    best.swap(next);
  }
  out = {best[cells - 1], unit == 1};
  return true;
}

}  // namespace lod
