// Stress: 10,000 objects of three model types over 200 frames of a moving camera, through the
// service in driven mode. Every frame must meet the budget or flag it, select nothing outside
// the frustum, leave out nothing inside it, and come with a strictly increasing index.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_access.hpp>

#include "jobs/service.h"
#include "unit/jobs/synthetic_scene.h"

namespace lod {
namespace {

// Frustum planes taken from projection * view directly (Gribb & Hartmann), independent of
// runtime's frustum_of; normalized so that plane distances are in world units.
std::array<glm::vec4, 6> planes_of(const View& v) {
  const glm::mat4 m = projection_matrix(v) * view_matrix(v);
  const glm::vec4 r0 = glm::row(m, 0), r1 = glm::row(m, 1), r2 = glm::row(m, 2), r3 = glm::row(m, 3);
  std::array<glm::vec4, 6> p = {r3 + r0, r3 - r0, r3 + r1, r3 - r1, r3 + r2, r3 - r2};
  for (glm::vec4& q : p) q /= glm::length(glm::vec3(q));
  return p;
}

// Signed distance of the sphere's surface beyond the worst plane (> 0: fully outside one).
float outside_by(const std::array<glm::vec4, 6>& planes, const ObjectSet& o, uint32_t i) {
  float worst = -1e30f;
  for (const glm::vec4& q : planes) {
    const float d = q.x * o.cx[i] + q.y * o.cy[i] + q.z * o.cz[i] + q.w;
    worst = std::max(worst, -d - o.radius[i]);
  }
  return worst;
}

TEST(Stress, TenThousandObjectsTwoHundredFramesMovingCamera) {
  constexpr uint32_t kObjects = 10000;
  constexpr uint32_t kFrames = 200;
  const float extent = test::extent_for(kObjects);
  const Scene scene = test::synthetic_scene(kObjects, extent, 11);
  ASSERT_EQ(scene.objects.size(), kObjects);
  CameraPath path = test::synthetic_config(kObjects, extent).camera;  // orbit over the field
  path.period_frames = kFrames;

  // A budget that binds: halfway between the coarsest levels and what the screen-space
  // levels alone would pick on frame 0.
  uint64_t unbudgeted = 0, coarsest = 0;
  {
    FrameGraphOptions free_options;
    free_options.selection.budget = UINT64_MAX;
    FrameGraph g(scene, free_options);
    Frame f;
    g.run(view_at(path, 0), f);
    unbudgeted = f.tris_selected;
    coarsest = f.coarsest_cost;
  }
  const uint64_t budget = (unbudgeted + coarsest) / 2;
  ASSERT_GT(budget, 0u);

  FrameGraphOptions options;
  options.threads = 2;
  options.selection.budget = budget;
  std::unique_ptr<Service> owned = make_service(scene, options, 60);
  Service& service = *owned;

  uint64_t last_index = 0;
  uint32_t bound = 0, flagged = 0, culled_some = 0;
  for (uint32_t n = 0; n < kFrames; ++n) {
    // Every 50th frame asks for the impossible, so the flag is exercised along the way.
    const bool impossible = n % 50 == 49;
    service.set_budget(impossible ? 1000 : budget);
    const View view = view_at(path, n);
    ASSERT_TRUE(set_view(service, 0, view) && service.step(1.0 / 60)) << "frame " << n;
    const FrameRef held = service.acquire_frame();
    const Frame& f = *held;
    SCOPED_TRACE("frame " + std::to_string(n));

    ASSERT_GT(f.index, last_index) << "indices strictly increase";
    last_index = f.index;
    ASSERT_EQ(f.object_count, kObjects);
    ASSERT_EQ(f.objects.size(), f.visible);
    ASSERT_EQ(f.levels.size(), f.visible);

    if (f.over_budget) {
      ++flagged;
      EXPECT_GT(f.coarsest_cost, f.budget);
      EXPECT_EQ(f.tris_selected, f.coarsest_cost);
    } else {
      EXPECT_LE(f.tris_selected, f.budget);
      bound += f.lowered_steps > 0;
    }
    EXPECT_EQ(impossible, f.over_budget);

    // Nothing selected lies wholly outside the frustum, nothing left out lies inside it.
    // The runtime's test is conservative near corners, hence one-sided tolerances.
    const auto planes = planes_of(view);
    std::vector<uint8_t> selected(kObjects, 0);
    for (size_t k = 0; k < f.objects.size(); ++k) {
      const uint32_t i = f.objects[k];
      ASSERT_LT(i, kObjects);
      ASSERT_EQ(selected[i], 0) << "object " << i << " published twice";
      selected[i] = 1;
      EXPECT_LE(outside_by(planes, scene.objects, i), 1e-3f * (1 + scene.objects.radius[i]))
          << "object " << i;
      EXPECT_LT(f.levels[k], scene.models.level_count[scene.objects.model[i]]);
    }
    for (uint32_t i = 0; i < kObjects; ++i) {
      if (!selected[i]) {
        EXPECT_GT(outside_by(planes, scene.objects, i), -1e-3f * (1 + scene.objects.radius[i])) << i;
      }
    }
    culled_some += f.visible < kObjects;
  }
  EXPECT_EQ(flagged, kFrames / 50);
  EXPECT_GT(bound, kFrames / 2) << "the budget should bind on most frames";
  EXPECT_EQ(culled_some, kFrames);
  EXPECT_EQ(service.stats().frames, kFrames);
  EXPECT_EQ(service.stats().errors, 0u);
}

}  // namespace
}  // namespace lod
