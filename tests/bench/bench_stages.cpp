// Each per-frame stage of runtime/ alone, single-threaded, at 1k / 10k / 100k objects, with
// baselines in the same binary so figures can be quoted as ratios:
//   BM_StreamBaseline  reads the four sphere columns and writes one byte per object (the
//                      memory floor a culling pass cannot beat);
//   BM_SelectPriorityQueue  the textbook selection loop on std::priority_queue (allocates, pop + push),
//                      against BM_Select on identical inputs.
// Scene: Yu, Liang and Chen's three model types plus a bunny, random in a 2 km box, seen from outside it.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <memory>
#include <queue>
#include <random>

#include "runtime/importance.h"
#include "runtime/initial_levels.h"
#include "runtime/model_table.h"
#include "runtime/object_set.h"
#include "runtime/slc_selection.h"
#include "runtime/visibility.h"

namespace {

using namespace lod;

ModelTable bench_models() {
  // Triangle counts of Yu, Liang and Chen's models at its ratios; errors double per level (object units).
  const std::vector<std::pair<double, std::vector<double>>> specs = {
      {5804, {1.0, 0.5, 0.25, 0.12, 0.06}},
      {345944, {0.25, 0.12, 0.06, 0.03, 0.015, 0.0075, 0.0037, 0.0018}},
      {1087716, {0.25, 0.12, 0.06, 0.03, 0.015, 0.0075, 0.0037, 0.0018}},
      {69451, {1.0, 0.5, 0.25, 0.12, 0.06, 0.03}},
  };
  ModelTable t;
  for (const auto& [full, ratios] : specs) {
    t.first_level.push_back(static_cast<uint32_t>(t.triangles.size()));
    t.level_count.push_back(static_cast<uint8_t>(ratios.size()));
    t.radius.push_back(1.0f);
    float error = 0;
    for (double r : ratios) {
      const auto tris = static_cast<uint32_t>(full * r);
      t.triangles.push_back(tris);
      t.level_l.push_back(level_of_triangles(tris));
      t.error.push_back(error);
      error = error == 0 ? 0.002f : error * 2;
    }
  }
  return t;
}

struct BenchScene {
  ModelTable models;
  ObjectSet objects;
  ObjectState state;
  View view;
  Frustum frustum;
  float focal = 0;
  ViewMinima minima{};
  std::vector<uint8_t> initial;  // levels after choose_initial_levels
  std::vector<HeapEntry> heap;
  std::vector<uint8_t> full;     // level 0 everywhere: a selection start with heavy lowering
  uint64_t start_cost = 0, full_cost = 0, coarsest_cost = 0;  // triangles
  size_t visible = 0;
};

// Built once per size and shared by every benchmark of that size.
const BenchScene& scene_of(size_t n) {
  static std::vector<std::unique_ptr<BenchScene>> cache;
  for (const auto& s : cache) {
    if (s->objects.size() == n) return *s;
  }
  auto s = std::make_unique<BenchScene>();
  s->models = bench_models();
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> xz(-1000, 1000), y(0, 20), scale(0.5f, 8.f);
  ObjectSet& o = s->objects;
  o.resize(n);
  for (size_t i = 0; i < n; ++i) {
    o.model[i] = static_cast<uint32_t>(rng() % s->models.model_count());
    o.x[i] = o.cx[i] = xz(rng);
    o.y[i] = o.cy[i] = y(rng);
    o.z[i] = o.cz[i] = xz(rng);
    o.scale[i] = scale(rng);
    o.radius[i] = o.scale[i] * s->models.radius[o.model[i]];
  }
  s->view.eye = {0, 150, 1300};
  s->view.target = {0, 0, 0};
  s->view.far_plane = 5000;
  s->frustum = frustum_of(s->view);
  s->focal = focal_pixels(s->view);
  ObjectState& st = s->state;
  st.resize(n);
  s->visible = cull_spheres(st.visible, o.cx, o.cy, o.cz, o.radius, s->frustum);
  s->minima = measure_objects(st.distance, st.area, st.visible, o.cx, o.cy, o.cz, o.radius, s->view.eye, s->focal);
  importance_weights(st.weight, st.visible, st.distance, st.area, s->minima);
  InitialLevelParams ip;
  ip.focal_px = s->focal;
  choose_initial_levels(st.level, st.visible, st.prev_level, st.was_visible, st.distance, o.scale, o.model,
                        s->models, ip);
  s->initial = st.level;
  uint64_t start = 0, coarsest = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!st.visible[i]) continue;
    start += level_cost(s->models, o.model[i], st.level[i], BudgetCount::triangles);
    s->full_cost += level_cost(s->models, o.model[i], 0, BudgetCount::triangles);
    coarsest += level_cost(s->models, o.model[i], s->models.level_count[o.model[i]] - 1u, BudgetCount::triangles);
  }
  s->full.assign(n, 0);
  s->start_cost = start;
  s->coarsest_cost = coarsest;
  s->heap.resize(n);
  cache.push_back(std::move(s));
  return *cache.back();
}

void common_counters(benchmark::State& state, const BenchScene& s) {
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * s.objects.size()));
  state.counters["visible"] = static_cast<double>(s.visible);
}

void BM_StreamBaseline(benchmark::State& state) {
  const BenchScene& s = scene_of(static_cast<size_t>(state.range(0)));
  const ObjectSet& o = s.objects;
  std::vector<uint8_t> out(o.size());
  for (auto _ : state) {
    const float* __restrict x = o.cx.data();
    const float* __restrict y = o.cy.data();
    const float* __restrict z = o.cz.data();
    const float* __restrict r = o.radius.data();
    uint8_t* __restrict w = out.data();
    for (size_t i = 0; i < o.size(); ++i) w[i] = (x[i] + y[i] + z[i] + r[i]) >= 0.f;
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  common_counters(state, s);
}

void BM_Cull(benchmark::State& state) {
  const BenchScene& s = scene_of(static_cast<size_t>(state.range(0)));
  const ObjectSet& o = s.objects;
  std::vector<uint8_t> visible(o.size());
  for (auto _ : state) {
    benchmark::DoNotOptimize(cull_spheres(visible, o.cx, o.cy, o.cz, o.radius, s.frustum));
    benchmark::ClobberMemory();
  }
  common_counters(state, s);
}

void BM_Measure(benchmark::State& state) {
  const BenchScene& s = scene_of(static_cast<size_t>(state.range(0)));
  const ObjectSet& o = s.objects;
  std::vector<float> distance(o.size()), area(o.size());
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        measure_objects(distance, area, s.state.visible, o.cx, o.cy, o.cz, o.radius, s.view.eye, s.focal));
    benchmark::ClobberMemory();
  }
  common_counters(state, s);
}

void BM_Weights(benchmark::State& state) {
  const BenchScene& s = scene_of(static_cast<size_t>(state.range(0)));
  std::vector<float> weight(s.objects.size());
  for (auto _ : state) {
    benchmark::DoNotOptimize(importance_weights(weight, s.state.visible, s.state.distance, s.state.area, s.minima));
    benchmark::ClobberMemory();
  }
  common_counters(state, s);
}

void BM_InitialLevels(benchmark::State& state) {
  const BenchScene& s = scene_of(static_cast<size_t>(state.range(0)));
  const ObjectSet& o = s.objects;
  std::vector<uint8_t> level(o.size());
  InitialLevelParams ip;
  ip.focal_px = s.focal;
  for (auto _ : state) {
    benchmark::DoNotOptimize(choose_initial_levels(level, s.state.visible, s.initial, s.state.visible,
                                                   s.state.distance, o.scale, o.model, s.models, ip));
    benchmark::ClobberMemory();
  }
  common_counters(state, s);
}

// range(1) picks the start: 0 = the screen-space initial levels (a few hundred pops at 100k),
// 1 = full detail everywhere (tens of thousands of pops: heap-bound). The budget sits halfway
// between the start's cost and the coarsest levels' cost.
const std::vector<uint8_t>& start_of(const BenchScene& s, int64_t which) { return which ? s.full : s.initial; }
SelectionParams budget_of(const BenchScene& s, int64_t which) {
  SelectionParams p;
  p.budget = s.coarsest_cost + ((which ? s.full_cost : s.start_cost) - s.coarsest_cost) / 2;
  return p;
}

// Both selection benchmarks restore the initial levels each iteration (a memcpy of n bytes).
void BM_Select(benchmark::State& state) {
  const BenchScene& s = scene_of(static_cast<size_t>(state.range(0)));
  const SelectionParams params = budget_of(s, state.range(1));
  const std::vector<uint8_t>& start = start_of(s, state.range(1));
  std::vector<uint8_t> level(s.objects.size());
  std::vector<HeapEntry> heap(s.objects.size());
  SelectionResult r;
  for (auto _ : state) {
    std::copy(start.begin(), start.end(), level.begin());
    r = select_under_budget(level, s.state.visible, s.state.weight, s.objects.model, s.models, params, heap);
    benchmark::DoNotOptimize(r);
  }
  common_counters(state, s);
  state.counters["pops"] = r.lowered_steps;
}

// The frame where the initial levels already fit: only the totals pass runs.
void BM_SelectWithinBudget(benchmark::State& state) {
  const BenchScene& s = scene_of(static_cast<size_t>(state.range(0)));
  std::vector<uint8_t> level(s.initial);
  std::vector<HeapEntry> heap(s.objects.size());
  SelectionParams loose;
  loose.budget = UINT64_MAX;
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        select_under_budget(level, s.state.visible, s.state.weight, s.objects.model, s.models, loose, heap));
  }
  common_counters(state, s);
}

void BM_SelectPriorityQueue(benchmark::State& state) {
  const BenchScene& s = scene_of(static_cast<size_t>(state.range(0)));
  const SelectionParams params = budget_of(s, state.range(1));
  const std::vector<uint8_t>& start = start_of(s, state.range(1));
  const ModelTable& t = s.models;
  const std::vector<uint32_t>& model = s.objects.model;
  const std::vector<float>& weight = s.state.weight;
  std::vector<uint8_t> level(s.objects.size());
  uint32_t pops = 0;
  auto worse = [](const HeapEntry& a, const HeapEntry& b) {
    return a.key < b.key || (a.key == b.key && a.object > b.object);
  };
  for (auto _ : state) {
    std::copy(start.begin(), start.end(), level.begin());
    auto key = [&](uint32_t i) {
      const uint32_t at = t.first_level[model[i]] + level[i];
      return weight[i] * static_cast<float>(span_of_level_changed(t.level_l[at], t.level_l[at + 1]));
    };
    std::priority_queue<HeapEntry, std::vector<HeapEntry>, decltype(worse)> q(worse);
    uint64_t cost = 0;
    for (uint32_t i = 0; i < level.size(); ++i) {
      if (!s.state.visible[i]) continue;
      cost += level_cost(t, model[i], level[i], params.count);
      if (level[i] + 1u < t.level_count[model[i]]) q.push({key(i), i});
    }
    pops = 0;
    while (cost > params.budget && !q.empty()) {
      const uint32_t i = q.top().object;
      q.pop();
      cost -= level_cost(t, model[i], level[i], params.count) -
              level_cost(t, model[i], level[i] + 1u, params.count);
      ++level[i];
      ++pops;
      if (level[i] + 1u < t.level_count[model[i]]) q.push({key(i), i});
    }
    benchmark::DoNotOptimize(cost);
  }
  common_counters(state, s);
  state.counters["pops"] = pops;
}

#define LOD_SIZES ->Arg(1000)->Arg(10000)->Arg(100000)
BENCHMARK(BM_StreamBaseline) LOD_SIZES;
BENCHMARK(BM_Cull) LOD_SIZES;
BENCHMARK(BM_Measure) LOD_SIZES;
BENCHMARK(BM_Weights) LOD_SIZES;
BENCHMARK(BM_InitialLevels) LOD_SIZES;
#define LOD_SIZES_AND_BUDGETS ->ArgsProduct({{1000, 10000, 100000}, {0, 1}})
BENCHMARK(BM_Select) LOD_SIZES_AND_BUDGETS;
BENCHMARK(BM_SelectWithinBudget) LOD_SIZES;
BENCHMARK(BM_SelectPriorityQueue) LOD_SIZES_AND_BUDGETS;

}  // namespace

BENCHMARK_MAIN();
