// Occlusion buffer: what a wall hides and what it does not, and hostile values.
#include "runtime/occlusion.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lod {
namespace {

// A wall of two triangles at z = wall_z (world), spanning x, y in [-half, half].
void draw_wall(OcclusionBuffer& b, const OcclusionCamera& c, float wall_z, float half, Transform t = {}) {
  const float p[12] = {-half, -half, wall_z, half, -half, wall_z, half, half, wall_z, -half, half, wall_z};
  const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
  rasterize_occluder(b, c, p, idx, t);
}

OcclusionCamera camera() {
  View v;  // at the origin looking down -z
  v.width = 160;
  v.height = 90;
  return occlusion_camera(v, 160, 90);
}

TEST(Occlusion, AWallHidesWhatIsBehindItOnly) {
  const OcclusionCamera c = camera();
  OcclusionBuffer b;
  occlusion_clear(b, c);
  draw_wall(b, c, -10, 100);
  occlusion_finish(b);
  const float behind[3] = {0, 0, -30}, front[3] = {0, 0, -5}, touching[3] = {0, 0, -11};
  EXPECT_TRUE(sphere_occluded(b, c, behind, 2));
  EXPECT_FALSE(sphere_occluded(b, c, front, 1));
  EXPECT_FALSE(sphere_occluded(b, c, touching, 2)) << "reaches in front of the wall";
  const float near_cam[3] = {0, 0, -0.4f};
  EXPECT_FALSE(sphere_occluded(b, c, near_cam, 0.5f)) << "crosses the near plane";
}

TEST(Occlusion, APartialWallHidesOnlyWhatItCoversEntirely) {
  const OcclusionCamera c = camera();
  OcclusionBuffer b;
  occlusion_clear(b, c);
  draw_wall(b, c, -10, 2);  // a small square in the middle of the view
  occlusion_finish(b);
  // The wall (half size 2 at distance 10) shadows |x| <= 8 at distance 40.
  const float centre[3] = {0, 0, -40}, beside[3] = {12, 0, -40};
  EXPECT_TRUE(sphere_occluded(b, c, centre, 1));
  EXPECT_FALSE(sphere_occluded(b, c, beside, 1));
  const float big[3] = {0, 0, -40};
  EXPECT_FALSE(sphere_occluded(b, c, big, 20)) << "larger than the wall's shadow";
}

TEST(Occlusion, EmptyOrHostileInputHidesNothing) {
  const OcclusionCamera c = camera();
  OcclusionBuffer b;
  occlusion_clear(b, c);
  occlusion_finish(b);
  const float p[3] = {0, 0, -30};
  EXPECT_FALSE(sphere_occluded(b, c, p, 1)) << "no occluder";
  occlusion_clear(b, c);
  Transform huge;
  huge.scale = 1e30f;
  draw_wall(b, c, -10, 100, huge);
  Transform far;
  far.position[0] = 3e38f;
  draw_wall(b, c, -10, 100, far);
  const float bad_p[6] = {NAN, 0, -5, 1, 1, -5};
  const uint32_t bad_i[6] = {0, 1, 7, 0, 1, 1};  // an index out of range is skipped
  rasterize_occluder(b, c, std::span(bad_p, 6), bad_i, Transform{});
  occlusion_finish(b);
  const float nan_c[3] = {NAN, 0, -30};
  EXPECT_FALSE(sphere_occluded(b, c, nan_c, 1));
  const float inf_c[3] = {0, 0, -INFINITY};
  EXPECT_FALSE(sphere_occluded(b, c, inf_c, 1));
}

}  // namespace
}  // namespace lod
