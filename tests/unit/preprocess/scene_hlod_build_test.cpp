// Scene HLOD build (Zhou and Tian 3.2): the octree over the objects, the proxies, their error bounds
// (checked against the objects' full-detail surfaces), determinism and refused input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <thread>

#include "preprocess/lod_bake.h"
#include "preprocess/scene_hlod_build.h"
#include "preprocess/surface_error.h"
#include "runtime/world_bounds.h"
#include "test_support.h"

namespace lod {
namespace {

struct Objects {
  std::vector<LodChain> chains;
  std::vector<uint32_t> model, scene_index;
  std::vector<Transform> transform;
  std::vector<Sphere> sphere;
  SceneHlodObjectsIn in() const { return {chains, model, transform, sphere, scene_index}; }
};

LodChain baked_sphere(const std::string& tag, int rings) {
  const auto dir = test::temp_dir("scene-hlod-" + tag);
  test::write_text(dir / "s.off", test::sphere_off(rings, 2 * rings));
  BakeSettings settings;
  settings.ratios = {1.0f, 0.25f, 0.08f};
  LodChain chain;
  EXPECT_TRUE(bake_model(dir / "s.off", tag, settings, chain, nullptr, nullptr).ok);
  return chain;
}

// A 12 x 6 grid of two kinds of spheres, 6 units apart, scales 1..2.
const Objects& grid() {
  static const Objects objects = [] {
    Objects o;
    o.chains = {baked_sphere("small", 12), baked_sphere("large", 18)};
    const Sphere spheres[2] = {chain_sphere(o.chains[0]), chain_sphere(o.chains[1])};
    for (uint32_t i = 0; i < 72; ++i) {
      Transform t;
      t.position[0] = float(i % 12) * 6.f;
      t.position[2] = float(i / 12) * 6.f;
      t.scale = 1.f + float(i % 5) * 0.25f;
      o.model.push_back(i % 3 == 0 ? 1 : 0);
      o.transform.push_back(t);
      o.sphere.push_back(world_sphere(t, spheres[o.model.back()]));
      o.scene_index.push_back(100 + i);
    }
    return o;
  }();
  return objects;
}

void serial(size_t n, const std::function<void(size_t)>& body) {
  for (size_t i = 0; i < n; ++i) body(i);
}

void two_threads(size_t n, const std::function<void(size_t)>& body) {
  std::thread other([&] {
    for (size_t i = 1; i < n; i += 2) body(i);
  });
  for (size_t i = 0; i < n; i += 2) body(i);
  other.join();
}

SceneHlodTree build(const Objects& o, const ParallelFor& pf = serial, SceneHlodSettings s = {}) {
  SceneHlodTree t;
  EXPECT_TRUE(build_scene_hlod(o.in(), s, pf, nullptr, t).ok);
  return t;
}

float distance(const float a[3], const float b[3]) {
  const float d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
  return std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

TEST(SceneHlodBuild, NodesNestTheirObjectsAndBoundThem) {
  const Objects& o = grid();
  const SceneHlodTree t = build(o);
  ASSERT_GT(t.nodes.size(), 4u);
  EXPECT_EQ(t.nodes[0].object_count, 72u);
  std::multiset<uint32_t> seen;
  for (const SceneHlodObject& ob : t.objects) seen.insert(ob.scene_index);
  EXPECT_EQ(seen.size(), 72u);
  EXPECT_EQ(std::set<uint32_t>(seen.begin(), seen.end()).size(), 72u) << "every object exactly once";
  for (size_t i = 0; i < t.nodes.size(); ++i) {
    const SceneHlodNode& n = t.nodes[i];
    SCOPED_TRACE("node " + std::to_string(i));
    EXPECT_GE(n.object_count, 2u);
    EXPECT_GT(n.triangles(), 0u);
    uint32_t last_end = n.first_object;
    for (uint32_t c = 0; c < n.child_count; ++c) {
      const SceneHlodNode& k = t.nodes[n.first_child + c];
      EXPECT_GT(n.first_child, i);
      EXPECT_EQ(k.depth, n.depth + 1);
      EXPECT_GE(k.first_object, last_end) << "children in order, disjoint";
      last_end = k.first_object + k.object_count;
      EXPECT_LE(last_end, n.first_object + n.object_count);
      EXPECT_GE(n.error, k.error) << "errors never decrease up the tree";
    }
    for (uint32_t j = n.first_object; j < n.first_object + n.object_count; ++j) {
      const Sphere& s = t.objects[j].sphere;
      EXPECT_LE(distance(s.center, n.bounds.center) + s.radius, n.bounds.radius * 1.0001f + 1e-4f);
    }
  }
}

TEST(SceneHlodBuild, ProxiesAreCoarserThanTheirObjectsAndWithinTheirErrorOfTheFullSurfaces) {
  const Objects& o = grid();
  const SceneHlodTree t = build(o);
  for (size_t i = 0; i < t.nodes.size(); ++i) {
    const SceneHlodNode& n = t.nodes[i];
    SCOPED_TRACE("node " + std::to_string(i));
    // The objects at full detail, in world space.
    std::vector<float> pos;
    std::vector<uint32_t> idx;
    uint64_t coarsest = 0;
    for (uint32_t j = n.first_object; j < n.first_object + n.object_count; ++j) {
      const uint32_t k = t.objects[j].scene_index - 100;
      const LodChain& c = o.chains[o.model[k]];
      const LodLevel& l0 = c.levels[0];
      coarsest += c.levels.back().triangles();
      const uint32_t base = uint32_t(pos.size() / 3);
      float q[4];
      normalized_rotation(o.transform[k], q);
      for (uint32_t v = 0; v < l0.vertex_count; ++v) {
        const float* p = &c.positions[3 * (size_t(l0.first_vertex) + v)];
        const float s[3] = {p[0] * o.transform[k].scale, p[1] * o.transform[k].scale, p[2] * o.transform[k].scale};
        float r[3];
        rotate_by_quaternion(q, s, r);
        for (int a = 0; a < 3; ++a) pos.push_back(r[a] + o.transform[k].position[a]);
      }
      for (uint32_t x = 0; x < l0.index_count; ++x) idx.push_back(base + c.indices[l0.first_index + x]);
    }
    // A small group may keep all (cell_error stops QEM near its objects); the root may not.
    EXPECT_LE(n.triangles(), coarsest) << "a proxy never has more triangles than its objects' coarsest levels";
    if (i == 0) {
      EXPECT_LT(n.triangles(), coarsest / 2);
    }
    SurfaceError e;
    SurfaceErrorSettings es;
    es.surface_samples = 20000;
    const TriangleMeshView full{pos.data(), pos.size() / 3, idx.data(), idx.size()};
    const TriangleMeshView proxy{t.positions.data() + 3 * size_t(n.first_vertex), n.vertex_count,
                                 t.indices.data() + n.first_index, n.index_count};
    ASSERT_TRUE(measure_surface_error(full, proxy, es, e).ok);
    EXPECT_LE(e.max, n.error * 1.1f + 1e-3f) << "the proxy's error bounds its distance to the objects";
  }
}

TEST(SceneHlodBuild, TheSameTreeAtAnyThreadCount) {
  const Objects& o = grid();
  const SceneHlodTree a = build(o, serial), b = build(o, two_threads);
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.indices, b.indices);
  for (size_t i = 0; i < a.nodes.size(); ++i) {
    EXPECT_EQ(a.nodes[i].error, b.nodes[i].error);
    EXPECT_EQ(a.nodes[i].first_object, b.nodes[i].first_object);
  }
  for (size_t j = 0; j < a.objects.size(); ++j) EXPECT_EQ(a.objects[j].scene_index, b.objects[j].scene_index);
}

TEST(SceneHlodBuild, FewObjectsOrObjectsAtOnePointAreHandled) {
  Objects o = grid();
  o.model.resize(1), o.transform.resize(1), o.sphere.resize(1), o.scene_index.resize(1);
  EXPECT_TRUE(build(o).empty()) << "one object: no proxy";
  Objects same = grid();
  for (size_t i = 1; i < same.sphere.size(); ++i) same.sphere[i] = same.sphere[0], same.transform[i] = same.transform[0];
  const SceneHlodTree t = build(same);
  ASSERT_EQ(t.nodes.size(), 1u) << "objects at one point are not split";
  EXPECT_EQ(t.nodes[0].object_count, 72u);
}

TEST(SceneHlodBuild, RefusesObjectsOfUnknownModelsAndRaggedColumns) {
  Objects o = grid();
  o.model[5] = 7;
  SceneHlodTree t;
  const Status st = build_scene_hlod(o.in(), {}, serial, nullptr, t);
  EXPECT_FALSE(st.ok);
  EXPECT_NE(st.message.find("unknown model"), std::string::npos) << st.message;
  Objects r = grid();
  r.sphere.pop_back();
  EXPECT_FALSE(build_scene_hlod(r.in(), {}, serial, nullptr, t).ok);
}

}  // namespace
}  // namespace lod
