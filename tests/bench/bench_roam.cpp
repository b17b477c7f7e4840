// ROAM terrain benchmarks on a 1,025 x 1,025 grid: the deal.II step-53 SRTM
// topography (scripts/fetch-topography.sh) resampled bilinearly, or generated ridges + noise
// when the file is absent. The camera flies a straight line 800 m above the ground at a steady
// pace (0.05 % of the terrain's side per frame), looking ahead and down, 1280 x 720, 60 degrees.
//
//   BM_RoamFlight/0   per-frame incremental update at 1 pixel of projected error; every 8th
//                     frame the same view is also built from scratch in a second state (reset +
//                     update to the same target): counters median_update_ms, median_rebuild_ms,
//                     ratio = rebuild / update (frame-to-frame coherence), triangles,
//                     changes (splits + merges) per frame, rekeyed front diamonds per frame,
//                     target_missed_frames (target not met although the error allowed it)
//   BM_RoamFlight/1   the same at a triangle-count target (50,000)
//   BM_RoamFlight/2   the same at 0.1 pixel (a finer mesh at a pixel-error target)
//   BM_RoamFlight/3   the time target: the 50,000-triangle loop stopped at max_ms = 0.25 by the
//                     steady clock (rebuilds without the limit): also max_update_ms,
//                     time_bound_frames, median_error_px (the largest projected error left)
//   BM_RoamFlight/4   0.1 pixel with max_ms = 0.25 (the same counters)
//   BM_RoamReset      the part of a rebuild that clears the per-sample state (O(grid))
//   BM_RoamVsChunked/T/P  the baseline: Ulrich's chunked LOD (runtime/chunked_terrain.h, P x P
//                     cell patches with skirts) selected on the same flight at the same projected
//                     error, T/10 pixels, against ROAM's drawn (frustum-culled) list:
//                     tris_ratio = ROAM / chunked triangles drawn (skirts included; _no_skirts
//                     without), median_roam_update_ms, median_chunked_select_ms, chunks
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <vector>

#include "preprocess/height_field_io.h"
#include "runtime/chunked_terrain.h"
#include "runtime/roam.h"

namespace {

using namespace lod;

HeightField generated_field(uint32_t size) {
  HeightField f;
  f.width = f.height = size;
  f.cell_size_x = f.cell_size_y = 30.f;
  f.heights.resize(f.sample_count());
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> noise(-4.f, 4.f);
  for (uint32_t y = 0; y < size; ++y)
    for (uint32_t x = 0; x < size; ++x)
      f.heights[size_t(y) * size + x] = 400.f * std::sin(0.013f * float(x)) * std::cos(0.009f * float(y)) +
                                        120.f * std::sin(0.05f * float(x + 2 * y)) + noise(rng);
  return f;
}

const RoamTerrain& terrain() {
  static RoamTerrain t = [] {
    // The fetched topography: build/data of the source tree, else this build's data directory.
    std::filesystem::path real = std::filesystem::path(LOD_SOURCE_DIR) / "build" / "data" / "topography.txt";
    if (!std::filesystem::exists(real)) real = std::filesystem::path(LOD_DATA_DIR) / "topography.txt";
    HeightField f;
    HeightFieldTextOptions o;
    o.coordinates = GridCoordinates::degrees_lat_lon;
    const bool have = std::filesystem::exists(real) && read_height_field_text(real, f, o).ok;
    if (!have) f = generated_field(1025);
    std::fprintf(stderr, "roam bench terrain: %s, %u x %u -> 1025 x 1025\n",
                 have ? real.c_str() : "generated", f.width, f.height);
    const auto t0 = std::chrono::steady_clock::now();
    RoamTerrain built =
        build_roam_terrain(f.width == 1025 && f.height == 1025 ? f : resample_square(f, 1025));
    std::fprintf(stderr, "roam terrain build: %.1f ms\n",
                 std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    return built;
  }();
  return t;
}

float ground_at(const RoamTerrain& t, float wx, float wz) {
  const glm::vec3 far = t.positions.back();
  const uint32_t x = uint32_t(std::clamp(wx / far.x, 0.f, 1.f) * float(t.size - 1));
  const uint32_t y = uint32_t(std::clamp(wz / far.z, 0.f, 1.f) * float(t.size - 1));
  return t.positions[size_t(y) * t.size + x].y;
}

View flight_view(const RoamTerrain& t, int frame) {
  const glm::vec3 far = t.positions.back();
  const float u = 0.15f + 0.0005f * float(frame % 1400);  // along the diagonal, 0.15 .. 0.85
  View v;
  v.eye = {u * far.x, 0, (0.3f + 0.5f * u) * far.z};
  v.eye.y = ground_at(t, v.eye.x, v.eye.z) + 800.f;
  v.target = v.eye + glm::vec3(0.7f * far.x, -0.25f * far.x, 0.5f * far.z) * 1e-3f;
  v.near_plane = 5.f;
  v.far_plane = 2.f * std::max(far.x, far.z);
  return v;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

double steady_ms(const void*) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

RoamParams params_for(int64_t mode) {
  RoamParams p;
  p.pixel_error = mode == 2 || mode == 4 ? 0.1f : 1.f;
  if (mode == 1 || mode == 3) p.target = RoamTarget::triangle_count, p.triangle_count = 50000;
  if (mode == 3) p.target = RoamTarget::time_limit;
  if (mode >= 3) p.max_ms = 0.25f, p.clock = {&steady_ms, nullptr};
  return p;
}

template <class F>
double ms_of(F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// A frame misses its target when the error still allowed meeting it: at a pixel target, a
// visible leaf above tau without the operation budget having stopped the update; at a count
// target, a count outside [target - 2, target] (one diamond) while visible error was left.
bool target_missed(const RoamState& s, const RoamParams& p, const RoamFrameStats& st) {
  const float top = s.split_queue.heap.empty() ? 0.f : s.priority[s.split_queue.heap.front()];
  if (st.time_bound) return false;  // the clock, not the error, stopped it
  if (p.target == RoamTarget::pixel_error) return top > p.pixel_error && !st.budget_bound;
  const bool short_of = st.triangles + 2 < p.triangle_count && top > 0;
  return short_of || st.triangles > p.triangle_count;
}

void BM_RoamFlight(benchmark::State& state) {
  const RoamTerrain& t = terrain();
  const RoamParams p = params_for(state.range(0));
  RoamParams unlimited = p;
  unlimited.max_ms = 0;
  RoamState s, fresh;
  roam_reset(s, t);
  roam_reset(fresh, t);
  roam_update(s, t, flight_view(t, 0), p);  // settle the first frame outside the timing
  std::vector<double> update_ms, rebuild_ms, error_px;
  double tris = 0, changes = 0, rekeyed = 0, missed = 0, time_bound = 0;
  int frame = 1;
  for (auto _ : state) {
    const View v = flight_view(t, frame);
    RoamFrameStats st;
    const double ms = ms_of([&] { st = roam_update(s, t, v, p); });
    state.SetIterationTime(ms * 1e-3);
    update_ms.push_back(ms);
    tris += st.triangles, changes += st.splits + st.merges, rekeyed += st.rekeyed;
    missed += target_missed(s, p, st);
    time_bound += st.time_bound;
    error_px.push_back(s.split_queue.heap.empty() ? 0.0 : s.priority[s.split_queue.heap.front()]);
    if (frame % 8 == 0)
      rebuild_ms.push_back(ms_of([&] {
        roam_reset(fresh, t);
        roam_update(fresh, t, v, unlimited);
      }));
    ++frame;
  }
  const double n = double(update_ms.size());
  state.counters["median_update_ms"] = median(update_ms);
  state.counters["median_rebuild_ms"] = median(rebuild_ms);
  state.counters["ratio"] = median(rebuild_ms) / std::max(median(update_ms), 1e-9);
  state.counters["triangles"] = tris / n;
  state.counters["changes_per_frame"] = changes / n;
  state.counters["rekeyed_per_frame"] = rekeyed / n;
  state.counters["target_missed_frames"] = missed;
  state.counters["max_update_ms"] = *std::max_element(update_ms.begin(), update_ms.end());
  state.counters["time_bound_frames"] = time_bound;
  state.counters["median_error_px"] = median(error_px);
}
BENCHMARK(BM_RoamFlight)->DenseRange(0, 4)->Unit(benchmark::kMillisecond)->UseManualTime()->Iterations(400);

void BM_RoamReset(benchmark::State& state) {
  const RoamTerrain& t = terrain();
  RoamState s;
  for (auto _ : state) {
    roam_reset(s, t);
    benchmark::DoNotOptimize(s.split.data());
  }
}
BENCHMARK(BM_RoamReset)->Unit(benchmark::kMillisecond);

void BM_RoamVsChunked(benchmark::State& state) {
  const RoamTerrain& t = terrain();
  const uint32_t patch = uint32_t(state.range(1));
  static std::vector<ChunkedTerrain> built;  // by patch size, built once
  auto it = std::find_if(built.begin(), built.end(), [&](const ChunkedTerrain& c) { return c.patch == patch; });
  if (it == built.end()) {
    const double ms = ms_of([&] { built.push_back(build_chunked_terrain(t, patch)); });
    std::fprintf(stderr, "chunked terrain build (patch %u): %zu nodes, %.1f ms\n", patch, built.back().nodes.size(), ms);
    it = built.end() - 1;
  }
  const ChunkedTerrain& chunked = *it;
  RoamParams p;
  p.pixel_error = float(state.range(0)) / 10;
  RoamState s;
  roam_reset(s, t);
  roam_update(s, t, flight_view(t, 0), p);
  std::vector<uint32_t> drawn, chunks;
  std::vector<double> roam_ms, chunk_ms;
  double roam_tris = 0, chunk_tris = 0, chunk_count = 0, skirts = 0;
  int frame = 1;
  for (auto _ : state) {
    const View v = flight_view(t, frame++);
    const double ms = ms_of([&] { roam_update(s, t, v, p); });
    state.SetIterationTime(ms * 1e-3);
    roam_ms.push_back(ms);
    roam_tris += double(roam_visible_triangles(drawn, s, t));
    ChunkedSelection sel;
    chunk_ms.push_back(ms_of([&] { sel = select_chunks(chunks, chunked, v, p.pixel_error); }));
    chunk_tris += double(sel.triangles), skirts += double(sel.skirt_triangles), chunk_count += sel.chunks;
  }
  const double n = double(roam_ms.size());
  state.counters["roam_triangles"] = roam_tris / n;
  state.counters["chunked_triangles"] = chunk_tris / n;
  state.counters["chunks"] = chunk_count / n;
  state.counters["tris_ratio"] = roam_tris / std::max(chunk_tris, 1.0);
  state.counters["tris_ratio_no_skirts"] = roam_tris / std::max(chunk_tris - skirts, 1.0);
  state.counters["median_roam_update_ms"] = median(roam_ms);
  state.counters["median_chunked_select_ms"] = median(chunk_ms);
}
BENCHMARK(BM_RoamVsChunked)->ArgsProduct({{10, 5, 2}, {32, 8}})->Unit(benchmark::kMillisecond)->UseManualTime()->Iterations(400);

}  // namespace

BENCHMARK_MAIN();
