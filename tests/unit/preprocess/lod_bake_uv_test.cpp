// Texture coordinates through every level: a textured sphere with a uv seam (the meridian
// where u wraps from 1 to 0: one position, two uvs) baked from a .glb keeps uvs in every
// level, keeps the seam (the texture never smears across it), reports how far the texture slid,
// and round-trips through the asset and the glTF export.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "preprocess/gltf_write.h"
#include "preprocess/lod_bake.h"
#include "preprocess/mesh_io.h"
#include "runtime/lod_asset.h"
#include "test_support.h"

namespace lod {
namespace {

// Latitude-longitude sphere: rings x (segments + 1) vertices, u = longitude / 2 pi in [0, 1].
MeshData textured_sphere(int rings, int segments) {
  MeshData m;
  for (int r = 0; r <= rings; ++r) {
    const float theta = std::numbers::pi_v<float> * (0.02f + 0.96f * float(r) / float(rings));  // poles left open
    for (int s = 0; s <= segments; ++s) {
      const float phi = s == segments ? 0.f : 2 * std::numbers::pi_v<float> * float(s) / float(segments);  // the seam: same point
      m.positions.insert(m.positions.end(), {std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)});
      m.uvs.insert(m.uvs.end(), {float(s) / float(segments), float(r) / float(rings)});
    }
  }
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const uint32_t a = uint32_t(r * (segments + 1) + s), b = a + 1, c = a + uint32_t(segments + 1), d = c + 1;
      m.indices.insert(m.indices.end(), {a, c, b, b, c, d});
    }
  return m;
}

// Vertex pairs of the level at one position whose u differ by about 1 (the two sides of the seam).
size_t seam_pairs(const LodChain& c, const LodLevel& l) {
  size_t pairs = 0;
  for (uint32_t i = 0; i < l.vertex_count; ++i)
    for (uint32_t j = i + 1; j < l.vertex_count; ++j) {
      const float* p = &c.positions[3 * size_t(l.first_vertex + i)];
      const float* q = &c.positions[3 * size_t(l.first_vertex + j)];
      if (p[0] != q[0] || p[1] != q[1] || p[2] != q[2]) continue;
      const float du = std::fabs(c.uvs[2 * size_t(l.first_vertex + i)] - c.uvs[2 * size_t(l.first_vertex + j)]);
      pairs += du > 0.9f;
    }
  return pairs;
}

LodChain bake_textured(const std::filesystem::path& dir) {
  const MeshData m = textured_sphere(24, 48);
  GltfMeshView view;
  view.name = "globe";
  view.positions = m.positions.data();
  view.vertex_count = m.vertex_count();
  view.uvs = m.uvs.data();
  view.indices = m.indices.data();
  view.index_count = m.indices.size();
  EXPECT_TRUE(save_gltf(dir / "globe.glb", view).ok);
  BakeSettings settings;
  settings.ratios = {1.0f, 0.5f, 0.25f, 0.1f};
  settings.method = SimplifyMethod::qem;
  LodChain chain;
  BakeReport report;
  const Status st = bake_model(dir / "globe.glb", "globe", settings, chain, &report, nullptr);
  EXPECT_TRUE(st.ok) << st.message;
  for (const std::string& n : report.notes) EXPECT_EQ(n.find("texture coordinates"), std::string::npos) << n;
  return chain;
}

TEST(LodBakeUv, EveryLevelKeepsItsUvsAndTheSeam) {
  const LodChain chain = bake_textured(test::temp_dir("bake-uv"));
  ASSERT_EQ(chain.levels.size(), 4u);
  ASSERT_EQ(chain.uvs.size(), chain.positions.size() / 3 * 2);
  ASSERT_EQ(chain.uv_errors.size(), chain.levels.size());
  std::string why;
  EXPECT_TRUE(validate_chain(chain, &why)) << why;
  EXPECT_EQ(chain.uv_errors[0], 0.f);
  for (size_t k = 0; k < chain.levels.size(); ++k) {
    SCOPED_TRACE("level " + std::to_string(k));
    EXPECT_GE(seam_pairs(chain, chain.levels[k]), 3u) << "the seam is still two columns of vertices";
    // uvs follow their vertices: at 10 % of the triangles a vertex stands for ~10 input ones,
    // a few grid cells (1/48 x 1/24 of the texture) from the one it descends from.
    EXPECT_LT(chain.uv_errors[k], 0.25f) << "the texture slid far";
    for (size_t v = 0; v < 2 * size_t(chain.levels[k].vertex_count); ++v) {
      const float uv = chain.uvs[2 * size_t(chain.levels[k].first_vertex) + v];
      EXPECT_TRUE(uv >= -1e-4f && uv <= 1 + 1e-4f) << "interpolated uvs stay in the texture";
    }
  }
  EXPECT_LT(chain.uv_errors[1], chain.uv_errors[3]) << "coarser levels slide further";
  EXPECT_LT(chain.levels.back().triangles(), chain.levels[0].triangles() / 5);
}

TEST(LodBakeUv, UvsRoundTripThroughTheAssetAndTheExport) {
  const auto dir = test::temp_dir("bake-uv-io");
  const LodChain chain = bake_textured(dir);
  LodChain back;
  ASSERT_TRUE(decode_lod_asset(encode_lod_asset(chain), "globe.lod", back).ok);
  EXPECT_EQ(back.uvs, chain.uvs);
  EXPECT_EQ(back.uv_errors, chain.uv_errors);

  const LodLevel& l = chain.levels[2];
  GltfMeshView view;
  view.name = "globe2";
  view.positions = chain.positions.data() + 3 * size_t(l.first_vertex);
  view.vertex_count = l.vertex_count;
  view.uvs = chain.uvs.data() + 2 * size_t(l.first_vertex);
  view.indices = chain.indices.data() + l.first_index;
  view.index_count = l.index_count;
  ASSERT_TRUE(save_gltf(dir / "level2.glb", view).ok);
  MeshData m;
  ASSERT_TRUE(load_mesh(dir / "level2.glb", m).ok);
  ASSERT_EQ(m.uvs.size(), 2 * size_t(l.vertex_count));
  for (size_t i = 0; i < m.uvs.size(); ++i) EXPECT_FLOAT_EQ(m.uvs[i], view.uvs[i]);
}

TEST(LodBakeUv, RaggedOrNonFiniteUvsAreRefused) {
  LodChain chain = bake_textured(test::temp_dir("bake-uv-bad"));
  LodChain short_uvs = chain;
  short_uvs.uvs.pop_back();
  std::string why;
  const char* section = nullptr;
  EXPECT_FALSE(validate_chain(short_uvs, &why, &section));
  EXPECT_STREQ(section, "TEX0");
  LodChain nan_uv = chain;
  nan_uv.uvs[7] = std::nanf("");
  EXPECT_FALSE(validate_chain(nan_uv, &why));
  EXPECT_NE(why.find("uv"), std::string::npos) << why;
  LodChain errors = chain;
  errors.uv_errors.pop_back();
  EXPECT_FALSE(validate_chain(errors, &why));
}

TEST(LodBakeUv, TheAggressiveSimplifierSaysItDropsThem) {
  const auto dir = test::temp_dir("bake-uv-extreme");
  bake_textured(dir);  // writes globe.glb
  BakeSettings settings;
  settings.ratios = {1.0f, 0.25f};
  settings.method = SimplifyMethod::extreme;
  LodChain chain;
  BakeReport report;
  ASSERT_TRUE(bake_model(dir / "globe.glb", "globe", settings, chain, &report, nullptr).ok);
  EXPECT_TRUE(chain.uvs.empty());
  bool said = false;
  for (const std::string& n : report.notes) said |= n.find("texture coordinates") != std::string::npos;
  EXPECT_TRUE(said) << "nothing dropped silently";
}

}  // namespace
}  // namespace lod
