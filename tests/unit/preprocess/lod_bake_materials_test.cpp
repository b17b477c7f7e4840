// Materials through every level: a sphere whose two halves have two materials (one textured)
// keeps both in every level, each triangle on its own side of the equator where they meet
// (the boundary is a seam: a copy of each vertex per material, simplified along its length
// with both copies together and never across), the runs cover every
// level's triangles grouped by material, and the materials round-trip through the asset.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "preprocess/lod_bake.h"
#include "preprocess/material_runs.h"
#include "preprocess/mesh_clean.h"
#include "preprocess/mesh_io.h"
#include "runtime/lod_asset.h"
#include "test_support.h"
#include "textured_fixture.h"
#include "unit/runtime/runtime_fixtures.h"

namespace lod {
namespace {

constexpr int kRings = 24, kSegments = 48;

// The chain's materials alone against validate_chain (its runs made to cover each level).
bool validate_materials_only(LodChain& chain, std::string& why) {
  chain.submeshes.clear();
  for (uint32_t k = 0; k < chain.levels.size(); ++k) chain.submeshes.push_back({k, 0, chain.levels[k].index_count, 0});
  return validate_chain(chain, &why);
}

LodChain bake(const std::filesystem::path& gltf, SimplifyMethod method, BakeReport* report = nullptr) {
  BakeSettings settings;
  settings.ratios = {1.0f, 0.5f, 0.25f, 0.1f};
  settings.method = method;
  LodChain chain;
  BakeReport r;
  const Status st = bake_model(gltf, "globe", settings, chain, &r, nullptr);
  EXPECT_TRUE(st.ok) << st.message;
  if (report) *report = r;
  return chain;
}

// y of the equator ring, where the two materials meet.
float equator_y() {
  const float theta = std::numbers::pi_v<float> * (0.02f + 0.96f * float(kRings / 2) / float(kRings));
  return std::cos(theta);
}

TEST(MaterialRuns, CleaningSplitsASharedVertexPerMaterial) {
  MeshData m = test::two_material_sphere(4, 8);
  const size_t before = m.vertex_count();
  const CleanReport r = clean_mesh(m);
  EXPECT_EQ(r.material_split_vertices, 9u) << "the equator ring (8 + the seam copy) once more";
  EXPECT_EQ(m.vertex_count(), before + 9);
  const std::vector<int32_t> vm = vertex_materials(m);
  const std::vector<int32_t> tm = triangle_materials(m);
  for (size_t t = 0; t < m.triangle_count(); ++t)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(vm[m.indices[3 * t + size_t(c)]], tm[t]) << "one material per vertex";
}

TEST(LodBakeMaterials, EveryLevelKeepsEachTrianglesMaterial) {
  const auto dir = test::temp_dir("bake-materials");
  const auto gltf = test::write_two_material_gltf(dir, "globe", kRings, kSegments);
  ASSERT_FALSE(gltf.empty());
  BakeReport report;
  const LodChain chain = bake(gltf, SimplifyMethod::qem, &report);
  for (const std::string& n : report.notes) EXPECT_EQ(n.find("not kept"), std::string::npos) << n;
  ASSERT_EQ(chain.levels.size(), 4u);
  ASSERT_EQ(chain.materials.size(), 2u);
  EXPECT_EQ(chain.materials[0].name, "cap");
  EXPECT_EQ(chain.materials[0].base_color_texture, "globe-image0.png");
  EXPECT_TRUE(chain.materials[1].double_sided);
  EXPECT_FLOAT_EQ(chain.materials[1].base_color[0], 0.8f);
  EXPECT_EQ(std::filesystem::path(chain.texture_base), std::filesystem::absolute(dir).lexically_normal());
  std::string why;
  ASSERT_TRUE(validate_chain(chain, &why)) << why;
  const float eq = equator_y();
  for (uint32_t k = 0; k < chain.levels.size(); ++k) {
    SCOPED_TRACE("level " + std::to_string(k));
    const LodLevel& l = chain.levels[k];
    const auto runs = level_submeshes(chain, k);
    ASSERT_EQ(runs.size(), 2u) << "both materials in every level";
    EXPECT_EQ(runs[0].material, 0);
    EXPECT_EQ(runs[1].material, 1);
    EXPECT_EQ(runs[0].index_count + runs[1].index_count, l.index_count);
    // Each material's triangles stay on its side of the equator, and the equator ring is
    // still there in both, the same vertices on each side (no collapse moved a vertex across
    // or off the boundary; coarse levels drop ring vertices along it).
    std::set<std::pair<float, float>> ring[2];
    for (int r = 0; r < 2; ++r)
      for (uint32_t i = runs[size_t(r)].first_index; i < runs[size_t(r)].first_index + runs[size_t(r)].index_count; ++i) {
        const float* p = &chain.positions[3 * size_t(l.first_vertex + chain.indices[l.first_index + i])];
        if (r == 0) EXPECT_GE(p[1], eq - 1e-5f);
        else EXPECT_LE(p[1], eq + 1e-5f);
        if (p[1] == eq) ring[r].insert({p[0], p[2]});
      }
    if (k == 0) {
      EXPECT_EQ(ring[0].size(), size_t(kSegments));
    }
    EXPECT_GE(ring[0].size(), 8u) << "the boundary survives in the cap";
    EXPECT_EQ(ring[1], ring[0]) << "and meets the base's boundary exactly";
    if (k + 1 == chain.levels.size()) {
      EXPECT_LT(ring[0].size(), size_t(kSegments)) << "simplified along its length";
    }
  }
  EXPECT_LT(chain.levels.back().triangles(), chain.levels[0].triangles() / 5);
  EXPECT_EQ(chain.uvs.size(), chain.positions.size() / 3 * 2) << "uvs kept beside the materials";
}

TEST(LodBakeMaterials, TheAggressiveSimplifierClustersPerMaterial) {
  const auto dir = test::temp_dir("bake-materials-extreme");
  const auto gltf = test::write_two_material_gltf(dir, "globe", kRings, kSegments);
  BakeReport report;
  const LodChain chain = bake(gltf, SimplifyMethod::extreme, &report);
  std::string why;
  ASSERT_TRUE(validate_chain(chain, &why)) << why;
  bool said = false;
  for (const std::string& n : report.notes) said |= n.find("each material's triangles") != std::string::npos;
  EXPECT_TRUE(said) << "the per-material grids are said in the notes";
  const float eq = equator_y();
  for (uint32_t k = 1; k < chain.levels.size(); ++k) {
    const LodLevel& l = chain.levels[k];
    const auto runs = level_submeshes(chain, k);
    ASSERT_EQ(runs.size(), 2u) << k;
    // A cell's vertex lies inside its material's cluster of input vertices, so on its side
    // (up to the cell's extent along y, well under a ring's spacing beyond the boundary here).
    double mean[2] = {0, 0};
    for (int r = 0; r < 2; ++r) {
      for (uint32_t i = runs[size_t(r)].first_index; i < runs[size_t(r)].first_index + runs[size_t(r)].index_count; ++i)
        mean[r] += chain.positions[3 * size_t(l.first_vertex + chain.indices[l.first_index + i]) + 1];
      mean[r] /= runs[size_t(r)].index_count;
    }
    EXPECT_GT(mean[0], eq) << k;
    EXPECT_LT(mean[1], eq) << k;
  }
}

TEST(LodBakeMaterials, MaterialsRoundTripThroughTheAsset) {
  const auto dir = test::temp_dir("bake-materials-io");
  const LodChain chain = bake(test::write_two_material_gltf(dir, "globe"), SimplifyMethod::qem);
  LodChain back;
  const Status st = decode_lod_asset(encode_lod_asset(chain), "globe.lod", back);
  ASSERT_TRUE(st.ok) << st.message;
  ASSERT_EQ(back.materials.size(), chain.materials.size());
  for (size_t i = 0; i < chain.materials.size(); ++i) {
    EXPECT_EQ(back.materials[i].name, chain.materials[i].name);
    EXPECT_EQ(back.materials[i].base_color_texture, chain.materials[i].base_color_texture);
    EXPECT_EQ(back.materials[i].double_sided, chain.materials[i].double_sided);
    EXPECT_EQ(back.materials[i].alpha_mode, chain.materials[i].alpha_mode);
    for (int c = 0; c < 4; ++c) EXPECT_EQ(back.materials[i].base_color[c], chain.materials[i].base_color[c]);
  }
  EXPECT_EQ(back.texture_base, chain.texture_base);
  ASSERT_EQ(back.submeshes.size(), chain.submeshes.size());
  for (size_t i = 0; i < chain.submeshes.size(); ++i) {
    EXPECT_EQ(back.submeshes[i].level, chain.submeshes[i].level);
    EXPECT_EQ(back.submeshes[i].first_index, chain.submeshes[i].first_index);
    EXPECT_EQ(back.submeshes[i].index_count, chain.submeshes[i].index_count);
    EXPECT_EQ(back.submeshes[i].material, chain.submeshes[i].material);
  }
  EXPECT_EQ(encode_lod_asset(back), encode_lod_asset(chain));
}

TEST(LodBakeMaterials, InvalidRunsAndMaterialsAreRefused) {
  const LodChain chain = bake(test::write_two_material_gltf(test::temp_dir("bake-materials-bad"), "globe"),
                              SimplifyMethod::qem);
  auto refused = [](const LodChain& c, const char* needle) {
    std::string why;
    const char* section = nullptr;
    EXPECT_FALSE(validate_chain(c, &why, &section)) << needle;
    EXPECT_STREQ(section, "MATL");
    EXPECT_NE(why.find(needle), std::string::npos) << why;
  };
  LodChain c = chain;
  c.submeshes[1].material = 7;
  refused(c, "names material 7");
  c = chain;
  c.submeshes[0].index_count -= 3;
  refused(c, "starts at index");
  c = chain;
  c.submeshes.pop_back();
  refused(c, "cover");
  c = chain;
  std::swap(c.submeshes[0], c.submeshes.back());
  refused(c, "");
  c = chain;
  c.materials[0].base_color[2] = std::nanf("");
  refused(c, "base colour");
  c = chain;
  c.materials[1].name = std::string("a\x1b[2Jb");
  refused(c, "control bytes");
  c = chain;
  c.materials[1].alpha_mode = AlphaMode(9);
  refused(c, "alpha mode");
  c = chain;
  c.materials[0].normal_scale = -1;
  refused(c, "normal texture scale");
  c = chain;
  c.materials[0].occlusion_strength = std::nanf("");
  refused(c, "occlusion strength");
  c = chain;
  c.materials[1].emissive[2] = 2;
  refused(c, "emissive factor");
  c = chain;
  c.materials[0].normal_texture = std::string("n\x07.png");
  refused(c, "material 0 normal texture URI");
}

// Out-of-range or NaN texture factors from a file (glTF's JSON cannot hold NaN, but a huge
// number parses as infinity; MTL's -bm can be negative) are clamped, each said naming the
// file and the material; the chain then validates.
TEST(LodBakeMaterials, HostileTextureFactorsAreClampedAndSaid) {
  MeshData mesh;
  mesh.source = "hostile.gltf";
  MeshMaterial m;
  m.name = "rock";
  m.normal_texture = "n.png";
  m.normal_scale = -2;
  m.occlusion_strength = std::nanf("");
  m.emissive[0] = 3;
  m.emissive[1] = std::numeric_limits<float>::infinity();
  m.emissive_texture = "e.png";
  mesh.materials = {m};
  LodChain chain = test::fan_chain("rock", {9});
  std::vector<std::string> notes;
  add_chain_materials(mesh, "/data/hostile.gltf", chain, notes);
  ASSERT_EQ(chain.materials.size(), 1u);
  const ChainMaterial& c = chain.materials[0];
  EXPECT_EQ(c.normal_scale, 0.0f);
  EXPECT_EQ(c.occlusion_strength, 1.0f);
  EXPECT_EQ(c.emissive[0], 1.0f);
  EXPECT_EQ(c.emissive[1], 0.0f) << "a non-finite factor emits nothing";
  EXPECT_EQ(c.normal_texture, "n.png");
  auto said = [&](const std::string& needle) {
    for (const std::string& n : notes)
      if (n.find(needle) != std::string::npos) return true;
    return false;
  };
  EXPECT_TRUE(said("hostile.gltf: material 0 ('rock'): normalTexture.scale -2 is out of [0, 1e6], clamped to 0"));
  EXPECT_TRUE(said("hostile.gltf: material 0 ('rock'): occlusionTexture.strength nan outside [0, 1]"));
  EXPECT_TRUE(said("hostile.gltf: material 0 ('rock'): emissive factor 3 inf 0"));
  std::string why;
  EXPECT_TRUE(validate_materials_only(chain, why)) << why;
}

// Images inside the source reach the chain once each, only when a kept material names them, the
// slots renumbered to the chain's images; an embedded texture the import could not keep, and a
// file URI that looks like the asset's own form, are said and left out.
TEST(LodBakeMaterials, EmbeddedImagesAreCopiedOnceWhenAKeptSlotNamesThem) {
  MeshData mesh;
  mesh.source = "t.glb";
  const auto image = [](uint8_t tag) {
    EmbeddedImage img;
    img.type = ImageType::png;
    img.bytes = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a, tag};
    return img;
  };
  mesh.images = {image(0), image(1), image(2)};
  MeshMaterial a, b;
  a.name = "a";
  a.base_color_texture = "embedded:2", a.base_color_texture_embedded = true;
  a.normal_texture_embedded = true;  // the import dropped it (not PNG/JPEG): no URI
  b.name = "b";
  b.emissive_texture = "embedded:2", b.emissive_texture_embedded = true;
  b.occlusion_texture = "embedded:0";  // a file URI, not an image of the source
  mesh.materials = {a, b};
  LodChain chain = test::fan_chain("t", {9});
  std::vector<std::string> notes;
  add_chain_materials(mesh, "/data/t.glb", chain, notes);
  ASSERT_EQ(chain.images.size(), 1u) << "images 0 and 1 are named by no kept slot";
  EXPECT_EQ(chain.images[0].bytes, mesh.images[2].bytes);
  EXPECT_EQ(chain.materials[0].base_color_texture, "embedded:0");
  EXPECT_EQ(chain.materials[1].emissive_texture, "embedded:0");
  EXPECT_TRUE(chain.materials[0].normal_texture.empty());
  EXPECT_TRUE(chain.materials[1].occlusion_texture.empty());
  auto said = [&](const std::string& needle) {
    for (const std::string& n : notes)
      if (n.find(needle) != std::string::npos) return true;
    return false;
  };
  EXPECT_TRUE(said("t.glb: material 0 ('a'): its normal texture is embedded in the file but was not kept"));
  EXPECT_TRUE(said("t.glb: material 1 ('b'): occlusion texture URI 'embedded:0' has the scheme the asset keeps"));
  std::string why;
  EXPECT_TRUE(validate_materials_only(chain, why)) << why;
}

}  // namespace
}  // namespace lod
