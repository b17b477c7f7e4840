// Authored normals (glTF NORMAL) at level 0: a smooth sphere's are kept bit for bit (and flagged
// in the asset, so the vertex hierarchy carries them); a flat-shaded box's hard edges, whose
// copies differ in normal only and are welded by cleaning, are not kept, and the bake says so.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "preprocess/gltf_write.h"
#include "preprocess/lod_bake.h"
#include "preprocess/mesh_clean.h"
#include "runtime/lod_asset.h"
#include "test_support.h"
#include "textured_fixture.h"

namespace lod {
namespace {

std::filesystem::path write_mesh(const std::filesystem::path& dir, const MeshData& m) {
  std::filesystem::create_directories(dir);
  GltfMeshView view;
  view.name = "m";
  view.positions = m.positions.data();
  view.normals = m.normals.data();
  view.vertex_count = m.vertex_count();
  view.uvs = m.uvs.empty() ? nullptr : m.uvs.data();
  view.indices = m.indices.data();
  view.index_count = m.indices.size();
  const auto file = dir / "m.gltf";
  EXPECT_TRUE(save_gltf(file, view).ok);
  return file;
}

LodChain bake(const std::filesystem::path& file, BakeReport& report) {
  BakeSettings settings;
  settings.ratios = {1.0f, 0.5f};
  LodChain chain;
  const Status st = bake_model(file, "m", settings, chain, &report, nullptr);
  EXPECT_TRUE(st.ok) << st.message;
  return chain;
}

bool said(const BakeReport& r, const std::string& what) {
  for (const std::string& n : r.notes)
    if (n.find(what) != std::string::npos) return true;
  return false;
}

TEST(LodBakeNormals, SmoothAuthoredNormalsAreLevelZerosAndRoundTrip) {
  MeshData m = test::two_material_sphere(12, 24);
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    const float* p = &m.positions[3 * v];
    const float len = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    // Tilted away from radial, so they differ from anything computed from the faces.
    const float n[3] = {p[0] / len + 0.3f, p[1] / len, p[2] / len};
    const float nl = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    m.normals.insert(m.normals.end(), {n[0] / nl, n[1] / nl, n[2] / nl});
  }
  m.submeshes.clear(), m.materials.clear();
  BakeReport report;
  const LodChain chain = bake(write_mesh(test::temp_dir("bake-normals"), m), report);
  EXPECT_FALSE(said(report, "authored normals")) << "nothing dropped";
  ASSERT_TRUE(chain.authored_normals);
  const LodLevel& l0 = chain.levels[0];
  // Cleaning keeps the vertex order (no welds here): level 0's normals are the file's.
  ASSERT_EQ(l0.vertex_count, m.vertex_count());
  for (uint32_t v = 0; v < l0.vertex_count; ++v)
    for (int k = 0; k < 3; ++k)
      ASSERT_NEAR(chain.normals[3 * size_t(v) + k], m.normals[3 * size_t(v) + k], 1e-6f) << v;
  LodChain back;
  const Status s = decode_lod_asset(encode_lod_asset(chain), "m.lod", back);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_TRUE(back.authored_normals);
  EXPECT_EQ(back.normals, chain.normals);
  // A non-unit authored normal in the asset is refused naming the section.
  LodChain bad = chain;
  bad.normals[3] *= 3;
  LodChain out;
  const Status r = decode_lod_asset(encode_lod_asset(bad), "m.lod", out);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("NRML section: level 0 vertex 1 authored normal has length"), std::string::npos)
      << r.message;
}

TEST(LodBakeNormals, HardEdgesWeldedByCleaningAreSaidAndNotKept) {
  // A box of 6 faces x 4 vertices, each face's own normal: every corner is three copies that
  // differ in normal only, welded by cleaning.
  MeshData m;
  const float d[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const auto& n : d) {
    const int a = n[0] != 0 ? 0 : n[1] != 0 ? 1 : 2, b = (a + 1) % 3, c = (a + 2) % 3;
    const uint32_t base = uint32_t(m.vertex_count());
    const float s = n[a];
    const float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (const auto& q : corners) {
      float p[3];
      p[a] = s, p[b] = q[0], p[c] = q[1];
      m.positions.insert(m.positions.end(), p, p + 3);
      m.normals.insert(m.normals.end(), n, n + 3);
    }
    if (s > 0)
      m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    else
      m.indices.insert(m.indices.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
  }
  MeshData cleaned = m;
  EXPECT_EQ(clean_mesh(cleaned).normal_conflicts, 16u);  // 24 corners welded to 8
  BakeReport report;
  const LodChain chain = bake(write_mesh(test::temp_dir("bake-box-normals"), m), report);
  EXPECT_FALSE(chain.authored_normals);
  EXPECT_TRUE(said(report, "authored normals of")) << "the dropped normals are said";
  EXPECT_TRUE(said(report, "16 welded vertices differ in normal only"));
}

}  // namespace
}  // namespace lod
