// The frame side of streaming never waits on I/O: StreamPager::update's cost per frame with
// loaders that answer at once and with loaders that sleep 20 ms per read (injected), on a
// camera flying over a 4,681-node octree under a budget of a sixth of its bytes. The select
// runs each frame too but is not timed; only update is. Reports mean and p99 per latency and
// their ratios (20 ms / 0 ms); the 0 ms run is the baseline. Fast loaders make update take in
// more loads (and evict more) per frame, so the like-for-like figure is `quiet`: frames that
// took in and evicted nothing, where waiting on a read would show.
#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>
#include <vector>

#include "jobs/stream_pager.h"
#include "runtime/hlod_select.h"
#include "unit/runtime/hlod_fixtures.h"

namespace {

using namespace lod;
using Clock = std::chrono::steady_clock;

const HlodTree& tree() {
  static const HlodTree t = test::full_octree({.depth = 4, .half = 64, .root_error = 16, .triangles = 400});
  return t;
}

HlodView view_at(int frame) {
  const float a = float(frame) * 0.01f;
  View v;
  v.eye = glm::vec3(150 * std::cos(a), 30 * std::sin(3 * a), 150 * std::sin(a)) *
          (0.6f + 0.4f * std::cos(0.5f * a));
  v.far_plane = 1e4f;
  return hlod_view_of(v);
}

Status fill(uint32_t node, HlodPayload& out) {
  out.indices.assign(3 * 64, node);
  out.positions.assign(3 * 64, 0.f);
  out.normals.assign(3 * 64, 0.f);
  return Status::success();
}

// The frame thread's own CPU time: on a shared 2-core machine wall time also counts the
// moments the scheduler gives the core to someone else (the loaders among them).
double thread_cpu_us() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) * 1e6 + double(ts.tv_nsec) * 1e-3;
}

double mean_of(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return s / double(v.size());
}

double p99_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() * 99 / 100];
}

struct Run {
  std::vector<double> update_us, update_cpu_us;
  std::vector<double> quiet_us;  // frames that took in no load and evicted nothing: like for like
  uint64_t loads = 0;
  double mean() const { return mean_of(update_us); }
  double p99() const { return p99_of(update_us); }
  double cpu_mean() const { return mean_of(update_cpu_us); }
  double cpu_p99() const { return p99_of(update_cpu_us); }
};

// `frames` frames of select + update at ~1 kHz (a 1 ms pause between frames, so the loaders
// run between them as they would between real frames); update alone is timed.
Run fly(int latency_ms, int frames) {
  const HlodTree& t = tree();
  uint64_t total = 0;
  for (const HlodNode& n : t.nodes) total += n.resident_bytes;
  StreamPager pager(t, {.loader_threads = 2, .budget_bytes = total / 6, .max_in_flight = 4},
                    [latency_ms](uint32_t n, HlodPayload& out) {
                      if (latency_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(latency_ms));
                      return fill(n, out);
                    });
  HlodCut cut;
  HlodCutScratch scratch;
  prepare_hlod_cut(cut, scratch, t);
  Run run;
  run.update_us.reserve(size_t(frames));
  run.update_cpu_us.reserve(size_t(frames));
  for (int f = 0; f < frames; ++f) {
    select_hlod_cut(cut, scratch, t, pager.residency(), {}, view_at(f), {1.0f, UINT64_MAX});
    const double c0 = thread_cpu_us();
    const Clock::time_point t0 = Clock::now();
    const StreamUpdate& u = pager.update(uint64_t(f + 1), cut.requests, cut.kept);
    run.update_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
    if (u.loaded.empty() && u.evicted.empty()) run.quiet_us.push_back(run.update_us.back());
    run.update_cpu_us.push_back(thread_cpu_us() - c0);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  run.loads = pager.counters().loads;
  return run;
}

void BM_StreamUpdate(benchmark::State& state) {
  const int latency = int(state.range(0));
  Run run;
  for (auto _ : state) run = fly(latency, 1500);
  state.counters["update_mean_us"] = run.mean();
  state.counters["update_p99_us"] = run.p99();
  state.counters["update_cpu_mean_us"] = run.cpu_mean();
  state.counters["update_cpu_p99_us"] = run.cpu_p99();
  state.counters["quiet_mean_us"] = mean_of(run.quiet_us);
  state.counters["quiet_frames"] = double(run.quiet_us.size());
  state.counters["loads"] = double(run.loads);
}
BENCHMARK(BM_StreamUpdate)->Arg(0)->Arg(20)->Iterations(1)->Unit(benchmark::kMillisecond);

// Both latencies in one run, so the ratio is taken on the same machine state.
void BM_StreamUpdateRatio20msTo0ms(benchmark::State& state) {
  Run fast, slow;
  for (auto _ : state) {
    fast = fly(0, 1500);
    slow = fly(20, 1500);
  }
  state.counters["mean_ratio"] = slow.mean() / fast.mean();
  state.counters["p99_ratio"] = slow.p99() / fast.p99();
  state.counters["cpu_mean_ratio"] = slow.cpu_mean() / fast.cpu_mean();
  state.counters["cpu_p99_ratio"] = slow.cpu_p99() / fast.cpu_p99();
  state.counters["quiet_mean_ratio"] = mean_of(slow.quiet_us) / mean_of(fast.quiet_us);
  state.counters["mean_0ms_us"] = fast.mean();
  state.counters["mean_20ms_us"] = slow.mean();
  state.counters["loads_0ms"] = double(fast.loads);
  state.counters["loads_20ms"] = double(slow.loads);
}
BENCHMARK(BM_StreamUpdateRatio20msTo0ms)->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
