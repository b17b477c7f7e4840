// The simulation side of lod::Service on a 100,000-object scene: what staging transform
// updates costs on the simulation thread (one call per object, and one batched call), what
// commit() costs while frames are in flight on the LOD thread, and how long a commit takes to
// appear in a published frame when the service free-runs (in frame periods).
//
// Counters: ns_per_update; commit_p50_us / commit_p99_us / commit_max_us; visible_p50_periods /
// visible_p99_periods (commit -> first frame carrying its tick, over the frame period).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>

#include "jobs/service.h"
#include "unit/jobs/synthetic_scene.h"

namespace {

using namespace lod;
using Clock = std::chrono::steady_clock;

struct Sim {
  std::unique_ptr<Service> service;
  std::vector<ObjectHandle> handles;
  std::vector<Transform> start;
  CameraPath path;
};

Sim make_sim(uint32_t objects, double rate_hz) {
  Sim s;
  const float extent = test::extent_for(objects);
  const Scene scene = test::synthetic_scene(objects, extent, 3);
  s.path = test::synthetic_config(objects, extent).camera;
  FrameGraphOptions o;
  o.threads = 2;
  o.selection.budget = 2000000;
  s.service = make_service(scene, o, rate_hz, &s.handles);
  for (size_t i = 0; i < scene.objects.size(); ++i) s.start.push_back(transform_of(scene.objects, i));
  set_view(*s.service, 0, view_at(s.path, 0));
  s.service->step(1.0 / 60);
  return s;
}

Transform nudged(const Transform& t, uint64_t tick) {
  Transform x = t;
  x.position[0] += 0.01f * float(tick % 13);
  return x;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(p * static_cast<double>(v.size() - 1) + 0.5)];
}

// 100,000 set_transform calls, one per object, then the commit (timed apart).
void BM_StageTransforms(benchmark::State& state) {
  Sim sim = make_sim(100000, 60);
  Service& s = *sim.service;
  const bool batched = state.range(0) != 0;
  std::vector<Transform> next(sim.handles.size());
  uint64_t tick = 1;
  for (auto _ : state) {
    state.PauseTiming();
    for (size_t i = 0; i < next.size(); ++i) next[i] = nudged(sim.start[i], tick);
    state.ResumeTiming();
    if (batched) {
      benchmark::DoNotOptimize(s.set_transforms(sim.handles, next));
    } else {
      for (size_t i = 0; i < next.size(); ++i) benchmark::DoNotOptimize(s.set_transform(sim.handles[i], next[i]));
    }
    state.PauseTiming();
    s.commit(tick++);
    s.step(1.0 / 60);  // drains the batch, so every iteration stages into recycled buffers
    state.ResumeTiming();
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(next.size()));
  state.counters["ns_per_update"] =
      benchmark::Counter(double(next.size()), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_StageTransforms)->ArgName("batched")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// The service free-runs at 60 Hz on its own thread; the simulation stages 10 % of the objects
// and commits every 2 ms, timing commit() itself. A consumer thread polls frames every 0.1 ms
// (not spinning: a 2-core machine has two cores for it, the simulation and the LOD thread) and
// notes when each tick first appears, so commit -> visible is measured to within 0.1 ms.
void BM_CommitWhileRunning(benchmark::State& state) {
  Sim sim = make_sim(100000, 60);
  Service& s = *sim.service;
  const size_t moving = sim.handles.size() / 10;
  std::vector<double> commit_us;
  std::vector<Clock::time_point> committed_at, first_seen;
  committed_at.reserve(4096);
  first_seen.assign(4096, Clock::time_point{});
  std::atomic<bool> stop{false};
  std::thread consumer([&] {
    uint64_t seen = 0;
    while (!stop.load(std::memory_order_relaxed)) {
      std::this_thread::sleep_for(std::chrono::microseconds(100));
      const FrameRef f = s.acquire_frame();
      if (!f || f->tick <= seen) continue;
      const auto now = Clock::now();
      for (uint64_t t = seen + 1; t <= f->tick && t < first_seen.size(); ++t) first_seen[t] = now;
      seen = f->tick;
    }
  });
  uint64_t tick = 1;
  s.start();
  for (auto _ : state) {
    for (size_t k = 0; k < moving; ++k) {
      const size_t i = (tick * moving + k) % sim.handles.size();
      s.set_transform(sim.handles[i], nudged(sim.start[i], tick));
    }
    if (committed_at.size() <= tick) committed_at.resize(tick + 1);
    const auto t0 = Clock::now();
    s.commit(tick);
    const auto t1 = Clock::now();
    committed_at[tick] = t1;
    commit_us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
    ++tick;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(100));  // the last commits reach a frame
  stop.store(true);
  consumer.join();
  s.stop();
  std::vector<double> visible_periods;
  for (uint64_t t = 1; t < tick && t < first_seen.size(); ++t)
    if (first_seen[t] != Clock::time_point{})
      visible_periods.push_back(std::chrono::duration<double>(first_seen[t] - committed_at[t]).count() * 60.0);
  const ServiceStats st = s.stats();
  state.counters["commit_p50_us"] = percentile(commit_us, 0.5);
  state.counters["commit_p99_us"] = percentile(commit_us, 0.99);
  state.counters["commit_max_us"] = percentile(commit_us, 1.0);
  state.counters["visible_p50_periods"] = percentile(visible_periods, 0.5);
  state.counters["visible_p99_periods"] = percentile(visible_periods, 0.99);
  state.counters["visible_max_periods"] = percentile(visible_periods, 1.0);
  state.counters["frame_mean_periods"] = st.mean_ms * 60.0 / 1000.0;
}
BENCHMARK(BM_CommitWhileRunning)->Iterations(600)->Unit(benchmark::kMillisecond)->UseRealTime();

// create then destroy, staged (commits every 1,000 pairs, outside the timing).
void BM_CreateDestroy(benchmark::State& state) {
  Sim sim = make_sim(1000, 60);
  Service& s = *sim.service;
  Transform t;
  uint64_t tick = 1, n = 0;
  for (auto _ : state) {
    const ObjectHandle h = s.create(0, t);
    benchmark::DoNotOptimize(s.destroy(h));
    if (++n % 1000 == 0) {
      state.PauseTiming();
      s.commit(tick++);
      s.step(1.0 / 60);
      state.ResumeTiming();
    }
  }
  state.SetItemsProcessed(int64_t(state.iterations()));
}
BENCHMARK(BM_CreateDestroy);

// acquire_frame + release while the LOD thread free-runs (10,000 objects).
void BM_AcquireRelease(benchmark::State& state) {
  Sim sim = make_sim(10000, 60);
  Service& s = *sim.service;
  s.start();
  for (auto _ : state) {
    const FrameRef f = s.acquire_frame();
    benchmark::DoNotOptimize(f.get());
  }
  s.stop();
}
BENCHMARK(BM_AcquireRelease);

// One driven frame through the public API (set_view + step), 10k and 100k objects, 2 threads.
void BM_Step(benchmark::State& state) {
  Sim sim = make_sim(uint32_t(state.range(0)), 60);
  Service& s = *sim.service;
  uint32_t n = 1;
  for (auto _ : state) {
    set_view(s, 0, view_at(sim.path, n++));
    benchmark::DoNotOptimize(s.step(1.0 / 60));
  }
}
BENCHMARK(BM_Step)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
