// How good is the selection? On random scenes (tests/unit/runtime/random_knapsack.h: 200
// objects, budgets from 10 % to 60 % of the way from the coarsest to the finest levels), the
// benefit of R0's heap and of Funkhouser-Sequin's benefit/cost greedy as a fraction of the
// exact optimum (dynamic programming), and what each costs. Prints the distribution.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "unit/runtime/random_knapsack.h"

namespace {

using namespace lod;

void BM_SelectionQuality(benchmark::State& state) {
  std::vector<double> heap_share, greedy_share;
  for (auto _ : state) {
    heap_share.clear();
    greedy_share.clear();
    for (uint32_t seed = 1; seed <= 60; ++seed) {
      for (double share : {0.1, 0.3, 0.6}) {
        test::RandomScene s(200, seed, share);
        std::vector<uint8_t> opt(200), greedy(200);
        if (!optimal_choice(s.problem, 10, opt) || !greedy_choice(s.problem, greedy)) continue;
        const double o = benefit_of(s.problem, opt);
        if (o <= 0) continue;
        heap_share.push_back(benefit_of(s.problem, s.heap_choice()) / o);
        greedy_share.push_back(benefit_of(s.problem, greedy) / o);
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
  stats(greedy_share, "greedy");
  state.counters["scenes"] = double(heap_share.size());
}
BENCHMARK(BM_SelectionQuality)->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
