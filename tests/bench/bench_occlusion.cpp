// Occlusion culling on a town of 10,000 objects seen from street level: a grid of box
// buildings along streets, props (small boxes) everywhere between them. The two ways of filling
// the depth buffer compared in the same run:
//   raster  rasterize_occluder (runtime/occlusion.h), the default
//   embree  make_embree_occlusion_tracer (preprocess/embree_occlusion.h): a ray per sample
// BM_Visibility (method: 0 = frustum only, 1 = raster, 2 = embree; faces: building faces split
// faces x faces, 1 = 12 triangles, 4 = 192): the visibility stage on 2 threads, objects the
// frustum keeps, objects occlusion culls and the cull rate, occluder triangles, selected
// triangles. BM_OccluderFill (method, buffer width): one core filling the depth buffer with
// the 48 best occluders of the same view (192-triangle buildings): occluder triangles per
// second, samples per second.
#include <benchmark/benchmark.h>

#include <chrono>

#include "jobs/frame_graph.h"
#include "preprocess/embree_occlusion.h"
#include "runtime/visibility.h"
#include "runtime/world_bounds.h"
#include "unit/jobs/box_chain.h"

namespace {

using namespace lod;

// A box like test::box_chain's with every face split into n x n quads (12 n^2 triangles),
// counter-clockwise seen from outside.
LodChain split_box_chain(const std::string& name, float hx, float hy, float hz, int n) {
  LodChain c;
  c.name = name;
  struct Face {
    float o[3], u[3], v[3];
  };
  const Face faces[6] = {
      {{hx, 0, -hz}, {0, 2 * hy, 0}, {0, 0, 2 * hz}},       {{-hx, 0, -hz}, {0, 0, 2 * hz}, {0, 2 * hy, 0}},
      {{-hx, 2 * hy, -hz}, {0, 0, 2 * hz}, {2 * hx, 0, 0}}, {{-hx, 0, -hz}, {2 * hx, 0, 0}, {0, 0, 2 * hz}},
      {{-hx, 0, hz}, {2 * hx, 0, 0}, {0, 2 * hy, 0}},       {{-hx, 0, -hz}, {0, 2 * hy, 0}, {2 * hx, 0, 0}}};
  for (const Face& f : faces) {
    const uint32_t base = static_cast<uint32_t>(c.positions.size() / 3);
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i)
        for (int a = 0; a < 3; ++a)
          c.positions.push_back(f.o[a] + f.u[a] * float(i) / float(n) + f.v[a] * float(j) / float(n));
    const auto at = [&](int i, int j) { return base + uint32_t(j * (n + 1) + i); };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        c.indices.insert(c.indices.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j),
                                           at(i + 1, j + 1), at(i, j + 1)});
  }
  c.normals.assign(c.positions.size(), 0.f);
  LodLevel l;
  l.index_count = static_cast<uint32_t>(c.indices.size());
  l.vertex_count = static_cast<uint32_t>(c.positions.size() / 3);
  l.level = level_of_triangles(l.index_count / 3);
  l.bounds.center[1] = hy;
  l.bounds.radius = std::sqrt(hx * hx + hy * hy + hz * hz);
  c.levels.push_back(l);
  return c;
}

Scene town(uint32_t objects, int faces) {
  Scene s;
  s.chains = {split_box_chain("building", 7, 12, 7, faces), test::box_chain("prop", 0.7f, 0.7f, 0.7f)};
  s.models = build_model_table(s.chains);
  ObjectSet& o = s.objects;
  o.resize(objects);
  const uint32_t buildings = objects / 10, side = uint32_t(std::ceil(std::sqrt(double(buildings))));
  for (uint32_t i = 0; i < objects; ++i) {
    const bool building = i < buildings;
    o.model[i] = building ? 0 : 1;
    o.scale[i] = 1;
    o.yaw[i] = 0;
    o.y[i] = 0;
    if (building) {  // blocks on a 20 m grid, streets of 6 m between them
      o.x[i] = 20.f * float(i % side) - 10.f * float(side);
      o.z[i] = -20.f * float(i / side);
    } else {  // props scattered over the town, deterministic
      const uint32_t h = i * 2654435761u;
      o.x[i] = (float(h % 10000) / 10000.f - 0.5f) * 20.f * float(side);
      o.z[i] = -float((h >> 13) % 10000) / 10000.f * 20.f * float(side);
    }
  }
  return s;
}

View street_view(float step) {
  View v;
  v.eye = {-10, 1.7f, 5 - step};  // in the street between two columns of blocks
  v.target = {-10, 1.7f, v.eye.z - 100};
  v.far_plane = 2000;
  return v;
}

void BM_Visibility(benchmark::State& state) {
  const int method = int(state.range(0));
  const Scene scene = town(10000, int(state.range(1)));
  FrameGraphOptions o;
  o.threads = 2;
  o.selection.budget = UINT64_MAX;
  o.occlusion.enabled = method != 0;
  if (method == 2) o.occlusion.make_tracer = make_embree_occlusion_tracer;
  FrameGraph g(scene, o);
  Frame f;
  double vis_ms = 0, frames = 0, in_view = 0, occluded = 0, selected = 0;
  float step = 0;
  for (auto _ : state) {
    g.run(street_view(step), f);  // walking down the street
    step = step > 100 ? 0 : step + 0.5f;
    vis_ms += f.stage_ms[size_t(Stage::visibility)];
    in_view += double(f.visible + f.occluded);
    occluded += double(f.occluded);
    selected += double(f.tris_selected);
    ++frames;
  }
  state.counters["visibility_ms"] = vis_ms / frames;
  state.counters["in_view"] = in_view / frames;
  state.counters["occluded"] = occluded / frames;
  state.counters["cull_rate"] = occluded / std::max(1.0, in_view);
  state.counters["occluder_tris"] = double(f.occluder_tris);
  state.counters["selected_tris"] = selected / frames;
}
BENCHMARK(BM_Visibility)
    ->ArgNames({"method", "faces"})
    ->Args({0, 1})
    ->Args({1, 1})
    ->Args({2, 1})
    ->Args({0, 4})
    ->Args({1, 4})
    ->Args({2, 4})
    ->Iterations(200)  // the same 200 frames of the walk for every method
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_OccluderFill(benchmark::State& state) {
  const int method = int(state.range(0)), width = int(state.range(1)), height = width * 9 / 16;
  const Scene scene = town(10000, 4);
  const View view = street_view(0);
  const OcclusionCamera cam = occlusion_camera(view, width, height);
  // The 48 best occluders, as the visibility node picks them.
  const ObjectSet& o = scene.objects;
  std::vector<float> cx(o.size()), cy(o.size()), cz(o.size()), r(o.size());
  std::vector<uint8_t> visible(o.size(), 1), usable = {1, 0};
  std::vector<Transform> transforms(o.size());
  for (uint32_t i = 0; i < o.size(); ++i) {
    transforms[i] = transform_of(o, i);
    const Sphere s = world_sphere(transforms[i], scene.chains[o.model[i]].levels[0].bounds);
    cx[i] = s.center[0], cy[i] = s.center[1], cz[i] = s.center[2], r[i] = s.radius;
  }
  cull_spheres(visible, cx, cy, cz, r, frustum_of(view));
  std::vector<OccluderCandidate> best;
  gather_occluders(best, 48, visible, cx, cy, cz, r, o.model, usable, cam.eye, 0);
  keep_best_occluders(best, 48);
  const LodChain& chain = scene.chains[0];
  std::vector<OccluderMesh> meshes;
  for (const OccluderCandidate& c : best)
    meshes.push_back({chain.positions, chain.indices, transforms[c.object]});
  std::unique_ptr<OcclusionTracer> tracer = method == 2 ? make_embree_occlusion_tracer() : nullptr;
  OcclusionBuffer buffer;
  uint64_t triangles = 0;
  for (auto _ : state) {
    occlusion_clear(buffer, cam);
    if (tracer) {
      buffer.triangles = tracer->prepare(meshes);
      tracer->trace_rows(buffer, cam, 0, height);
    } else {
      for (const OccluderMesh& m : meshes)
        rasterize_occluder(buffer, cam, m.positions, m.indices, m.transform);
    }
    occlusion_finish(buffer);
    triangles += buffer.triangles;
    benchmark::DoNotOptimize(buffer.levels.back().data());
  }
  state.counters["occluder_tris_per_s"] = benchmark::Counter(double(triangles), benchmark::Counter::kIsRate);
  state.counters["samples_per_s"] =
      benchmark::Counter(double(state.iterations()) * width * height, benchmark::Counter::kIsRate);
  state.counters["occluders"] = double(meshes.size());
  size_t covered = 0;
  for (float d : buffer.levels[0]) covered += d < 1e30f;
  state.counters["covered_share"] = double(covered) / double(buffer.levels[0].size());
}
BENCHMARK(BM_OccluderFill)
    ->ArgNames({"method", "width"})
    ->Args({1, 320})
    ->Args({2, 320})
    ->Args({1, 1920})
    ->Args({2, 1920})
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
