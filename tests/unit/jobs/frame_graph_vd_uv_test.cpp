// A textured, two-material model drawn view-dependently: every frame publishes its active
// mesh's uvs (geomorphed with the positions) and its triangles grouped by material.
#include <gtest/gtest.h>

#include "jobs/frame_graph.h"
#include "preprocess/vertex_hierarchy.h"
#include "runtime/vertex_front.h"
#include "synthetic_scene.h"
#include "textured_fixture.h"

namespace lod {
namespace {

// Two levels of the two-material globe (north: material 0, v <= 0.5; south: material 1,
// v >= 0.5), level 0's hierarchy built with its uvs and runs.
LodChain globe_chain() {
  const MeshData fine = test::two_material_sphere(24, 48), coarse = test::two_material_sphere(6, 12);
  LodChain c;
  c.name = "globe";
  c.materials.resize(2);
  c.materials[0].name = "cap";
  c.materials[1].name = "base";
  for (const MeshData* m : {&fine, &coarse}) {
    LodLevel l;
    l.first_index = static_cast<uint32_t>(c.indices.size());
    l.index_count = static_cast<uint32_t>(m->indices.size());
    l.first_vertex = static_cast<uint32_t>(c.positions.size() / 3);
    l.vertex_count = static_cast<uint32_t>(m->vertex_count());
    l.level = level_of_triangles(m->triangle_count());
    l.error = m == &fine ? 0.f : 0.05f;
    l.bounds.radius = 1;
    for (const Submesh& s : m->submeshes)
      c.submeshes.push_back({uint32_t(c.levels.size()), 3 * s.first_triangle, 3 * s.triangle_count, s.material});
    c.levels.push_back(l);
    c.positions.insert(c.positions.end(), m->positions.begin(), m->positions.end());
    c.normals.insert(c.normals.end(), m->positions.begin(), m->positions.end());
    c.uvs.insert(c.uvs.end(), m->uvs.begin(), m->uvs.end());
    c.indices.insert(c.indices.end(), m->indices.begin(), m->indices.end());
    c.uv_errors.push_back(m == &fine ? 0.f : 0.1f);
  }
  MeshData input = fine;
  input.source = "globe";
  EXPECT_TRUE(build_vertex_hierarchy(c.hierarchy, input).ok);
  return c;
}

Scene globe_scene() { return test::one_vd_object_scene(globe_chain()); }

TEST(FrameGraphVdUv, TexturedObjectPublishesUvsAndTrianglesGroupedByMaterial) {
  const Scene scene = globe_scene();
  ASSERT_EQ(scene.chains[1].hierarchy.uvs.size(), 2 * size_t(scene.chains[1].hierarchy.node_count()));
  FrameGraphOptions o;
  o.threads = 2;
  o.selection.budget = 60000;
  FrameGraph g(scene, o);
  Frame f;
  uint64_t changes = 0;
  for (uint32_t n = 0; n < 60; ++n) {
    View v;
    const float a = 0.05f * float(n);
    v.eye = {100 * std::sin(a), 20 + float(n), 100 * std::cos(a)};
    v.target = {0, 0, 0};
    v.far_plane = 2000;
    g.run(v, f);
    ASSERT_EQ(f.vd_objects.size(), 1u) << "frame " << n;
    const VdObjectFrame& e = f.vd_objects[0];
    ASSERT_TRUE(e.has_uvs);
    ASSERT_EQ(f.vd_uvs.size(), 2 * f.vd_positions.size() / 3);
    std::string msg;
    ASSERT_TRUE(check_triangles(std::span(f.vd_indices.data() + e.first_index, e.index_count), e.vertex_count,
                                EdgeCheck::oriented, &msg))
        << "frame " << n << ": " << msg;
    // Runs cover the object's indices in order, one per material present, material order.
    ASSERT_GE(e.run_count, 1u);
    ASSERT_LE(e.first_run + e.run_count, f.vd_runs.size());
    uint32_t at = e.first_index;
    int32_t last = -2;
    for (uint32_t r = e.first_run; r < e.first_run + e.run_count; ++r) {
      const VdRunFrame& run = f.vd_runs[r];
      ASSERT_EQ(run.first_index, at);
      ASSERT_GT(run.material, last);
      last = run.material;
      at += run.index_count;
      // Each triangle lies on its material's half of the texture: the pinned equator (v = 0.5)
      // is where they meet, and no collapse moves a corner across it.
      for (uint32_t k = run.first_index; k < run.first_index + run.index_count; ++k) {
        const float tv = f.vd_uvs[2 * (size_t(e.first_vertex) + f.vd_indices[k]) + 1];
        if (run.material == 0) ASSERT_LE(tv, 0.5f + 1e-6f) << "frame " << n;
        if (run.material == 1) ASSERT_GE(tv, 0.5f - 1e-6f) << "frame " << n;
      }
    }
    ASSERT_EQ(at, e.first_index + e.index_count);
    for (uint32_t k = 0; k < 2 * e.vertex_count; ++k) {
      const float u = f.vd_uvs[2 * size_t(e.first_vertex) + k];
      ASSERT_TRUE(u >= 0 && u <= 1) << "frame " << n;
    }
    changes += e.splits + e.collapses;
  }
  EXPECT_GT(changes, 0u);
}

}  // namespace
}  // namespace lod
