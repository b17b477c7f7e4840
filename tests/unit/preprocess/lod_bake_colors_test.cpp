// Vertex colours (COLOR_0) and a second uv set (TEXCOORD_1) through every level: a
// sphere whose halves are red and blue (the equator a colour seam, one position, two colours),
// with a lightmap-style TEXCOORD_1 and an occlusion texture reading it, baked from a .gltf:
// every level keeps both, interpolated within the input's range, the colour seam stays closed
// and no triangle mixes the halves; the aggressive simplifier keeps the colours (cell means);
// the texture keeps its texCoord; the chain round-trips through the asset and the GLB export.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "preprocess/gltf_write.h"
#include "preprocess/lod_bake.h"
#include "preprocess/mesh_io.h"
#include "runtime/lod_asset.h"
#include "test_support.h"
#include "textured_fixture.h"

namespace lod {
namespace {

LodChain bake_coloured(const std::filesystem::path& dir, SimplifyMethod method, BakeReport* report = nullptr) {
  const std::filesystem::path source = test::write_coloured_gltf(dir, "painted");
  EXPECT_FALSE(source.empty());
  BakeSettings settings;
  settings.ratios = {1.0f, 0.5f, 0.25f, 0.1f};
  settings.method = method;
  LodChain chain;
  BakeReport r;
  const Status st = bake_model(source, "painted", settings, chain, &r, nullptr);
  EXPECT_TRUE(st.ok) << st.message;
  if (report) *report = r;
  return chain;
}

bool is_red(const float* c) { return std::fabs(c[0] - 1) < 1e-5f && std::fabs(c[2]) < 1e-5f && std::fabs(c[3] - 1) < 1e-5f; }
bool is_blue(const float* c) {
  return std::fabs(c[0]) < 1e-5f && std::fabs(c[1]) < 1e-5f && std::fabs(c[2] - 1) < 1e-5f && std::fabs(c[3] - 0.5f) < 1e-5f;
}

TEST(LodBakeColors, EveryLevelKeepsColoursAndTexcoord1WithinTheInputRange) {
  const LodChain chain = bake_coloured(test::temp_dir("bake-colour"), SimplifyMethod::qem);
  ASSERT_EQ(chain.levels.size(), 4u);
  const size_t nv = chain.positions.size() / 3;
  ASSERT_EQ(chain.colors.size(), 4 * nv);
  ASSERT_EQ(chain.uvs1.size(), 2 * nv);
  ASSERT_EQ(chain.uvs.size(), 2 * nv);
  ASSERT_EQ(chain.color_errors.size(), chain.levels.size());
  ASSERT_EQ(chain.uv1_errors.size(), chain.levels.size());
  std::string why;
  EXPECT_TRUE(validate_chain(chain, &why)) << why;
  EXPECT_EQ(chain.color_errors[0], 0.f);
  EXPECT_EQ(chain.uv1_errors[0], 0.f);
  for (size_t k = 1; k < chain.levels.size(); ++k) {
    EXPECT_GE(chain.uv1_errors[k], 0.f);
    EXPECT_LT(chain.uv1_errors[k], 0.25f) << "level " << k << ": TEXCOORD_1 slid across the lightmap";
    EXPECT_LT(chain.color_errors[k], 0.5f) << "level " << k;
  }
  for (size_t v = 0; v < nv; ++v) {
    const float* c = &chain.colors[4 * v];
    EXPECT_TRUE(is_red(c) || is_blue(c)) << "vertex " << v << ": " << c[0] << " " << c[1] << " " << c[2] << " " << c[3];
    EXPECT_GE(c[1], -1e-6f);
    EXPECT_LE(c[1], 1 + 1e-6f);
    const float* t = &chain.uvs1[2 * v];
    EXPECT_GE(t[0], 0.25f - 1e-5f);
    EXPECT_LE(t[0], 0.75f + 1e-5f);
    EXPECT_GE(t[1], -1e-5f);
    EXPECT_LE(t[1], 0.5f + 1e-5f);
  }
  for (size_t k = 0; k < chain.levels.size(); ++k) {
    SCOPED_TRACE("level " + std::to_string(k));
    const LodLevel& l = chain.levels[k];
    const float* colors = &chain.colors[4 * size_t(l.first_vertex)];
    // No triangle mixes the halves: the seam is never collapsed across.
    for (uint32_t i = 0; i < l.index_count; i += 3) {
      const uint32_t* t = &chain.indices[l.first_index + i];
      const bool red = is_red(&colors[4 * t[0]]);
      EXPECT_EQ(is_red(&colors[4 * t[1]]), red);
      EXPECT_EQ(is_red(&colors[4 * t[2]]), red);
    }
    // The seam is still there: positions with a red and a blue copy. Green follows latitude
    // within the red half (interpolated, not constant).
    size_t seam = 0;
    float green_lo = 1, green_hi = 0;
    for (uint32_t i = 0; i < l.vertex_count; ++i) {
      if (is_red(&colors[4 * i])) green_lo = std::min(green_lo, colors[4 * i + 1]), green_hi = std::max(green_hi, colors[4 * i + 1]);
      for (uint32_t j = i + 1; j < l.vertex_count; ++j) {
        const float* p = &chain.positions[3 * size_t(l.first_vertex + i)];
        const float* q = &chain.positions[3 * size_t(l.first_vertex + j)];
        if (p[0] == q[0] && p[1] == q[1] && p[2] == q[2]) seam += is_red(&colors[4 * i]) != is_red(&colors[4 * j]);
      }
    }
    std::printf("painted level %zu: %u triangles, colour seam pairs %zu, colour error %.4f, uv1 error %.4f\n", k,
                l.index_count / 3, seam, chain.color_errors[k], chain.uv1_errors[k]);
    EXPECT_GE(seam, 4u);
    EXPECT_LT(green_lo, 0.2f);
    EXPECT_GT(green_hi, 0.4f);
  }
  ASSERT_EQ(chain.materials.size(), 1u);
  EXPECT_EQ(chain.materials[0].occlusion_texture, "painted-image1.png");
  EXPECT_EQ(chain.materials[0].tex_coords[3], 1) << "the occlusion texture still reads TEXCOORD_1";
  EXPECT_EQ(chain.materials[0].tex_coords[0], 0);
}

TEST(LodBakeColors, TheAggressiveSimplifierKeepsColoursAndSaysItDropsTheUvs) {
  BakeReport report;
  const LodChain chain = bake_coloured(test::temp_dir("bake-colour-extreme"), SimplifyMethod::extreme, &report);
  EXPECT_TRUE(chain.uvs.empty());
  EXPECT_TRUE(chain.uvs1.empty());
  bool said = false;
  for (const std::string& n : report.notes) said |= n.find("texture coordinates (both sets)") != std::string::npos;
  EXPECT_TRUE(said) << "nothing dropped silently";
  ASSERT_EQ(chain.colors.size(), chain.positions.size() / 3 * 4);
  for (float c : chain.colors) {
    EXPECT_GE(c, 0.f);
    EXPECT_LE(c, 1.f);
  }
  std::string why;
  EXPECT_TRUE(validate_chain(chain, &why)) << why;
}

TEST(LodBakeColors, ColoursAndTexcoord1RoundTripThroughTheAssetAndTheGlbExport) {
  const auto dir = test::temp_dir("bake-colour-io");
  const LodChain chain = bake_coloured(dir, SimplifyMethod::qem);
  LodChain back;
  ASSERT_TRUE(decode_lod_asset(encode_lod_asset(chain), "painted.lod", back).ok);
  EXPECT_EQ(back.colors, chain.colors);
  EXPECT_EQ(back.uvs1, chain.uvs1);
  EXPECT_EQ(back.color_errors, chain.color_errors);
  EXPECT_EQ(back.uv1_errors, chain.uv1_errors);
  EXPECT_EQ(back.materials[0].tex_coords, chain.materials[0].tex_coords);

  for (size_t k = 0; k < chain.levels.size(); ++k) {
    SCOPED_TRACE("level " + std::to_string(k));
    const LodLevel& l = chain.levels[k];
    GltfMeshView view;
    view.name = "painted" + std::to_string(k);
    view.positions = chain.positions.data() + 3 * size_t(l.first_vertex);
    view.vertex_count = l.vertex_count;
    view.uvs = chain.uvs.data() + 2 * size_t(l.first_vertex);
    view.uvs1 = chain.uvs1.data() + 2 * size_t(l.first_vertex);
    view.colors = chain.colors.data() + 4 * size_t(l.first_vertex);
    view.indices = chain.indices.data() + l.first_index;
    view.index_count = l.index_count;
    const auto file = dir / ("level" + std::to_string(k) + ".glb");
    ASSERT_TRUE(save_gltf(file, view).ok);
    MeshData m;
    const Status st = load_mesh(file, m);
    ASSERT_TRUE(st.ok) << st.message;
    ASSERT_EQ(m.vertex_count(), size_t(l.vertex_count));
    ASSERT_EQ(m.triangle_count(), size_t(l.index_count / 3));
    ASSERT_EQ(m.colors.size(), 4 * m.vertex_count());
    ASSERT_EQ(m.uvs1.size(), 2 * m.vertex_count());
    for (size_t i = 0; i < m.colors.size(); ++i) EXPECT_FLOAT_EQ(m.colors[i], view.colors[i]) << i;
    for (size_t i = 0; i < m.uvs1.size(); ++i) EXPECT_FLOAT_EQ(m.uvs1[i], view.uvs1[i]) << i;
  }
}

TEST(LodBakeColors, RaggedOrNonFiniteColoursAreRefusedNamingTheSection) {
  const LodChain chain = bake_coloured(test::temp_dir("bake-colour-bad"), SimplifyMethod::qem);
  std::string why;
  const char* section = nullptr;
  LodChain ragged = chain;
  ragged.colors.pop_back();
  EXPECT_FALSE(validate_chain(ragged, &why, &section));
  EXPECT_STREQ(section, "COL0");
  LodChain nan_colour = chain;
  nan_colour.colors[9] = std::nanf("");
  EXPECT_FALSE(validate_chain(nan_colour, &why, &section));
  EXPECT_STREQ(section, "COL0");
  EXPECT_NE(why.find("vertex 2 has a huge or non-finite colour"), std::string::npos) << why;
  LodChain uv1 = chain;
  uv1.uv1_errors.pop_back();
  EXPECT_FALSE(validate_chain(uv1, &why, &section));
  EXPECT_STREQ(section, "TEX1");
}

}  // namespace
}  // namespace lod
