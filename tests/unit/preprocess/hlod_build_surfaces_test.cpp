// Model HLOD with a textured, two-material input: every layer and patch keeps the
// uvs and its triangles' materials, grouped into runs; uv seams and the material boundary stay
// closed (every random cut crack-free); each material's triangles stay on their half with uvs
// in their chart; the bytes do not depend on threads or the frontier; a positions-only input
// writes no surfaces at all.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <thread>
#include <vector>

#include "preprocess/hlod_build.h"
#include "preprocess/mesh_clean.h"
#include "runtime/hlod_asset.h"
#include "runtime/hlod_cut_check.h"
#include "textured_fixture.h"
#include "vd_meshes.h"

namespace lod {
namespace {

// The fixture's sphere (u = longitude with its seam at u = 0 / 1, v = latitude; material 0 the
// northern half, 1 the southern), cleaned as the bake cleans it: the equator split per material.
MeshData textured_mesh() {
  MeshData m = test::two_material_sphere(48, 96);
  m.source = "sphere.gltf";
  clean_mesh(m);
  return m;
}

HlodBuildOptions textured_options(uint32_t subtrees = 16, const ParallelFor& parallel_for = {}) {
  HlodBuildOptions o;
  o.min_verts = 300;
  o.subtrees = subtrees;
  o.parallel_for = parallel_for;
  ChainMaterial cap, base;
  cap.name = "cap";
  cap.base_color_texture = "checker.png";
  base.name = "base";
  o.surfaces.materials = {cap, base};
  o.surfaces.texture_base = "/textures";
  return o;
}

HlodModel build_with(const MeshData& mesh, const HlodBuildOptions& o) {
  HlodModel m;
  const Status st = build_hlod(m, mesh, o);
  EXPECT_TRUE(st) << st.message;
  return m;
}

const ParallelFor kTwoThreads = [](size_t n, const std::function<void(size_t)>& body) {
  std::thread other([&] {
    for (size_t i = 1; i < n; i += 2) body(i);
  });
  for (size_t i = 0; i < n; i += 2) body(i);
  other.join();
};

// Every range of node `i`: its runs cover it in material order; each run's triangles lie on
// their material's half, with uvs in that half's chart, and none spans the u seam.
void expect_surfaces(const HlodModel& m, size_t i) {
  const HlodPayload& p = m.payloads[i];
  ASSERT_EQ(p.uvs.size(), p.positions.size() / 3 * 2) << "node " << i;
  EXPECT_EQ(m.tree.nodes[i].material_runs, p.runs.size());
  for (uint32_t r = 0; r <= p.layers.size(); ++r) {
    const LodLevel& range = r < p.layers.size() ? p.layers[r] : p.boundary;
    uint32_t covered = 0;
    int32_t last = -2;
    for (const LevelSubmesh& run : hlod_range_runs(p, r)) {
      EXPECT_EQ(run.first_index, covered);
      EXPECT_GT(run.material, last) << "runs in material order, one per material";
      ASSERT_GE(run.material, 0) << "every triangle of the sphere has a material";
      last = run.material;
      for (uint32_t k = run.first_index; k < run.first_index + run.index_count; k += 3) {
        float y = 0, umin = 1e9f, umax = -1e9f;
        for (int c = 0; c < 3; ++c) {
          const uint32_t v = range.first_vertex + p.indices[range.first_index + k + uint32_t(c)];
          y += p.positions[3 * size_t(v) + 1] / 3;
          const float u = p.uvs[2 * size_t(v)], w = p.uvs[2 * size_t(v) + 1];
          umin = std::min(umin, u), umax = std::max(umax, u);
          ASSERT_GE(u, -1e-4f);
          ASSERT_LE(u, 1 + 1e-4f);
          if (run.material == 0) {
            ASSERT_LE(w, 0.5f + 1e-4f) << "node " << i << " range " << r;
          } else {
            ASSERT_GE(w, 0.5f - 1e-4f) << "node " << i << " range " << r;
          }
        }
        if (run.material == 0) {
          EXPECT_GE(y, -0.02f) << "a cap triangle below the equator";
        } else {
          EXPECT_LE(y, 0.02f) << "a base triangle above the equator";
        }
        EXPECT_LT(umax - umin, 0.5f) << "a triangle smeared across the uv seam";
      }
      covered += run.index_count;
    }
    EXPECT_EQ(covered, range.index_count) << "node " << i << " range " << r;
  }
}

TEST(HlodBuildSurfaces, TexturedSphereKeepsUvsAndMaterialsInEveryLayerAndPatch) {
  const MeshData mesh = textured_mesh();
  const HlodModel m = build_with(mesh, textured_options());
  ASSERT_GT(m.tree.nodes.size(), 8u) << "the mesh must split for the test to mean anything";
  EXPECT_TRUE(m.tree.uvs);
  EXPECT_EQ(m.tree.material_count, 2u);
  ASSERT_EQ(m.tree.materials.size(), 2u);
  EXPECT_EQ(m.tree.materials[0].base_color_texture, "checker.png");
  EXPECT_EQ(m.tree.texture_base, "/textures");
  float coarsest_uv_error = 0;
  for (size_t i = 0; i < m.tree.nodes.size(); ++i) {
    expect_surfaces(m, i);
    const HlodNode& n = m.tree.nodes[i];
    if (n.leaf()) {
      EXPECT_EQ(n.layers[0].uv_error, 0.0f) << "a leaf's finest layer is the original";
    }
    coarsest_uv_error = std::max(coarsest_uv_error, n.layers[n.layer_count - 1].uv_error);
  }
  EXPECT_GT(coarsest_uv_error, 0.0f);
  EXPECT_LT(coarsest_uv_error, 0.25f);
  // Random cuts: the seams (uv and material) never open.
  std::vector<const HlodPayload*> payloads;
  for (const HlodPayload& x : m.payloads) payloads.push_back(&x);
  const HlodCutReference ref = hlod_cut_reference(m.tree, payloads);
  std::mt19937 rng(3);
  for (int k = 0; k < 100; ++k) {
    std::vector<int8_t> cut(m.tree.nodes.size(), kHlodCutOutside);
    std::vector<uint32_t> stack{0};
    while (!stack.empty()) {
      const uint32_t i = stack.back();
      stack.pop_back();
      const HlodNode& n = m.tree.nodes[i];
      if (!n.leaf() && rng() % 3 != 0) {
        cut[i] = kHlodCutOpened;
        for (uint32_t c = 0; c < n.child_count; ++c) stack.push_back(n.first_child + c);
      } else {
        cut[i] = int8_t(rng() % n.layer_count);
      }
    }
    EXPECT_EQ(count_cut_gaps(m.tree, payloads, cut, ref), 0u) << "cut " << k;
  }
  // And the file keeps all of it.
  HlodTree tree;
  std::vector<HlodPayload> back;
  const Status st = decode_hlod_asset(encode_hlod_asset(m.tree, m.payloads), "sphere.hlod", tree, back);
  ASSERT_TRUE(st) << st.message;
  ASSERT_EQ(back.size(), m.payloads.size());
  for (size_t i = 0; i < back.size(); ++i) {
    EXPECT_EQ(back[i].uvs, m.payloads[i].uvs);
    EXPECT_EQ(back[i].runs.size(), m.payloads[i].runs.size());
    EXPECT_EQ(tree.nodes[i].resident_bytes, m.tree.nodes[i].resident_bytes);
  }
}

TEST(HlodBuildSurfaces, SameBytesAtAnyThreadCountAndFrontier) {
  const MeshData mesh = textured_mesh();
  const HlodModel one = build_with(mesh, textured_options(1));
  const std::vector<uint8_t> bytes = encode_hlod_asset(one.tree, one.payloads);
  const HlodModel two = build_with(mesh, textured_options(1, kTwoThreads));
  EXPECT_EQ(encode_hlod_asset(two.tree, two.payloads), bytes) << "1 vs 2 threads";
  for (uint32_t subtrees : {3u, 16u, 100000u}) {
    const HlodModel m = build_with(mesh, textured_options(subtrees, kTwoThreads));
    EXPECT_EQ(encode_hlod_asset(m.tree, m.payloads), bytes) << subtrees << " subtrees";
  }
}

TEST(HlodBuildSurfaces, PositionsOnlyInputWritesNoSurfaces) {
  MeshData mesh = textured_mesh();
  mesh.uvs.clear();
  mesh.submeshes.clear();
  HlodBuildOptions o = textured_options();
  o.surfaces = {};
  const HlodModel m = build_with(mesh, o);
  EXPECT_FALSE(m.tree.uvs);
  EXPECT_EQ(m.tree.material_count, 0u);
  for (size_t i = 0; i < m.payloads.size(); ++i) {
    EXPECT_TRUE(m.payloads[i].uvs.empty());
    EXPECT_TRUE(m.payloads[i].runs.empty());
    EXPECT_EQ(m.tree.nodes[i].material_runs, 0u);
    EXPECT_EQ(m.tree.nodes[i].resident_bytes,
              4 * (m.payloads[i].positions.size() + m.payloads[i].normals.size() + m.payloads[i].indices.size()));
  }
}

TEST(HlodBuildSurfaces, RefusesNonFiniteUvsAndIgnoresUnknownMaterialIds) {
  MeshData mesh = textured_mesh();
  mesh.uvs[7] = NAN;
  HlodModel m;
  Status st = build_hlod(m, mesh, textured_options());
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("sphere.gltf: vertex 3 has a non-finite texture coordinate"), std::string::npos) << st.message;
  // Submesh ids past the materials given are drawn with the default material (-1).
  mesh = textured_mesh();
  for (Submesh& s : mesh.submeshes) s.material = s.material == 1 ? 7 : s.material;
  m = build_with(mesh, textured_options());
  for (const HlodPayload& p : m.payloads)
    for (const LevelSubmesh& r : p.runs) EXPECT_TRUE(r.material == -1 || r.material == 0) << r.material;
}

}  // namespace
}  // namespace lod

namespace lod {
namespace {

// The coloured sphere (north red with green following the latitude, south blue at alpha 0.5,
// a colour seam on the equator; TEXCOORD_1 a lightmap-style set), cleaned as the bake cleans it.
MeshData coloured_mesh() {
  MeshData m = test::coloured_sphere(48, 96);
  m.source = "painted.gltf";
  clean_mesh(m);
  return m;
}

HlodBuildOptions coloured_options(uint32_t subtrees = 16, const ParallelFor& parallel_for = {}) {
  HlodBuildOptions o;
  o.min_verts = 300;
  o.subtrees = subtrees;
  o.parallel_for = parallel_for;
  return o;
}

// Colours and the second uv set ride through QEM like TEXCOORD_0: every layer and
// patch has them; each vertex keeps its half's colour (the seam holds: no red in the south, no
// blue in the north), green still follows the latitude, uv1 stays in its chart; the errors are
// 0 on a leaf's original layer and small elsewhere; cuts stay closed; the file keeps it all.
TEST(HlodBuildSurfaces, ColouredSphereKeepsColoursAndUv1InEveryLayerAndPatch) {
  const MeshData mesh = coloured_mesh();
  const HlodModel m = build_with(mesh, coloured_options());
  ASSERT_GT(m.tree.nodes.size(), 8u) << "the mesh must split for the test to mean anything";
  EXPECT_TRUE(m.tree.uvs && m.tree.uvs1 && m.tree.colors);
  float coarsest_color = 0, coarsest_uv1 = 0;
  for (size_t i = 0; i < m.tree.nodes.size(); ++i) {
    const HlodNode& n = m.tree.nodes[i];
    const HlodPayload& p = m.payloads[i];
    const size_t nv = p.positions.size() / 3;
    ASSERT_TRUE(n.uvs1 && n.colors) << "node " << i;
    ASSERT_EQ(p.uvs1.size(), 2 * nv) << "node " << i;
    ASSERT_EQ(p.colors.size(), 4 * nv) << "node " << i;
    for (size_t v = 0; v < nv; ++v) {
      const float* c = &p.colors[4 * v];
      const float y = p.positions[3 * v + 1];
      const float u1 = p.uvs1[2 * v], w1 = p.uvs1[2 * v + 1];
      ASSERT_GE(u1, 0.25f - 1e-4f) << "node " << i;
      ASSERT_LE(u1, 0.75f + 1e-4f) << "node " << i;
      ASSERT_GE(w1, -1e-4f);
      ASSERT_LE(w1, 0.5f + 1e-4f);
      const bool red = c[0] > 0.5f;
      if (red) {
        ASSERT_GE(y, -0.02f) << "a red vertex below the equator, node " << i;
        EXPECT_NEAR(c[3], 1.0f, 1e-5f);
        EXPECT_NEAR(c[2], 0.0f, 1e-5f);
        EXPECT_NEAR(c[1], 2 * w1, 0.02f) << "green is the latitude, as uv1's v / 2 is";
      } else {
        ASSERT_LE(y, 0.02f) << "a blue vertex above the equator, node " << i;
        EXPECT_NEAR(c[2], 1.0f, 1e-5f);
        EXPECT_NEAR(c[3], 0.5f, 1e-5f);
      }
    }
    if (n.leaf()) {
      EXPECT_EQ(n.layers[0].color_error, 0.0f) << "a leaf's finest layer is the original";
      EXPECT_EQ(n.layers[0].uv1_error, 0.0f);
    }
    coarsest_color = std::max(coarsest_color, n.layers[n.layer_count - 1].color_error);
    coarsest_uv1 = std::max(coarsest_uv1, n.layers[n.layer_count - 1].uv1_error);
  }
  EXPECT_GT(coarsest_color, 0.0f);
  EXPECT_LT(coarsest_color, 0.25f) << "green slides along the latitude only";
  EXPECT_GT(coarsest_uv1, 0.0f);
  EXPECT_LT(coarsest_uv1, 0.125f);
  std::vector<const HlodPayload*> payloads;
  for (const HlodPayload& x : m.payloads) payloads.push_back(&x);
  const HlodCutReference ref = hlod_cut_reference(m.tree, payloads);
  std::mt19937 rng(5);
  for (int k = 0; k < 50; ++k) {
    std::vector<int8_t> cut(m.tree.nodes.size(), kHlodCutOutside);
    std::vector<uint32_t> stack{0};
    while (!stack.empty()) {
      const uint32_t i = stack.back();
      stack.pop_back();
      const HlodNode& n = m.tree.nodes[i];
      if (!n.leaf() && rng() % 3 != 0) {
        cut[i] = kHlodCutOpened;
        for (uint32_t c = 0; c < n.child_count; ++c) stack.push_back(n.first_child + c);
      } else {
        cut[i] = int8_t(rng() % n.layer_count);
      }
    }
    EXPECT_EQ(count_cut_gaps(m.tree, payloads, cut, ref), 0u) << "cut " << k;
  }
  HlodTree tree;
  std::vector<HlodPayload> back;
  const Status st = decode_hlod_asset(encode_hlod_asset(m.tree, m.payloads), "painted.hlod", tree, back);
  ASSERT_TRUE(st) << st.message;
  EXPECT_TRUE(tree.uvs1 && tree.colors);
  for (size_t i = 0; i < back.size(); ++i) {
    EXPECT_EQ(back[i].colors, m.payloads[i].colors);
    EXPECT_EQ(back[i].uvs1, m.payloads[i].uvs1);
    EXPECT_EQ(tree.nodes[i].layers[0].color_error, m.tree.nodes[i].layers[0].color_error);
    EXPECT_EQ(tree.nodes[i].resident_bytes, m.tree.nodes[i].resident_bytes);
  }
}

TEST(HlodBuildSurfaces, ColouredSameBytesAtAnyThreadCountAndFrontier) {
  const MeshData mesh = coloured_mesh();
  const HlodModel one = build_with(mesh, coloured_options(1));
  const std::vector<uint8_t> bytes = encode_hlod_asset(one.tree, one.payloads);
  for (uint32_t subtrees : {1u, 3u, 100000u}) {
    const HlodModel m = build_with(mesh, coloured_options(subtrees, kTwoThreads));
    EXPECT_EQ(encode_hlod_asset(m.tree, m.payloads), bytes) << subtrees << " subtrees, 2 threads";
  }
}

// Either attribute alone; and hostile inputs: a count that is not the vertices', a non-finite value.
TEST(HlodBuildSurfaces, ColoursOrUv1AloneAndHostileAttributesRefused) {
  MeshData only_colours = coloured_mesh();
  only_colours.uvs1.clear();
  HlodModel m = build_with(only_colours, coloured_options());
  EXPECT_TRUE(m.tree.colors);
  EXPECT_FALSE(m.tree.uvs1);
  for (const HlodPayload& p : m.payloads) EXPECT_TRUE(p.uvs1.empty() && p.colors.size() == p.positions.size() / 3 * 4);
  MeshData only_uv1 = coloured_mesh();
  only_uv1.colors.clear();
  only_uv1.uvs.clear();
  m = build_with(only_uv1, coloured_options());
  EXPECT_TRUE(m.tree.uvs1);
  EXPECT_FALSE(m.tree.colors || m.tree.uvs);
  for (const HlodPayload& p : m.payloads) EXPECT_TRUE(p.uvs.empty() && p.uvs1.size() == p.positions.size() / 3 * 2);
  auto refused = [](const MeshData& mesh, const char* expected) {
    HlodModel out;
    const Status st = build_hlod(out, mesh, coloured_options());
    ASSERT_FALSE(st) << expected;
    EXPECT_NE(st.message.find(expected), std::string::npos) << st.message;
    EXPECT_TRUE(out.tree.nodes.empty());
  };
  MeshData bad = coloured_mesh();
  bad.colors[4 * 9 + 2] = NAN;
  refused(bad, "painted.gltf: vertex 9 has a non-finite colour");
  bad = coloured_mesh();
  bad.uvs1[2 * 4 + 1] = INFINITY;
  refused(bad, "painted.gltf: vertex 4 has a non-finite TEXCOORD_1");
  bad = coloured_mesh();
  bad.colors.resize(bad.colors.size() - 4);
  refused(bad, "vertex colours for");
  bad = coloured_mesh();
  bad.uvs1.push_back(0), bad.uvs1.push_back(0);
  refused(bad, "TEXCOORD_1 values for");
}

}  // namespace
}  // namespace lod
