// The scene_hlod node through a service: far away, merged proxies stand for the static
// objects, which leave the frame; proxies count in M; a moved object's proxies are opened.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "jobs/scene_hlod_bake.h"
#include "jobs/service.h"
#include "preprocess/lod_bake.h"
#include "test_support.h"

namespace lod {
namespace {

struct Fixture {
  SceneConfig config;
  Scene scene;
  std::shared_ptr<SceneHlodTree> tree = std::make_shared<SceneHlodTree>();
};

LodChain baked_sphere(int rings) {
  const auto dir = test::temp_dir("scene-hlod-frame");
  test::write_text(dir / "s.off", test::sphere_off(rings, 2 * rings));
  BakeSettings settings;
  settings.ratios = {1.0f, 0.25f, 0.08f};
  LodChain chain;
  EXPECT_TRUE(bake_model(dir / "s.off", "s" + std::to_string(rings), settings, chain, nullptr, nullptr).ok);
  return chain;
}

// 60 static spheres on a 100 x 100 field, then 6 that wander (never in a proxy).
const Fixture& fixture() {
  static const Fixture f = [] {
    Fixture x;
    x.config.models = {ModelConfig{"small", {}, {}}, ModelConfig{"large", {}, {}}};
    InstanceConfig still;
    still.model = 0;
    still.count = 60;
    still.box_min[0] = still.box_min[2] = -50;
    still.box_max[0] = still.box_max[2] = 50;
    still.scale_min = 1, still.scale_max = 2;
    InstanceConfig movers = still;
    movers.model = 1;
    movers.count = 6;
    movers.motion.kind = MotionKind::wander;
    movers.motion.speed = 1;
    x.config.instances = {still, movers};
    x.config.scene_hlod.enabled = true;
    x.scene = make_scene(x.config, {baked_sphere(12), baked_sphere(16)});
    EXPECT_TRUE(bake_scene_hlod(x.config, x.scene, nullptr, *x.tree).ok);
    return x;
  }();
  return f;
}

// Looking at the field's centre from (0, z / 2, z).
Camera from(float z) {
  Camera c;
  c.eye[1] = z / 2;
  c.eye[2] = z;
  const float len = std::sqrt(z * z / 4 + z * z);
  c.forward[0] = 0, c.forward[1] = -z / 2 / len, c.forward[2] = -z / len;
  c.far_z = 1e6f;
  return c;
}

std::unique_ptr<Service> service_over(const Fixture& f, uint64_t budget, std::vector<ObjectHandle>& handles,
                                      float pixel_error = 1.0f) {
  FrameGraphOptions o;
  o.threads = 2;
  o.pixel_error = pixel_error;
  o.selection.budget = budget;
  o.scene_hlod = f.tree;
  return make_service(f.scene, o, 0, &handles);
}

// Tree objects under the drawn proxies, as scene indices.
std::vector<uint32_t> covered(const SceneHlodTree& t, const Frame& frame) {
  std::vector<uint32_t> out;
  for (uint32_t id : frame.scene_proxies)
    for (uint32_t j = t.nodes[id].first_object; j < t.nodes[id].first_object + t.nodes[id].object_count; ++j)
      out.push_back(t.objects[j].scene_index);
  std::sort(out.begin(), out.end());
  return out;
}

uint64_t level_triangles(const Frame& f, const Scene& scene) {
  uint64_t tris = 0;
  for (size_t k = 0; k < f.levels.size(); ++k)
    tris += scene.models.triangles[scene.models.first_level[f.models[k]] + f.levels[k]];
  return tris;
}

TEST(SceneHlodFrame, FarAwayProxiesStandForTheStaticObjectsWhichLeaveTheFrame) {
  const Fixture& f = fixture();
  ASSERT_FALSE(f.tree->empty());
  EXPECT_EQ(f.tree->objects.size(), 60u) << "the wandering block is not in the tree";
  std::vector<ObjectHandle> handles;
  auto s = service_over(f, 10000000, handles);
  ASSERT_TRUE(s->set_view(0, from(3000)));
  ASSERT_TRUE(s->step(1.0 / 60));
  const FrameRef frame = s->acquire_frame();
  ASSERT_FALSE(frame->scene_proxies.empty());
  const std::vector<uint32_t> under = covered(*f.tree, *frame);
  EXPECT_EQ(under.size(), frame->scene_proxy_objects);
  for (ObjectHandle h : frame->handles) {
    const auto i = uint32_t(std::find(handles.begin(), handles.end(), h) - handles.begin());
    EXPECT_FALSE(std::binary_search(under.begin(), under.end(), i)) << "object " << i << " drawn twice";
  }
  EXPECT_EQ(frame->visible + frame->scene_proxy_objects, 66u) << "every object is drawn one way or the other";
  uint64_t proxy_tris = 0;
  for (uint32_t id : frame->scene_proxies) proxy_tris += f.tree->nodes[id].triangles();
  EXPECT_EQ(frame->scene_proxy_tris, proxy_tris);
  EXPECT_EQ(frame->tris_selected, level_triangles(*frame, f.scene) + proxy_tris) << "proxies count in M";
  EXPECT_LT(frame->scene_proxies.size() + frame->visible, 66u) << "fewer draws than objects";
}

TEST(SceneHlodFrame, CloseByEveryObjectIsItsOwn) {
  const Fixture& f = fixture();
  std::vector<ObjectHandle> handles;
  auto s = service_over(f, 10000000, handles);
  ASSERT_TRUE(s->set_view(0, from(20)));
  ASSERT_TRUE(s->step(1.0 / 60));
  EXPECT_TRUE(s->acquire_frame()->scene_proxies.empty());
}

TEST(SceneHlodFrame, AMovedOrDestroyedObjectIsNeverInADrawnProxy) {
  const Fixture& f = fixture();
  std::vector<ObjectHandle> handles;
  auto s = service_over(f, 10000000, handles);
  ASSERT_TRUE(s->set_view(0, from(3000)));
  ASSERT_TRUE(s->step(1.0 / 60));
  std::vector<uint32_t> before = covered(*f.tree, *s->acquire_frame());
  ASSERT_GE(before.size(), 2u);
  const uint32_t moved = before[0], gone = before.back();
  Transform t = transform_of(f.scene.objects, moved);
  t.position[0] += 0.5f;
  ASSERT_TRUE(s->set_transform(handles[moved], t));
  ASSERT_TRUE(s->destroy(handles[gone]));
  s->commit(1);
  ASSERT_TRUE(s->step(1.0 / 60));
  const FrameRef frame = s->acquire_frame();
  const std::vector<uint32_t> after = covered(*f.tree, *frame);
  EXPECT_FALSE(std::binary_search(after.begin(), after.end(), moved));
  EXPECT_FALSE(std::binary_search(after.begin(), after.end(), gone));
  EXPECT_NE(std::find(frame->handles.begin(), frame->handles.end(), handles[moved]), frame->handles.end())
      << "the moved object is drawn on its own";
  // Moved back exactly where it was built: its proxies may be drawn again.
  ASSERT_TRUE(s->set_transform(handles[moved], transform_of(f.scene.objects, moved)));
  s->commit(2);
  ASSERT_TRUE(s->step(1.0 / 60));
  const std::vector<uint32_t> back = covered(*f.tree, *s->acquire_frame());
  EXPECT_TRUE(std::binary_search(back.begin(), back.end(), moved));
}

TEST(SceneHlodFrame, TheBudgetHoldsWithProxiesInIt) {
  const Fixture& f = fixture();
  std::vector<ObjectHandle> handles;
  auto unbound = service_over(f, 10000000, handles, 0.3f);
  // Near enough that the objects not under a proxy are drawn finer than their coarsest level.
  float z = 0;
  uint64_t loose = 0, floor = 0, proxies = 0;
  for (float at : {400.f, 300.f, 200.f, 150.f, 100.f, 70.f}) {
    ASSERT_TRUE(unbound->set_view(0, from(at)));
    ASSERT_TRUE(unbound->step(1.0 / 60));
    const FrameRef lf = unbound->acquire_frame();
    if (lf->scene_proxy_tris == 0 || lf->tris_selected <= lf->coarsest_cost + lf->scene_proxy_tris) continue;
    z = at, loose = lf->tris_selected, floor = lf->coarsest_cost + lf->scene_proxy_tris, proxies = lf->scene_proxy_tris;
    break;
  }
  ASSERT_GT(z, 0) << "no view with proxies and objects above their coarsest levels";
  const uint64_t budget = (loose + floor) / 2;
  auto s = service_over(f, budget, handles, 0.3f);
  ASSERT_TRUE(s->set_view(0, from(z)));
  ASSERT_TRUE(s->step(1.0 / 60));
  const FrameRef frame = s->acquire_frame();
  EXPECT_FALSE(frame->over_budget);
  EXPECT_LE(frame->tris_selected, budget) << "levels lowered so that levels + proxies fit M";
  EXPECT_EQ(frame->scene_proxy_tris, proxies);
}

}  // namespace
}  // namespace lod
