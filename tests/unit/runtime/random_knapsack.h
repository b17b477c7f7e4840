// Random selection problems for the oracle test and bench_selection: three models with costs
// in multiples of 10 triangles, objects at random distances, a budget between the coarsest
// and the finest levels.
#pragma once
#include <algorithm>
#include <random>
#include <vector>

#include "runtime/selection_oracle.h"
#include "runtime/slc_selection.h"
#include "unit/runtime/runtime_fixtures.h"

namespace lod::test {

struct RandomScene {
  ModelTable models;
  std::vector<uint32_t> model;
  std::vector<float> distance, area, scale, weight;
  KnapsackProblem problem;

  RandomScene(uint32_t objects, uint32_t seed, double budget_share) {
    std::mt19937 rng(seed);
    std::vector<std::vector<test::LevelSpec>> chains;
    for (int m = 0; m < 3; ++m) {
      std::vector<test::LevelSpec> levels;
      uint32_t tris = 10 * (100 + rng() % 400);
      float error = 0;
      for (int k = 0; k < 2 + int(rng() % 4); ++k) {
        levels.push_back({tris, error});
        tris = std::max<uint32_t>(10, tris / 2 / 10 * 10);
        error = error == 0 ? 0.01f : error * 2.1f;
      }
      chains.push_back(levels);
    }
    models = test::table_of(chains);
    std::uniform_real_distribution<float> d(5, 400);
    float nearest = 1e30f, smallest = 1e30f;
    for (uint32_t i = 0; i < objects; ++i) {
      model.push_back(rng() % 3);
      distance.push_back(d(rng));
      scale.push_back(1.f);
      area.push_back(3.14159f * 1000.f * 1000.f / (distance.back() * distance.back()));
      nearest = std::min(nearest, distance.back());
      smallest = std::min(smallest, area.back());
    }
    for (uint32_t i = 0; i < objects; ++i) weight.push_back((nearest / distance[i]) / (area[i] / smallest));
    problem = knapsack_of(model, distance, area, scale, models, 1000.f, 0);
    uint64_t finest = 0, coarsest = 0;
    for (size_t i = 0; i < problem.objects(); ++i)
      finest += problem.cost[problem.first[i]], coarsest += problem.cost[problem.first[i + 1] - 1];
    problem.capacity = (coarsest + uint64_t(double(finest - coarsest) * budget_share)) / 10 * 10;
    if (problem.capacity < coarsest) problem.capacity += 10;
  }

  // Yu, Liang and Chen's heap from every object at full detail (the selection's cold start), with either
  // selector; `pops` gets the heap pops it took.
  std::vector<uint8_t> heap_choice(Selector selector = Selector::greedy, uint32_t* pops = nullptr) const {
    std::vector<uint8_t> levels(model.size(), 0), visible(model.size(), 1);
    std::vector<HeapEntry> heap(model.size());
    SelectionParams p;
    p.budget = problem.capacity;
    p.selector = selector;
    const SelectionResult r = select_under_budget(levels, visible, weight, model, models, p, heap);
    if (pops) *pops = r.lowered_steps;
    return levels;
  }
};

}  // namespace lod::test
