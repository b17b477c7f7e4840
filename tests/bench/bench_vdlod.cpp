// View-dependent LOD benchmarks on a ~1M-triangle mesh: the Stanford bunny scan
// subdivided twice (1-to-4 midpoint), or a generated 1M-triangle sphere when the scan is absent.
//
//   BM_HierarchyBuild      build time of the vertex hierarchy (quadric order)
//   BM_FrontSmooth         one frame of front update, camera moving 0.5 % of the model's size
//                          per frame, threshold feedback holding ~200k active triangles;
//                          counters: median_ms, changes (splits + collapses) per frame, visited
//   BM_FrontFullPass       baseline in the same binary: the same frames, every node re-judged
//                          (no temporal coherence); ratio = smooth / full in BM_FrontSmooth
//   BM_FrontScaling        cost vs changes and vs active size: camera speed (Arg 0, per mille of
//                          the model's size per frame) x target active triangles (Arg 1, k)
//   BM_FrontSmoothRegions  the same motion on the mesh's hierarchy built in 2 parts (seam kept),
//                          its 2 region fronts updated one after the other (Arg 1) or on 2
//                          threads (Arg 2); one shared threshold; ratio = 1 thread / 2 threads
//   BM_FrontTeleport       a jump across the model under a triangle cap: frames to settle,
//                          most triangles seen vs the cap
//   BM_SplitCollapse       raw splits + collapses per second on one core (refine all, coarsen all)
//   BM_CompactMesh         the vd_mesh stage's copy of a ~200k-triangle front into a frame (baseline)
//   BM_CompactMeshNormals  the same plus the smooth normals the frame now carries
//                          (runtime/vertex_normals.h); the ratio is the stage's cost of normals
//   BM_CompactMeshAttributes  the same copy plus what a tree with TEXCOORD_1, colours and
//                          authored normals adds: each geomorphed straight into the frame's
//                          arrays, the normals renormalised (instead of computed from faces);
//                          ratio to BM_CompactMeshNormals = the stage's cost of those columns
#include <benchmark/benchmark.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numeric>
#include <vector>

#include "preprocess/mesh_clean.h"
#include "preprocess/mesh_io.h"
#include "preprocess/vertex_hierarchy.h"
#include "runtime/geomorph.h"
#include "runtime/vertex_front.h"
#include "runtime/vertex_normals.h"
#include "test_support.h"
#include "vd_meshes.h"

namespace {

using namespace lod;

struct Fixture {
  MeshData mesh;
  VertexTree tree;
  double build_seconds = 0;
  float center[3] = {0, 0, 0};
  float size = 1;  // bounding-box diagonal
};

const MeshData& big_mesh() {
  static MeshData mesh = [] {
    MeshData m;
    const auto scan = test::shared_meshes() / "stanford-bunny.obj";
    if (!test::shared_meshes().empty() && std::filesystem::exists(scan) && load_mesh(scan, m).ok) {
      clean_mesh(m);
      m = test::vd_subdivide(test::vd_subdivide(m));
    } else {
      m = test::vd_sphere(708, 707);
    }
    std::fprintf(stderr, "vdlod bench mesh: %s, %zu triangles\n", m.source.c_str(), m.triangle_count());
    return m;
  }();
  return mesh;
}

Fixture& fixture(uint32_t parts = 1) {
  static std::unique_ptr<Fixture> cache[17];
  std::unique_ptr<Fixture>& f = cache[std::min(parts, 16u)];
  if (!f) f = [parts] {
    auto fx = std::make_unique<Fixture>();
    fx->mesh = big_mesh();
    const auto t0 = std::chrono::steady_clock::now();
    HierarchyOptions options;
    options.parts = parts;
    const Status s = build_vertex_hierarchy(fx->tree, fx->mesh, options);
    fx->build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!s) std::fprintf(stderr, "hierarchy build failed: %s\n", s.message.c_str());
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (size_t v = 0; v < fx->mesh.vertex_count(); ++v)
      for (int k = 0; k < 3; ++k)
        lo[k] = std::min(lo[k], fx->mesh.positions[3 * v + k]),
        hi[k] = std::max(hi[k], fx->mesh.positions[3 * v + k]);
    for (int k = 0; k < 3; ++k) fx->center[k] = 0.5f * (lo[k] + hi[k]);
    fx->size = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                         (hi[2] - lo[2]) * (hi[2] - lo[2]));
    return fx;
  }();
  return *f;
}

// Orbit at 0.6 model sizes from the centre; `step` frames along it.
FrontView orbit_view(const Fixture& fx, double angle, float distance) {
  View v;
  v.eye = glm::vec3(fx.center[0] + distance * std::sin(angle), fx.center[1] + 0.2f * distance,
                    fx.center[2] + distance * std::cos(angle));
  v.target = glm::vec3(fx.center[0], fx.center[1], fx.center[2]);
  v.width = 1920;
  v.height = 1080;
  v.near_plane = 0.001f * fx.size;
  v.far_plane = 100 * fx.size;
  const float origin[3] = {0, 0, 0};
  return front_view_of(v, origin, 1.f, 0.f);
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

void BM_HierarchyBuild(benchmark::State& state) {
  const MeshData& m = big_mesh();
  for (auto _ : state) {
    VertexTree t;
    const auto t0 = std::chrono::steady_clock::now();
    build_vertex_hierarchy(t, m);
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    benchmark::DoNotOptimize(t.parent.data());
    state.counters["nodes"] = t.node_count();
  }
  state.counters["triangles"] = static_cast<double>(m.triangle_count());
}
BENCHMARK(BM_HierarchyBuild)->Unit(benchmark::kMillisecond)->UseManualTime()->Iterations(1);

constexpr uint32_t kTarget = 200000;

// Smooth orbit: an arc step of 0.5 % of the model's size per frame. Arg: hysteresis x 100.
void run_frames(benchmark::State& state, bool full_pass) {
  Fixture& fx = fixture();
  VertexFront front;
  front_init(front, fx.tree, 1.f);
  FrontParams p;
  p.target_triangles = kTarget;
  p.max_triangles = kTarget + kTarget / 10;
  p.hysteresis = static_cast<float>(state.range(0)) / 100;
  const float distance = 0.6f * fx.size;
  const double step = 0.005 * fx.size / distance;
  double angle = 0;
  for (int i = 0; i < 60; ++i)
    front_update(front, fx.tree, orbit_view(fx, angle += step, distance), p);  // settle
  std::vector<double> ms;
  uint64_t changes = 0, visited = 0, frames = 0, tris = 0;
  for (auto _ : state) {
    const FrontView v = orbit_view(fx, angle += step, distance);
    if (full_pass) front.has_view = false;  // forget the last view: every node is judged
    const auto t0 = std::chrono::steady_clock::now();
    const FrontStats s = front_update(front, fx.tree, v, p);
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    state.SetIterationTime(t);
    ms.push_back(1e3 * t);
    changes += s.splits + s.collapses;
    visited += s.visited;
    tris += s.active_tris;
    ++frames;
  }
  state.counters["median_ms"] = median(ms);
  state.counters["changes_per_frame"] = double(changes) / frames;
  state.counters["visited_per_frame"] = double(visited) / frames;
  state.counters["active_tris"] = double(tris) / frames;
}

void BM_FrontSmooth(benchmark::State& state) { run_frames(state, false); }
void BM_FrontFullPass(benchmark::State& state) { run_frames(state, true); }
BENCHMARK(BM_FrontSmooth)
    ->Unit(benchmark::kMicrosecond)
    ->UseManualTime()
    ->Iterations(300)
    ->Arg(150)
    ->Arg(100);
BENCHMARK(BM_FrontFullPass)->Unit(benchmark::kMicrosecond)->UseManualTime()->Iterations(30)->Arg(150);

// The vd_mesh stage's work for one object: its front's vertices and triangles into the frame's
// arrays, with or without the normals. Same settled front for both.
void compact_front(benchmark::State& state, bool normals) {
  Fixture& fx = fixture();
  VertexFront front;
  front_init(front, fx.tree, 1.f);
  FrontParams p;
  p.target_triangles = kTarget;
  p.max_triangles = kTarget + kTarget / 10;
  for (int i = 0; i < 60; ++i) front_update(front, fx.tree, orbit_view(fx, 0, 0.6f * fx.size), p);
  std::vector<float> positions(3 * size_t(front.active_count)), n(positions.size());
  std::vector<uint32_t> tris(3 * size_t(front.tri_count));
  for (auto _ : state) {
    front_compact_mesh(positions, tris, front, fx.tree, {});
    if (normals) area_weighted_normals(n, positions, tris);
    benchmark::DoNotOptimize(positions.data());
    benchmark::DoNotOptimize(n.data());
  }
  state.counters["active_tris"] = double(front.tri_count);
}
void BM_CompactMesh(benchmark::State& state) { compact_front(state, false); }
void BM_CompactMeshNormals(benchmark::State& state) { compact_front(state, true); }
BENCHMARK(BM_CompactMesh)->Unit(benchmark::kMicrosecond)->MinTime(0.5);
BENCHMARK(BM_CompactMeshNormals)->Unit(benchmark::kMicrosecond)->MinTime(0.5);

// The frame graph's per-frame work for a tree with uvs1, colours and normals (values are
// arbitrary: only the copies cost), on the same settled front.
void BM_CompactMeshAttributes(benchmark::State& state) {
  Fixture& fx = fixture();
  VertexFront front;
  front_init(front, fx.tree, 1.f);
  FrontParams p;
  p.target_triangles = kTarget;
  p.max_triangles = kTarget + kTarget / 10;
  for (int i = 0; i < 60; ++i) front_update(front, fx.tree, orbit_view(fx, 0, 0.6f * fx.size), p);
  VertexTree columns;  // only what vertex_morph_init reads
  columns.positions = fx.tree.positions;
  columns.parent = fx.tree.parent;
  const size_t nodes = fx.tree.node_count();
  columns.uvs1.assign(2 * nodes, 0.5f);
  columns.colors.assign(4 * nodes, 0.75f);
  columns.normals.assign(3 * nodes, 0.f);
  for (size_t v = 0; v < nodes; ++v) columns.normals[3 * v + 2] = 1;
  VertexMorph morph;
  vertex_morph_init(morph, columns, 0.25f);
  const size_t nv = front.active_count;
  std::vector<float> positions(3 * nv), uv1(2 * nv), color(4 * nv), n(3 * nv);
  std::vector<uint32_t> tris(3 * size_t(front.tri_count));
  const MorphOutput outputs[] = {{&morph.uv1, uv1}, {&morph.color, color}, {&morph.normal, n}};
  for (auto _ : state) {
    front_compact_mesh(positions, tris, front, fx.tree, {});
    vertex_morph_compact(outputs, morph, front.vertices(), 1.0);
    renormalise(n);
    benchmark::DoNotOptimize(positions.data());
    benchmark::DoNotOptimize(color.data());
    benchmark::DoNotOptimize(n.data());
  }
  state.counters["active_tris"] = double(front.tri_count);
}
BENCHMARK(BM_CompactMeshAttributes)->Unit(benchmark::kMicrosecond)->MinTime(0.5);

// Cost follows the changes (camera speed), not the active size (target triangles).
void BM_FrontScaling(benchmark::State& state) {
  Fixture& fx = fixture();
  VertexFront front;
  front_init(front, fx.tree, 1.f);
  FrontParams p;
  p.target_triangles = static_cast<uint32_t>(state.range(1)) * 1000;
  p.hysteresis = 1.5f;
  const float distance = 0.6f * fx.size;
  const double step = 0.001 * double(state.range(0)) * fx.size / distance;
  double angle = 0;
  for (int i = 0; i < 80; ++i) front_update(front, fx.tree, orbit_view(fx, angle += step, distance), p);
  std::vector<double> ms;
  uint64_t changes = 0, visited = 0, frames = 0, tris = 0;
  for (auto _ : state) {
    const FrontView v = orbit_view(fx, angle += step, distance);
    const auto t0 = std::chrono::steady_clock::now();
    const FrontStats s = front_update(front, fx.tree, v, p);
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    state.SetIterationTime(t);
    ms.push_back(1e3 * t);
    changes += s.splits + s.collapses, visited += s.visited, tris += s.active_tris;
    ++frames;
  }
  state.counters["median_ms"] = median(ms);
  state.counters["changes_per_frame"] = double(changes) / frames;
  state.counters["visited_per_frame"] = double(visited) / frames;
  state.counters["active_tris"] = double(tris) / frames;
  state.counters["us_per_change"] = 1e3 * std::accumulate(ms.begin(), ms.end(), 0.0) / std::max<uint64_t>(changes, 1);
}
BENCHMARK(BM_FrontScaling)
    ->Unit(benchmark::kMicrosecond)
    ->UseManualTime()
    ->Iterations(150)
    ->Args({1, 200})
    ->Args({5, 200})
    ->Args({20, 200})
    ->Args({5, 50})
    ->Args({5, 400});

// One object in kParts regions: the whole frame (every region's front and the shared threshold
// feedback), regions dealt to the threads by TBB's work stealing.
constexpr uint32_t kParts = 8;
void BM_FrontSmoothRegions(benchmark::State& state) {
  Fixture& fx = fixture(kParts);
  std::vector<uint8_t> region;
  const uint32_t regions = vertex_tree_regions(region, fx.tree, kParts);
  std::vector<VertexFront> fronts(regions);
  for (uint32_t r = 0; r < regions; ++r) front_init(fronts[r], fx.tree, 1.f, region, static_cast<uint8_t>(r));
  // What the seam costs: its fixed vertices, and the base mesh (coarsest front) they hold up.
  uint64_t base_tris = 0;
  for (const VertexFront& f : fronts) base_tris += f.tri_count;
  VertexFront whole;
  front_init(whole, fixture().tree, 1.f);
  state.counters["seam_vertices"] = static_cast<double>(std::count(region.begin(), region.end(), kSharedRegion));
  state.counters["base_tris"] = static_cast<double>(base_tris);
  state.counters["base_tris_one_part"] = whole.tri_count;
  // Memory: the regions' fronts (each sized for its own region) against one whole-tree front.
  size_t region_bytes = 0;
  for (const VertexFront& f : fronts) region_bytes += front_memory_bytes(f);
  state.counters["region_fronts_MB"] = double(region_bytes) / 1e6;
  state.counters["whole_front_MB"] = double(front_memory_bytes(whole)) / 1e6;
  FrontParams p;
  // No per-region cap: the shared feedback holds the target; a cap split by region would
  // block the regions in view while the others have room.
  p.hysteresis = 1.5f;
  const int threads = static_cast<int>(state.range(0));
  tbb::task_arena arena(threads);
  const float distance = 0.6f * fx.size;
  const double step = 0.005 * fx.size / distance;
  double angle = 0;
  uint64_t changes = 0, visited = 0, frames = 0, tris = 0;
  double balance = 0;
  auto frame = [&](const FrontView& v) {
    uint64_t total = 0;
    std::vector<FrontStats> st(regions);
    arena.execute([&] {
      tbb::parallel_for(0u, regions, [&](uint32_t r) { st[r] = front_update(fronts[r], fx.tree, v, p); });
    });
    for (uint32_t r = 0; r < regions; ++r) total += st[r].active_tris;
    const float next = front_next_threshold(fronts[0].threshold, total, kTarget, p);
    for (auto& f : fronts) front_set_threshold(f, next);
    uint64_t ch = 0, vis = 0;
    for (uint32_t r = 0; r < regions; ++r) ch += st[r].splits + st[r].collapses, vis += st[r].visited;
    uint32_t most = 1;
    for (const FrontStats& x : st) most = std::max(most, x.visited);
    balance += double(vis) / most / regions;
    return std::array<uint64_t, 3>{total, ch, vis};
  };
  for (int i = 0; i < 60; ++i) frame(orbit_view(fx, angle += step, distance));  // settle
  std::vector<double> ms;
  for (auto _ : state) {
    const FrontView v = orbit_view(fx, angle += step, distance);
    const auto t0 = std::chrono::steady_clock::now();
    const auto r = frame(v);
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    state.SetIterationTime(t);
    ms.push_back(1e3 * t);
    tris += r[0], changes += r[1], visited += r[2];
    ++frames;
  }
  state.counters["regions"] = regions;
  state.counters["visit_balance"] = balance / (frames + 60);  // mean / largest region's visits
  state.counters["median_ms"] = median(ms);
  state.counters["changes_per_frame"] = double(changes) / frames;
  state.counters["visited_per_frame"] = double(visited) / frames;
  state.counters["active_tris"] = double(tris) / frames;
}
BENCHMARK(BM_FrontSmoothRegions)->Unit(benchmark::kMicrosecond)->UseManualTime()->Iterations(300)->Arg(1)->Arg(2);

// Teleport: settle at one side, jump to the opposite side and closer. Frames until the front
// changes by under 1 % of its triangles, the most triangles of any frame vs the cap.
// Arg: max_operations per frame (0 = unlimited): spreads the work of a jump over frames.
void BM_FrontTeleport(benchmark::State& state) {
  Fixture& fx = fixture();
  FrontParams p;
  p.target_triangles = kTarget;
  p.max_triangles = kTarget + kTarget / 10;
  p.max_operations = static_cast<uint32_t>(state.range(0));
  double settle_frames = 0, worst = 0, first_ms = 0, runs = 0, slowest_ms = 0, first_ops = 0,
         first_visits = 0;
  for (auto _ : state) {
    state.PauseTiming();
    VertexFront front;
    front_init(front, fx.tree, 1.f);
    for (int i = 0; i < 60; ++i) front_update(front, fx.tree, orbit_view(fx, 0.0, 0.6f * fx.size), p);
    state.ResumeTiming();
    int frames = 0;
    uint32_t most = 0;
    for (; frames < 20; ++frames) {
      const auto t0 = std::chrono::steady_clock::now();
      const FrontStats s = front_update(front, fx.tree, orbit_view(fx, 3.0, 0.4f * fx.size), p);
      const double ms = 1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (frames == 0) first_ms += ms, first_ops += s.splits + s.collapses, first_visits += s.visited;
      slowest_ms = std::max(slowest_ms, ms);
      most = std::max(most, s.active_tris);
      if (frames > 0 && s.splits + s.collapses < 0.01 * s.active_tris) break;
    }
    settle_frames += frames;
    worst = std::max<double>(worst, double(most) / p.max_triangles);
    ++runs;
  }
  state.counters["frames_to_settle"] = settle_frames / runs;
  state.counters["most_tris_over_cap"] = worst;
  state.counters["first_frame_ms"] = first_ms / runs;
  state.counters["slowest_frame_ms"] = slowest_ms;
  state.counters["first_frame_ops"] = first_ops / runs;
  state.counters["first_frame_visits"] = first_visits / runs;
}
BENCHMARK(BM_FrontTeleport)->Unit(benchmark::kMillisecond)->Iterations(3)->Arg(0)->Arg(50000);

void BM_SplitCollapse(benchmark::State& state) {
  Fixture& fx = fixture();
  VertexFront front;
  front_init(front, fx.tree, 1.f);
  uint64_t ops = 0;
  for (auto _ : state) {
    front_refine_all(front, fx.tree);
    front_coarsen_all(front, fx.tree);
    ops += 2 * uint64_t(fx.tree.interior_count());
  }
  state.SetItemsProcessed(static_cast<int64_t>(ops));
  state.counters["hierarchy_build_s"] = fx.build_seconds;
}
BENCHMARK(BM_SplitCollapse)->Unit(benchmark::kMillisecond)->Iterations(5);

}  // namespace

BENCHMARK_MAIN();
