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

}  // namespace lod
