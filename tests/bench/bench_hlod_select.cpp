// Cost of one HLOD cut per frame (select_hlod_cut) on a 10,000-node tree along a moving
// camera: all resident, partly resident, under a budget that bites, and the worst case where
// the cut visits every node. Target: <= 0.3 ms per frame on the 2-core machine.
// Baseline in the same binary: the breadth-first visit alone at the same views (a loop that
// only transforms and culls every node's sphere), so the ratio says what the cut logic adds.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "runtime/hlod_select.h"
#include "runtime/world_bounds.h"
#include "unit/runtime/hlod_fixtures.h"

namespace {

using namespace lod;

const HlodTree& tree_10k() {
  // A random octree of about 10,000 nodes, uneven like a real scan's (grown breadth-first
  // until the node cap, depth up to 10).
  static const HlodTree t = test::random_octree(17, 10000, 10);
  return t;
}

std::vector<View> orbit_views(float radius, int count) {
  std::vector<View> views;
  for (int i = 0; i < count; ++i) {
    const float a = 6.2831853f * float(i) / float(count);
    View v;
    v.eye = glm::vec3(radius * std::cos(a), 0.3f * radius, radius * std::sin(a));
    v.target = glm::vec3(0, 0, 0);
    v.far_plane = 1e5f;
    views.push_back(v);
  }
  return views;
}

Transform placed() {
  Transform t;
  t.position[0] = 5;
  t.rotation[1] = 0.2f;
  t.rotation[3] = 1;
  t.scale = 1.5f;
  return t;
}

void run_cut(benchmark::State& state, float radius, float pixel_error, uint32_t resident_percent,
             uint64_t budget) {
  const HlodTree& t = tree_10k();
  std::mt19937 rng(1);
  std::vector<uint8_t> resident(t.nodes.size(), 1);
  for (size_t i = 1; i < resident.size(); ++i) resident[i] = rng() % 100 < resident_percent;
  const std::vector<View> views = orbit_views(radius, 256);
  std::vector<HlodView> hviews;
  for (const View& v : views) hviews.push_back(hlod_view_of(v));
  HlodCut cut;
  HlodCutScratch scratch;
  prepare_hlod_cut(cut, scratch, t);
  const Transform tr = placed();
  size_t frame = 0, visited = 0, drawn = 0, requests = 0, undone = 0, wanted = 0, triangles = 0;
  for (auto _ : state) {
    select_hlod_cut(cut, scratch, t, resident, tr, hviews[frame++ % hviews.size()], {pixel_error, budget});
    benchmark::DoNotOptimize(cut.triangles);
    visited += scratch.queue.size();
    drawn += cut.drawn.size();
    requests += cut.requests.size();
    undone += cut.undone;
    wanted += cut.wanted_triangles;
    triangles += cut.triangles;
  }
  const double n = double(state.iterations());
  state.counters["nodes"] = double(t.nodes.size());
  state.counters["visited"] = double(visited) / n;
  state.counters["drawn"] = double(drawn) / n;
  state.counters["requests"] = double(requests) / n;
  state.counters["undone"] = double(undone) / n;
  state.counters["wanted_tris"] = double(wanted) / n;
  state.counters["tris"] = double(triangles) / n;
}

void BM_HlodCutResident(benchmark::State& state) { run_cut(state, 150, 1.0f, 100, UINT64_MAX); }
void BM_HlodCutPartlyResident(benchmark::State& state) { run_cut(state, 150, 1.0f, 70, UINT64_MAX); }
// Budgets at 87 % of the wanted cut (~104k triangles; the undoing pass) and at 34 % (refining).
void BM_HlodCutUnderBudgetUndo(benchmark::State& state) { run_cut(state, 150, 0.5f, 100, 90000); }
void BM_HlodCutUnderBudgetRefine(benchmark::State& state) { run_cut(state, 150, 0.5f, 100, 35000); }
// P so small that every node wants to open: the cut visits all 10,000 nodes.
void BM_HlodCutEveryNode(benchmark::State& state) { run_cut(state, 150, 1e-4f, 100, UINT64_MAX); }
void BM_HlodCutEveryNodeUnderBudget(benchmark::State& state) { run_cut(state, 150, 1e-4f, 100, 100000); }
// The undoing pass's worst case: every node visited, 40 % of the wanted cut to undo.
void BM_HlodCutEveryNodeUndoing40Percent(benchmark::State& state) {
  run_cut(state, 150, 1e-4f, 100, 4700000);
}

// Baseline: transform and cull every node's sphere, nothing else.
void BM_SphereCullEveryNode(benchmark::State& state) {
  const HlodTree& t = tree_10k();
  const std::vector<View> views = orbit_views(150, 256);
  std::vector<Frustum> frusta;
  for (const View& v : views) frusta.push_back(frustum_of(v));
  const Transform tr = placed();
  size_t frame = 0;
  for (auto _ : state) {
    const Frustum& f = frusta[frame++ % frusta.size()];
    uint32_t inside = 0;
    for (const HlodNode& n : t.nodes) {
      const Sphere s = world_sphere(tr, n.bounds);
      bool in = true;
      for (const glm::vec4& p : f.planes)
        in &= p.x * s.center[0] + p.y * s.center[1] + p.z * s.center[2] + p.w >= -s.radius;
      inside += in;
    }
    benchmark::DoNotOptimize(inside);
  }
  state.counters["nodes"] = double(t.nodes.size());
}

BENCHMARK(BM_HlodCutResident)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_HlodCutPartlyResident)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_HlodCutUnderBudgetUndo)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_HlodCutUnderBudgetRefine)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_HlodCutEveryNode)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_HlodCutEveryNodeUnderBudget)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_HlodCutEveryNodeUndoing40Percent)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SphereCullEveryNode)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
