// A view-dependent model with TEXCOORD_1, vertex colours and authored normals: every frame
// publishes them per active vertex (Frame::vd_uvs1, vd_colors, and the tree's normals in
// vd_normals), geomorphed with the positions; no colour bleeds across the pinned colour seam.
#include <gtest/gtest.h>

#include <cmath>

#include "jobs/frame_graph.h"
#include "preprocess/vertex_hierarchy.h"
#include "runtime/vertex_front.h"
#include "synthetic_scene.h"
#include "textured_fixture.h"

namespace lod {
namespace {

// coloured_sphere with radial authored normals.
MeshData attributed_sphere(int rings, int segments) {
  MeshData m = test::coloured_sphere(rings, segments);
  m.source = "ball";
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    const float* p = &m.positions[3 * v];
    const float len = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    m.normals.insert(m.normals.end(), {p[0] / len, p[1] / len, p[2] / len});
  }
  return m;
}

LodChain attributed_chain(bool normals) {
  const MeshData fine = attributed_sphere(24, 48), coarse = attributed_sphere(6, 12);
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
    c.normals.insert(c.normals.end(), m->normals.begin(), m->normals.end());
    c.uvs.insert(c.uvs.end(), m->uvs.begin(), m->uvs.end());
    c.uvs1.insert(c.uvs1.end(), m->uvs1.begin(), m->uvs1.end());
    c.colors.insert(c.colors.end(), m->colors.begin(), m->colors.end());
    c.indices.insert(c.indices.end(), m->indices.begin(), m->indices.end());
    c.uv_errors.push_back(m == &fine ? 0.f : 0.1f);
    c.uv1_errors.push_back(m == &fine ? 0.f : 0.1f);
    c.color_errors.push_back(m == &fine ? 0.f : 0.1f);
  }
  MeshData input = fine;
  if (!normals) input.normals.clear();
  EXPECT_TRUE(build_vertex_hierarchy(c.hierarchy, input).ok);
  return c;
}

Scene ball_scene(bool normals) { return test::one_vd_object_scene(attributed_chain(normals)); }

View orbit(uint32_t n) {
  View v;
  const float a = 0.05f * float(n);
  v.eye = {100 * std::sin(a), 20 + float(n), 100 * std::cos(a)};
  v.target = {0, 0, 0};
  v.far_plane = 2000;
  return v;
}

TEST(FrameGraphVdAttributes, PublishesSecondUvsColoursAndAuthoredNormalsPerVertex) {
  const Scene scene = ball_scene(true);
  // The pinned colour seam (the equator) cuts the tree into regions: several fronts, so the
  // columns follow fronts_compact_mesh's vertex order (fixed leaves once).
  std::vector<uint8_t> region;
  EXPECT_GE(vertex_tree_regions(region, scene.chains[1].hierarchy, 8), 2u);
  FrameGraphOptions o;
  o.threads = 2;
  o.selection.budget = 60000;
  FrameGraph g(scene, o);
  Frame f;
  uint64_t changes = 0, moving = 0;
  for (uint32_t n = 0; n < 60; ++n) {
    g.run(orbit(n), f);
    ASSERT_EQ(f.vd_objects.size(), 1u) << "frame " << n;
    const VdObjectFrame& e = f.vd_objects[0];
    ASSERT_TRUE(e.has_uvs1 && e.has_colors && e.has_authored_normals);
    const size_t nv = f.vd_positions.size() / 3;
    ASSERT_EQ(f.vd_uvs1.size(), 2 * nv);
    ASSERT_EQ(f.vd_colors.size(), 4 * nv);
    ASSERT_EQ(f.vd_normals.size(), 3 * nv);
    for (uint32_t v = e.first_vertex; v < e.first_vertex + e.vertex_count; ++v) {
      // Colours: a corner is the north's red (1, g, 0, 1) or the south's blue (0, 0, 1, 0.5),
      // never a mix (blends of one value are that value, to a rounding).
      const float* c = &f.vd_colors[4 * size_t(v)];
      const bool red = std::abs(c[0] - 1) < 1e-6f && std::abs(c[2]) < 1e-6f && std::abs(c[3] - 1) < 1e-6f;
      const bool blue = std::abs(c[0]) < 1e-6f && std::abs(c[1]) < 1e-6f && std::abs(c[2] - 1) < 1e-6f &&
                        std::abs(c[3] - 0.5f) < 1e-6f;
      ASSERT_TRUE(red || blue) << "frame " << n << " vertex " << v;
      // The lightmap set lies in (0.25 + u / 2, v / 2).
      const float* t = &f.vd_uvs1[2 * size_t(v)];
      ASSERT_TRUE(t[0] >= 0.25f - 1e-6f && t[0] <= 0.75f + 1e-6f && t[1] >= 0 && t[1] <= 0.5f + 1e-6f)
          << "frame " << n;
      // Authored (radial) normals, unit, near the direction of the shown position.
      const float* q = &f.vd_normals[3 * size_t(v)];
      const float* p = &f.vd_positions[3 * size_t(v)];
      ASSERT_NEAR(q[0] * q[0] + q[1] * q[1] + q[2] * q[2], 1.f, 1e-5f) << "frame " << n;
      const float len = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
      ASSERT_GT((q[0] * p[0] + q[1] * p[1] + q[2] * p[2]) / len, 0.5f) << "frame " << n << " vertex " << v;
    }
    changes += e.splits + e.collapses;
    moving += e.moving;
  }
  EXPECT_GT(changes, 0u);
  EXPECT_GT(moving, 0u);  // values were seen mid-morph
}

TEST(FrameGraphVdAttributes, WithoutAuthoredNormalsTheShownFacesGiveThem) {
  const Scene scene = ball_scene(false);
  FrameGraphOptions o;
  o.selection.budget = 60000;
  FrameGraph g(scene, o);
  Frame f;
  for (uint32_t n = 0; n < 5; ++n) g.run(orbit(n), f);
  ASSERT_EQ(f.vd_objects.size(), 1u);
  EXPECT_FALSE(f.vd_objects[0].has_authored_normals);
  EXPECT_TRUE(f.vd_objects[0].has_colors);
  ASSERT_EQ(f.vd_normals.size(), f.vd_positions.size());
  // The sphere winds inward: computed normals point in, the authored ones would point out.
  double inward = 0;
  for (size_t v = 0; v < f.vd_positions.size() / 3; ++v)
    inward +=
        -(f.vd_normals[3 * v] * f.vd_positions[3 * v] + f.vd_normals[3 * v + 1] * f.vd_positions[3 * v + 1] +
          f.vd_normals[3 * v + 2] * f.vd_positions[3 * v + 2]);
  EXPECT_GT(inward, 0.0);
}

}  // namespace
}  // namespace lod
