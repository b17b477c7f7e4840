// The whole per-frame graph (the node table of jobs/frame_graph.cpp) on hand-built scenes of
// 1k, 10k and 100k objects, with 1 and 2 threads, the camera orbiting and a budget that binds,
// static or with 10 % of the objects given a new transform every tick (committed commands the
// commit node applies). Baselines from the same run: 1 thread for 2, static for dynamic; the
// ratios are printed after the table.
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

// Every tick, `percent` of the objects (a window sliding through them) get a new transform:
// the commands a simulation thread would have committed, applied by the commit node.
struct Movers {
  std::vector<ObjectCommand> commands;
  std::vector<Transform> start;
  uint32_t next = 0;

  Movers(const Scene& scene, uint32_t percent) {
    commands.resize(scene.objects.size() * percent / 100);
    for (size_t i = 0; i < scene.objects.size(); ++i) start.push_back(transform_of(scene.objects, i));
  }
  std::span<const CommitBatchRef> tick(uint64_t t, CommitBatchRef& batch) {
    const uint32_t n = static_cast<uint32_t>(start.size());
    for (ObjectCommand& c : commands) {
      const uint32_t i = next++ % n;
      c.handle = make_handle(i, 1);  // the handles FrameGraph(scene) gives its objects
      c.kind = CommandKind::transform;
      c.transform = start[i];
      c.transform.position[0] += float(t % 7);  // a small move, the same on every run
    }
    batch = {t, commands};
    return commands.empty() ? std::span<const CommitBatchRef>() : std::span<const CommitBatchRef>(&batch, 1);
  }
};

void BM_FrameGraph(benchmark::State& state) {
  const uint32_t objects = static_cast<uint32_t>(state.range(0));
  const uint32_t threads = static_cast<uint32_t>(state.range(1));
  const uint32_t moving = static_cast<uint32_t>(state.range(2));
  const BenchScene& bs = scene_of(objects);
  FrameGraphOptions o;
  o.threads = threads;
  o.selection.budget = bs.budget;
  FrameGraph graph(bs.scene, o);
  Movers movers(bs.scene, moving);
  CommitBatchRef batch;
  Frame frame;
  auto run = [&](uint32_t n) {
    const View view = view_at(bs.path, n);
    FrameInput in;
    in.views = std::span(&view, 1);
    in.time = n / 60.0;
    in.commits = movers.tick(n, batch);
    graph.run(in, graph.scene_objects(), frame);
  };
  // Two warm-up frames: the first has no temporal state, allocation happens once.
  run(0);
  run(1);

  std::vector<double> totals;
  std::array<double, kStageCount> stage_sum{};
  double visible = 0, pops = 0;
  uint64_t over = 0;
  uint32_t n = 2;
  for (auto _ : state) {
    run(n++);
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
    ->ArgNames({"objects", "threads", "moving"})
    ->ArgsProduct({{1000, 10000, 100000}, {1, 2}, {0, 10}})
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
    auto find = [&](uint32_t objects, int threads, int moving) -> const Times* {
      const auto it = times_.find("BM_FrameGraph/objects:" + std::to_string(objects) + "/threads:" +
                                  std::to_string(threads) + "/moving:" + std::to_string(moving) + "/real_time");
      return it == times_.end() ? nullptr : &it->second;
    };
    for (uint32_t objects : {1000u, 10000u, 100000u}) {
      for (int moving : {0, 10}) {
        const Times* a = find(objects, 1, moving);
        const Times* b = find(objects, 2, moving);
        if (!a || !b) continue;
        std::printf(
            "speed-up %6u objects, %2d %% moving, 2 vs 1 thread: mean %.2fx, median %.2fx (%.3f -> %.3f ms), min "
            "%.2fx (%.3f -> %.3f ms)\n",
            objects, moving, a->mean / b->mean, a->median / b->median, a->median, b->median, a->min / b->min, a->min,
            b->min);
      }
      for (int threads : {1, 2}) {
        const Times* s = find(objects, threads, 0);
        const Times* d = find(objects, threads, 10);
        if (!s || !d) continue;
        std::printf("dynamic  %6u objects, %d thread(s): 10 %% moving / static, median %.2fx (%.3f vs %.3f ms)\n",
                    objects, threads, d->median / s->median, d->median, s->median);
      }
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
