// View-dependent objects in the frame graph: every published active mesh is a valid, closed
// triangulation, within its share of the budget, identical at 1 and 2 threads.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/glm.hpp>

#include "jobs/frame_graph.h"
#include "preprocess/vertex_hierarchy.h"
#include "runtime/vertex_front.h"
#include "synthetic_scene.h"
#include "vd_meshes.h"

namespace lod {
namespace {

// parts > 1: the hierarchy is cut into parts whose regions update as separate tasks.
LodChain ball_chain(uint32_t parts = 1) {
  const MeshData fine = test::vd_sphere(40, 60), coarse = test::vd_sphere(12, 16);
  LodChain c;
  c.name = "ball";
  for (const MeshData* m : {&fine, &coarse}) {
    LodLevel l;
    l.first_index = static_cast<uint32_t>(c.indices.size());
    l.index_count = static_cast<uint32_t>(m->indices.size());
    l.first_vertex = static_cast<uint32_t>(c.positions.size() / 3);
    l.vertex_count = static_cast<uint32_t>(m->vertex_count());
    l.level = level_of_triangles(m->triangle_count());
    l.error = m == &fine ? 0.f : 0.05f;
    l.bounds.radius = 1;
    c.levels.push_back(l);
    c.positions.insert(c.positions.end(), m->positions.begin(), m->positions.end());
    c.indices.insert(c.indices.end(), m->indices.begin(), m->indices.end());
  }
  HierarchyOptions o;
  o.parts = parts;
  EXPECT_TRUE(build_vertex_hierarchy(c.hierarchy, fine, o).ok);
  return c;
}

Scene ball_scene(uint32_t balls = 1, uint32_t parts = 1) {
  SceneConfig c = test::synthetic_config(300, 200);
  c.models.resize(1);  // cowlike
  c.instances.resize(1);
  c.instances[0].model = 0;
  c.models.push_back(ModelConfig{"ball", {}, {}});
  c.models.back().view_dependent = true;
  InstanceConfig i;
  i.model = 1;
  i.count = balls;
  i.grid = true;
  i.box_min[0] = i.box_min[1] = i.box_min[2] = 0;
  i.box_max[0] = i.box_max[1] = i.box_max[2] = 0;
  if (balls > 1) i.box_min[0] = -60, i.box_max[0] = 60;
  i.scale_min = i.scale_max = 40;
  c.instances.push_back(i);
  std::vector<LodChain> chains = {test::synthetic_chains()[0], ball_chain(parts)};
  return make_scene(c, std::move(chains));
}

View orbit(uint32_t n) {
  View v;
  const float a = 0.02f * n;
  v.eye = {120 * std::sin(a), 30, 120 * std::cos(a)};
  v.target = {0, 0, 0};
  v.far_plane = 2000;
  return v;
}

FrameGraphOptions options(uint32_t threads) {
  FrameGraphOptions o;
  o.threads = threads;
  o.selection.budget = 60000;
  return o;
}

void publishes_valid_closed_meshes(uint32_t parts) {
  const Scene scene = ball_scene(1, parts);
  FrameGraph g(scene, options(2));
  Frame f;
  uint64_t changes = 0;
  for (uint32_t n = 0; n < 90; ++n) {
    g.run(orbit(n), f);
    ASSERT_EQ(f.vd_objects.size(), 1u) << "frame " << n;
    const VdObjectFrame& o = f.vd_objects[0];
    EXPECT_TRUE(o.closed);
    std::string msg;
    ASSERT_TRUE(check_triangles(std::span(f.vd_indices.data() + o.first_index, o.index_count), o.vertex_count, EdgeCheck::closed,
                                &msg))
        << "frame " << n << ": " << msg;
    // Its share: the triangles of the level selection picked for it, plus the cap's margin.
    size_t slot = 0;
    while (f.objects[slot] != o.object) ++slot;
    const uint32_t m = scene.objects.model[o.object];
    const uint32_t share = scene.models.triangles[scene.models.first_level[m] + f.levels[slot]];
    EXPECT_LE(o.index_count / 3, share + share / 10 + 16) << "frame " << n;
    EXPECT_EQ(f.vd_active_tris, o.index_count / 3);
    changes += o.splits + o.collapses;
    for (float mf : f.morph) ASSERT_TRUE(mf >= 0 && mf <= 1);
  }
  EXPECT_GT(changes, 0u);
  EXPECT_GT(f.vd_active_tris, 50u);
}

TEST(FrameGraphVd, PublishesValidClosedMeshesWithinTheirShare) { publishes_valid_closed_meshes(1); }

// One object's regions are separate fronts; the published mesh joins them along fixed seams
// with no crack, and their shared cap holds.
TEST(FrameGraphVd, RegionsOfOneObjectPublishOneClosedMeshWithinItsShare) { publishes_valid_closed_meshes(4); }

void one_and_two_threads_agree(uint32_t balls, uint32_t parts) {
  const Scene scene = ball_scene(balls, parts);
  FrameGraph one(scene, options(1)), two(scene, options(2));
  Frame a, b;
  size_t seen = 0;
  for (uint32_t n = 0; n < 40; ++n) {
    one.run(orbit(3 * n), a);
    two.run(orbit(3 * n), b);
    ASSERT_EQ(a.vd_objects.size(), b.vd_objects.size());
    ASSERT_EQ(a.vd_indices, b.vd_indices) << "frame " << n;
    ASSERT_EQ(a.vd_positions, b.vd_positions) << "frame " << n;
    ASSERT_EQ(a.vd_normals, b.vd_normals) << "frame " << n;
    ASSERT_EQ(a.morph, b.morph);
    seen = std::max(seen, a.vd_objects.size());
  }
  EXPECT_GE(seen, std::min<size_t>(balls, 2));
}

TEST(FrameGraphVd, OneAndTwoThreadsGiveIdenticalFrames) {
  one_and_two_threads_agree(3, 1);  // three view-dependent objects update in parallel
}

TEST(FrameGraphVd, OneAndTwoThreadsGiveIdenticalFramesWithRegions) {
  one_and_two_threads_agree(2, 4);  // and each one's four regions too
}

// Smooth normals from the shown (geomorphed) faces: one per vertex; every corner of a face the
// viewer can see (non-zero area) has a unit normal, and once the first burst of splits has
// morphed out of the coarse base mesh (a tetrahedron-like hull whose faces are far from radial,
// and folded-over faces for a few frames) every one points out of the ball. A vertex whose
// faces are all degenerate (children still at their parent's place) gets (0, 0, 0): it draws
// no pixel.
void publishes_outward_unit_normals(uint32_t parts) {
  const Scene scene = ball_scene(1, parts);
  FrameGraph g(scene, options(2));
  Frame f;
  float settled_worst = 1;
  for (uint32_t n = 0; n < 80; ++n) {
    g.run(orbit(n < 60 ? 2 * n : 120), f);  // the last 20 frames hold still
    ASSERT_EQ(f.vd_objects.size(), 1u);
    ASSERT_EQ(f.vd_normals.size(), f.vd_positions.size()) << "frame " << n;
    const VdObjectFrame& o = f.vd_objects[0];
    auto at = [](const std::vector<float>& xyz, uint32_t v) { return glm::vec3(xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]); };
    for (uint32_t i = o.first_index; i < o.first_index + o.index_count; i += 3) {
      const uint32_t* c = &f.vd_indices[i];
      const glm::vec3 a = at(f.vd_positions, c[0]), b = at(f.vd_positions, c[1]), d = at(f.vd_positions, c[2]);
      if (glm::length(glm::cross(b - a, d - a)) < 1e-9f) continue;
      for (int k = 0; k < 3; ++k) {
        const glm::vec3 nv = at(f.vd_normals, c[k]);
        ASSERT_NEAR(glm::length(nv), 1.f, 1e-4f) << "frame " << n << " vertex " << c[k];
        const float cosine = glm::dot(nv, glm::normalize(at(f.vd_positions, c[k])));
        if (n >= 40) settled_worst = std::min(settled_worst, cosine);
      }
    }
  }
  EXPECT_GT(settled_worst, 0.9f);  // within 26 degrees of radial
}

TEST(FrameGraphVd, PublishesOutwardUnitNormalsForEveryVertex) { publishes_outward_unit_normals(1); }
TEST(FrameGraphVd, PublishesOutwardUnitNormalsAcrossRegions) { publishes_outward_unit_normals(4); }

TEST(FrameGraphVd, ObjectsWithoutAHierarchyPublishNoVdMesh) {
  const Scene scene = test::synthetic_scene(500, 200);
  FrameGraph g(scene, options(2));
  Frame f;
  g.run(orbit(0), f);
  EXPECT_TRUE(f.vd_objects.empty());
  EXPECT_EQ(f.vd_active_tris, 0u);
  EXPECT_TRUE(f.vd_indices.empty());
  EXPECT_TRUE(f.vd_normals.empty());
}

}  // namespace
}  // namespace lod
