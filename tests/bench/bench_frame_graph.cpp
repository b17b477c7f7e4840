// The whole per-frame graph (view -> visibility -> importance -> selection -> vdlod ->
// geomorph -> publish) on hand-built scenes of 1k, 10k and 100k objects, with 1 and 2 threads,
// the camera orbiting and a budget that binds. The 1-thread run of each size is the baseline
// of its 2-thread run: the ratio is printed after the table.
//
// Counters: min_ms / median_ms / p99_ms of the per-frame total, per-stage mean ms (st_<stage>), the
// share of selection in the frame, visible objects and heap pops per frame.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>

#include "jobs/frame_graph.h"
#include "unit/jobs/synthetic_scene.h"

namespace {

using namespace lod;

struct BenchScene {
  Scene scene;
  CameraPath path;
  uint64_t budget = 0;
};

// Built once per size; the budget sits halfway between the coarsest levels and the
// screen-space levels of frame 0, so selection has real work on every frame.
const BenchScene& scene_of(uint32_t objects) {
  static std::map<uint32_t, std::unique_ptr<BenchScene>> cache;
  auto& slot = cache[objects];
  if (!slot) {
    slot = std::make_unique<BenchScene>();
    const float extent = test::extent_for(objects);
    slot->scene = test::synthetic_scene(objects, extent, 3);
    slot->path = test::synthetic_config(objects, extent).camera;
    FrameGraphOptions o;
    o.threads = 1;
    o.selection.budget = UINT64_MAX;
    FrameGraph g(slot->scene, o);
    Frame f;
    g.run(view_at(slot->path, 0), f);
    slot->budget = (f.tris_selected + f.coarsest_cost) / 2;
  }
  return *slot;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(p * static_cast<double>(v.size() - 1) + 0.5)];
}

void BM_FrameGraph(benchmark::State& state) {
  const uint32_t objects = static_cast<uint32_t>(state.range(0));
  const uint32_t threads = static_cast<uint32_t>(state.range(1));
  const BenchScene& bs = scene_of(objects);
  FrameGraphOptions o;
  o.threads = threads;
  o.selection.budget = bs.budget;
  FrameGraph graph(bs.scene, o);
  Frame frame;
  // Two warm-up frames: the first has no temporal state, allocation happens once.
  graph.run(view_at(bs.path, 0), frame);
  graph.run(view_at(bs.path, 1), frame);

  std::vector<double> totals;
  std::array<double, kStageCount> stage_sum{};
  double visible = 0, pops = 0;
  uint64_t over = 0;
  uint32_t n = 2;
  for (auto _ : state) {
    graph.run(view_at(bs.path, n++), frame);
    totals.push_back(frame.total_ms);
    for (size_t s = 0; s < kStageCount; ++s) stage_sum[s] += frame.stage_ms[s];
    visible += frame.visible;
    pops += frame.lowered_steps;
    over += frame.over_budget;
    benchmark::DoNotOptimize(frame.tris_selected);
  }
  const double frames = static_cast<double>(totals.size());
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * objects);
  state.counters["min_ms"] = percentile(totals, 0.0);  // robust to other processes on a shared machine
  state.counters["median_ms"] = percentile(totals, 0.5);
  state.counters["p99_ms"] = percentile(totals, 0.99);
  for (size_t s = 0; s < kStageCount; ++s) state.counters[std::string("st_") + kStageNames[s]] = stage_sum[s] / frames;
  double sum = 0;
  for (double t : totals) sum += t;
  state.counters["sel_share"] = stage_sum[static_cast<size_t>(Stage::selection)] / sum;
  state.counters["visible"] = visible / frames;
  state.counters["pops"] = pops / frames;
  state.counters["over_budget"] = static_cast<double>(over);
}

BENCHMARK(BM_FrameGraph)
    ->ArgNames({"objects", "threads"})
    ->ArgsProduct({{1000, 10000, 100000}, {1, 2}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

// Console output as usual, plus the 2-vs-1-thread speed-up of every size at the end.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      if (r.run_type != Run::RT_Iteration || r.error_occurred) continue;
      const std::string name = r.benchmark_name();
      auto counter = [&](const char* key) {
        const auto it = r.counters.find(key);
        return it == r.counters.end() ? 0.0 : double(it->second);
      };
      times_[name] = {r.GetAdjustedRealTime(), counter("median_ms"), counter("min_ms")};
    }
  }
  void print_ratios() const {
    for (uint32_t objects : {1000u, 10000u, 100000u}) {
      const std::string base = "BM_FrameGraph/objects:" + std::to_string(objects) + "/threads:";
      const auto one = times_.find(base + "1/real_time");
      const auto two = times_.find(base + "2/real_time");
      if (one == times_.end() || two == times_.end()) continue;
      const Times& a = one->second;
      const Times& b = two->second;
      std::printf(
          "speed-up %6u objects, 2 vs 1 thread: mean %.2fx, median %.2fx (%.3f -> %.3f ms), min %.2fx (%.3f "
          "-> %.3f ms)\n",
          objects, a.mean / b.mean, a.median / b.median, a.median, b.median, a.min / b.min, a.min, b.min);
    }
  }

 private:
  struct Times {
    double mean, median, min;
  };
  std::map<std::string, Times> times_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.print_ratios();
  benchmark::Shutdown();
  return 0;
}
