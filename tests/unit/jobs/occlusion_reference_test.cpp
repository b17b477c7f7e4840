// Occlusion culling never culls a visible object: a street of box buildings with props behind
// them, seen from street level; the exact reference is Embree, a primary ray through the
// centre of every pixel of the same view at the occlusion buffer's resolution, and every
// object any ray hits first must be in the frame. It also has to cull: most props behind the
// buildings are hidden.
#include <embree3/rtcore.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <set>

#include "jobs/frame_graph.h"
#include "preprocess/embree_occlusion.h"
#include "runtime/occlusion.h"
#include "runtime/world_bounds.h"
#include "unit/jobs/box_chain.h"

namespace lod {
namespace {

using test::box_chain;

struct Street {
  Scene scene;
  View view;
};

// eye_z = 8: in front of the first buildings; 0: between them, their walls reaching past the
// eye (clipped at the near plane).
Street make_street(float eye_z = 8) {
  Street s;
  s.scene.chains = {box_chain("building", 6, 9, 6), box_chain("prop", 0.6f, 0.6f, 0.6f)};
  s.scene.models = build_model_table(s.scene.chains);
  ObjectSet& o = s.scene.objects;
  auto add = [&](uint32_t model, float x, float z) {
    const size_t i = o.size();
    o.resize(i + 1);
    o.model[i] = model, o.x[i] = x, o.y[i] = 0, o.z[i] = z, o.scale[i] = 1, o.yaw[i] = 0;
  };
  // Buildings in two rows along the street (x = +-10), with narrow gaps; props behind and
  // between them, and a few in the street itself.
  for (int k = 0; k < 20; ++k) {
    add(0, -10, -14.f * k);
    add(0, 10, -14.f * k);
  }
  for (int k = 0; k < 60; ++k) {
    for (float x : {-22.f, -30.f, 22.f, 30.f}) add(1, x + float(k % 3), -4.7f * k);
    if (k % 10 == 0) add(1, float(k % 7) - 3, -4.7f * k);
  }
  s.view.eye = {0, 1.7f, eye_z};
  s.view.target = {0, 1.5f, -100};
  s.view.width = 320;
  s.view.height = 180;
  s.view.near_plane = 0.3f;
  s.view.far_plane = 1000;
  return s;
}

// Objects hit first by a ray through the centre of every pixel of a width x height frame.
std::set<uint32_t> reference_visible(const Street& s, int width, int height) {
  RTCDevice device = rtcNewDevice(nullptr);
  RTCScene scene = rtcNewScene(device);
  const ObjectSet& o = s.scene.objects;
  for (uint32_t i = 0; i < o.size(); ++i) {
    const LodChain& chain = s.scene.chains[o.model[i]];
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 8));
    const Transform t = transform_of(o, i);
    for (int k = 0; k < 8; ++k) {
      float w[3];
      rotate_by_quaternion(t.rotation, &chain.positions[3 * k], w);
      for (int a = 0; a < 3; ++a) v[3 * k + a] = t.position[a] + t.scale * w[a];
    }
    auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), 12));
    std::copy(chain.indices.begin(), chain.indices.end(), idx);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(scene, g, i);
    rtcReleaseGeometry(g);
  }
  rtcCommitScene(scene);
  const OcclusionCamera cam = occlusion_camera(s.view, width, height);
  std::set<uint32_t> seen;
  RTCIntersectContext context;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      {
        {
          const float u = ((float(x) + 0.5f) / float(width) * 2 - 1) * cam.tan_x;
          const float w = (1 - (float(y) + 0.5f) / float(height) * 2) * cam.tan_y;
          RTCRayHit rh{};
          rh.ray.org_x = cam.eye[0], rh.ray.org_y = cam.eye[1], rh.ray.org_z = cam.eye[2];
          rh.ray.dir_x = cam.forward[0] + u * cam.right[0] + w * cam.up[0];
          rh.ray.dir_y = cam.forward[1] + u * cam.right[1] + w * cam.up[1];
          rh.ray.dir_z = cam.forward[2] + u * cam.right[2] + w * cam.up[2];
          rh.ray.tnear = s.view.near_plane;
          rh.ray.tfar = s.view.far_plane;
          rh.ray.mask = 0xffffffffu;
          rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
          rtcInitIntersectContext(&context);
          rtcIntersect1(scene, &context, &rh);
          if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) seen.insert(rh.hit.geomID);
        }
      }
    }
  }
  rtcReleaseScene(scene);
  rtcReleaseDevice(device);
  return seen;
}

Frame run_frame(const Street& s, bool occlusion, bool embree = false) {
  FrameGraphOptions o;
  if (embree) o.occlusion.make_tracer = make_embree_occlusion_tracer;
  o.threads = 2;
  o.grain = 32;
  o.selection.budget = UINT64_MAX;
  o.occlusion.enabled = occlusion;
  FrameGraph g(s.scene, o);
  Frame f;
  g.run(s.view, f);
  return f;
}

// Both ways of filling the depth buffer: rasterised, and traced with Embree.
class OcclusionReference : public ::testing::TestWithParam<bool> {};

TEST_P(OcclusionReference, NoObjectAnyPrimaryRayHitsIsCulled) {
  for (float eye_z : {8.f, 0.f}) {
    const Street s = make_street(eye_z);
    const FrameGraphOptions defaults;
    const std::set<uint32_t> reference =
        reference_visible(s, defaults.occlusion.width, defaults.occlusion.height);
    ASSERT_GT(reference.size(), 20u);
    const Frame with = run_frame(s, true, GetParam()), without = run_frame(s, false);
    const std::set<uint32_t> kept(with.objects.begin(), with.objects.end());
    for (uint32_t id : reference) EXPECT_TRUE(kept.count(id)) << "object " << id << " is seen but was culled";
    EXPECT_GT(with.occluders, 0u);
    EXPECT_GT(with.occluder_tris, 0u);
    EXPECT_EQ(without.occluded, 0u);
    EXPECT_EQ(with.visible + with.occluded, without.visible)
        << "occlusion only removes frustum-visible objects";
    // Most of what the frustum keeps but no ray reaches is culled.
    const uint32_t hidden = without.visible - static_cast<uint32_t>(reference.size());
    std::printf(
        "%s street, eye z %.0f: %zu objects, %u in the frustum, %zu hit by rays, %u culled by %u occluders "
        "(%llu triangles)\n",
        GetParam() ? "embree" : "raster", double(eye_z), s.scene.objects.size(), without.visible,
        reference.size(), with.occluded, with.occluders, (unsigned long long)with.occluder_tris);
    EXPECT_GE(with.occluded, hidden / 2) << with.occluded << " of " << hidden << " hidden objects culled";
  }
}

TEST_P(OcclusionReference, SameFramesAtOneAndTwoThreads) {
  const Street s = make_street();
  FrameGraphOptions o;
  if (GetParam()) o.occlusion.make_tracer = make_embree_occlusion_tracer;
  o.selection.budget = UINT64_MAX;
  o.occlusion.enabled = true;
  o.grain = 32;
  Frame a, b;
  o.threads = 1;
  FrameGraph(s.scene, o).run(s.view, a);
  o.threads = 2;
  FrameGraph(s.scene, o).run(s.view, b);
  EXPECT_EQ(a.objects, b.objects);
  EXPECT_EQ(a.occluded, b.occluded);
  EXPECT_GT(a.occluded, 0u);
}

INSTANTIATE_TEST_SUITE_P(Method, OcclusionReference, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool>& i) { return i.param ? "embree" : "raster"; });

}  // namespace
}  // namespace lod
