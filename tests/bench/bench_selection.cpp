// How good is the selection? On random scenes (tests/unit/runtime/random_knapsack.h: 200
// objects, budgets from 10 % to 60 % of the way from the coarsest to the finest levels), the
// benefit of Yu, Liang and Chen's heap (greedy), of the multi-level-per-pop heap (greedy_multi), of the
// runtime's Funkhouser-Sequin selector (benefit_cost) and of the oracle's reference greedy
// (selection_oracle.h) as a fraction of the exact optimum (dynamic programming). Prints the
// distribution.
// What do the selectors cost? BM_SelectorsColdStart: 100,000 objects from full detail with a
// budget that sends nearly all of them to their coarsest levels (and one 30 % of the way),
// greedy_multi and benefit_cost against greedy (the baseline) in the same iteration: ratios of
// time and pops. (Benefit is compared in BM_SelectionQuality, where each object's importance
// weight and benefit weight come from one distance and area, and on real scenes in `lod run`.)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
#include <vector>

#include "runtime/benefit_cost_selection.h"
#include "unit/runtime/random_knapsack.h"

namespace {

using namespace lod;

// The runtime's benefit_cost selector from full detail on a random scene.
std::vector<uint8_t> benefit_cost_choice(const test::RandomScene& s) {
  const size_t n = s.model.size();
  std::vector<uint8_t> levels(n, 0), visible(n, 1);
  std::vector<float> w(n);
  for (size_t i = 0; i < n; ++i) w[i] = benefit_weight(s.area[i], s.distance[i], s.scale[i], 1000.f);
  std::vector<HeapEntry> heap(n);
  SelectionParams p;
  p.budget = s.problem.capacity;
  p.selector = Selector::benefit_cost;
  select_under_budget(levels, visible, s.weight, s.model, s.models, p, heap, w);
  return levels;
}

void BM_SelectionQuality(benchmark::State& state) {
  std::vector<double> heap_share, multi_share, greedy_share, bc_share;
  for (auto _ : state) {
    heap_share.clear();
    multi_share.clear();
    greedy_share.clear();
    bc_share.clear();
    for (uint32_t seed = 1; seed <= 60; ++seed) {
      for (double share : {0.1, 0.3, 0.6}) {
        test::RandomScene s(200, seed, share);
        std::vector<uint8_t> opt(200), greedy(200);
        if (!optimal_choice(s.problem, 10, opt) || !greedy_choice(s.problem, greedy)) continue;
        const double o = benefit_of(s.problem, opt);
        if (o <= 0) continue;
        heap_share.push_back(benefit_of(s.problem, s.heap_choice()) / o);
        multi_share.push_back(benefit_of(s.problem, s.heap_choice(Selector::greedy_multi)) / o);
        greedy_share.push_back(benefit_of(s.problem, greedy) / o);
        bc_share.push_back(benefit_of(s.problem, benefit_cost_choice(s)) / o);
      }
    }
  }
  auto stats = [&](std::vector<double> v, const char* name) {
    std::sort(v.begin(), v.end());
    double mean = 0;
    for (double x : v) mean += x;
    mean /= double(v.size());
    state.counters[std::string(name) + "_min"] = v.front();
    state.counters[std::string(name) + "_p10"] = v[v.size() / 10];
    state.counters[std::string(name) + "_median"] = v[v.size() / 2];
    state.counters[std::string(name) + "_mean"] = mean;
  };
  stats(heap_share, "heap");
  stats(multi_share, "multi");
  stats(greedy_share, "oracle_greedy");
  stats(bc_share, "benefit_cost");
  state.counters["scenes"] = double(heap_share.size());
}
BENCHMARK(BM_SelectionQuality)->Iterations(1)->Unit(benchmark::kSecond);

// Yu, Liang and Chen's bunny-like chains (100/50/25/12/6/3 %) at three sizes.
ModelTable bunny_like_table() {
  std::vector<std::vector<test::LevelSpec>> chains;
  for (uint32_t full : {69451u, 5804u, 20000u}) {
    std::vector<test::LevelSpec> levels;
    float error = 0;
    for (double r : {1.0, 0.5, 0.25, 0.12, 0.06, 0.03}) {
      levels.push_back({static_cast<uint32_t>(full * r), error});
      error = error * 2 + 0.01f;
    }
    chains.push_back(levels);
  }
  return test::table_of(chains);
}

// arg 0: budget as per mille of the way from the coarsest to the finest levels; arg 1:
// greedy_multi's slack in percent (default 50); arg 2: its exact tail in percent (default 5).
void BM_SelectorsColdStart(benchmark::State& state) {
  const ModelTable t = bunny_like_table();
  constexpr size_t n = 100000;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> w(0.001f, 1.f);
  std::vector<uint32_t> model(n);
  std::vector<float> weight(n);
  std::vector<uint8_t> visible(n, 1), level(n);
  std::vector<HeapEntry> heap(n);
  uint64_t finest = 0, coarsest = 0;
  for (size_t i = 0; i < n; ++i) {
    model[i] = static_cast<uint32_t>(rng() % t.model_count());
    weight[i] = w(rng);
    finest += t.triangles[t.first_level[model[i]]];
    coarsest += t.triangles[t.first_level[model[i]] + t.level_count[model[i]] - 1];
  }
  SelectionParams p;
  p.budget = coarsest + (finest - coarsest) * uint64_t(state.range(0)) / 1000;
  p.multi_level_slack = float(state.range(1)) / 100.f;
  p.multi_exact_tail = float(state.range(2)) / 100.f;
  double ms[3] = {0, 0, 0};
  uint64_t pops[3] = {0, 0, 0}, levels[3] = {0, 0, 0};
  const Selector selectors[3] = {Selector::greedy, Selector::greedy_multi, Selector::benefit_cost};
  for (auto _ : state) {
    for (int k = 0; k < 3; ++k) {
      p.selector = selectors[k];
      std::fill(level.begin(), level.end(), uint8_t{0});
      const auto t0 = std::chrono::steady_clock::now();
      // benefit_cost's weights: the importance weights will do for timing.
      const SelectionResult r = select_under_budget(level, visible, weight, model, t, p, heap, weight);
      ms[k] += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      benchmark::DoNotOptimize(r);
      pops[k] += r.lowered_steps;
      levels[k] += r.levels_lowered;
    }
  }
  const double it = double(state.iterations());
  state.counters["greedy_ms"] = ms[0] / it;
  state.counters["multi_ms"] = ms[1] / it;
  state.counters["time_multi_over_greedy"] = ms[1] / ms[0];
  state.counters["greedy_pops"] = double(pops[0]) / it;
  state.counters["multi_pops"] = double(pops[1]) / it;
  state.counters["pops_multi_over_greedy"] = double(pops[1]) / double(pops[0]);
  state.counters["multi_levels_per_pop"] = double(levels[1]) / double(pops[1]);
  state.counters["bc_ms"] = ms[2] / it;
  state.counters["time_bc_over_greedy"] = ms[2] / ms[0];
  state.counters["bc_pops"] = double(pops[2]) / it;

}
BENCHMARK(BM_SelectorsColdStart)
    ->Args({20, 50, 5})   // the defaults
    ->Args({300, 50, 5})
    ->Args({20, 50, 0})   // no exact tail
    ->Args({20, 90, 5})   // a timid slack
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
