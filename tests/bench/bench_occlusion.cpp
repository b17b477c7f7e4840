// The visibility node with and without occlusion culling on a town of 10,000 objects seen
// from street level: a grid of box buildings along streets, props (small boxes) everywhere
// between them. Counters: visibility stage mean ms, objects the frustum keeps, objects
// occlusion culls, occluder triangles rasterised, selected triangles.
#include <benchmark/benchmark.h>

#include "jobs/frame_graph.h"
#include "unit/jobs/box_chain.h"

namespace {

using namespace lod;

Scene town(uint32_t objects) {
  Scene s;
  s.chains = {test::box_chain("building", 7, 12, 7), test::box_chain("prop", 0.7f, 0.7f, 0.7f)};
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

void BM_Visibility(benchmark::State& state) {
  const bool occlusion = state.range(0) != 0;
  static const Scene scene = town(10000);
  FrameGraphOptions o;
  o.threads = 2;
  o.selection.budget = UINT64_MAX;
  o.occlusion.enabled = occlusion;
  FrameGraph g(scene, o);
  View v;
  v.eye = {-10, 1.7f, 5};  // in the street between two columns of blocks
  v.target = {-10, 1.7f, -100};
  v.far_plane = 2000;
  Frame f;
  double vis_ms = 0, frames = 0;
  float step = 0;
  for (auto _ : state) {
    v.eye.z = 5 - step;  // walking down the street
    v.target.z = v.eye.z - 100;
    step = step > 100 ? 0 : step + 0.5f;
    g.run(v, f);
    vis_ms += f.stage_ms[size_t(Stage::visibility)];
    ++frames;
  }
  state.counters["visibility_ms"] = vis_ms / frames;
  state.counters["in_view"] = double(f.visible + f.occluded);
  state.counters["occluded"] = double(f.occluded);
  state.counters["occluder_tris"] = double(f.occluder_tris);
  state.counters["selected_tris"] = double(f.tris_selected);
}
BENCHMARK(BM_Visibility)->ArgName("occlusion")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
