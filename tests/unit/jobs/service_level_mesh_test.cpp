// Service::level_mesh, materials and material: views into the model's baked arrays (the same
// addresses on every call, nothing copied), materials with their textures resolved to a file
// path or, for embedded images, their bytes and MIME type; out-of-range requests refused.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <set>
#include <string>

#include "embedded_texture_fixture.h"
#include "jobs/service.h"
#include "lodkit/service.hpp"
#include "runtime/embedded_image.h"
#include "runtime/lod_chain.h"
#include "test_support.h"
#include "unit/jobs/box_chain.h"

namespace lod {
namespace {

namespace fs = std::filesystem;

std::unique_ptr<Service> baking_service(const fs::path& dir) {
  ServiceOptions o;
  o.threads = 1;
  o.baker = mesh_baker();
  o.cache_dir = dir / "cache";
  return std::make_unique<Service>(o);
}

TEST(ServiceLevelMesh, EveryLevelViewsTheBakedChain) {
  const fs::path dir = test::temp_dir("service-level-mesh");
  test::write_text(dir / "sphere.off", test::sphere_off(24, 48));
  test::write_text(dir / "small.off", test::sphere_off(12, 24));
  auto s = baking_service(dir);
  ModelId a = 0, b = 0;
  ASSERT_TRUE(s->add_model(dir / "sphere.off", &a)) << s->last_error();
  ASSERT_TRUE(s->add_model(dir / "small.off", &b)) << s->last_error();
  std::set<uint64_t> ids;
  for (ModelId model : {a, b}) {
    ASSERT_GE(s->level_count(model), 2u);
    EXPECT_TRUE(s->materials(model).empty());
    for (uint32_t l = 0; l < s->level_count(model); ++l) {
      SCOPED_TRACE("model " + std::to_string(model) + " level " + std::to_string(l));
      const std::optional<LevelMeshView> m = s->level_mesh(model, l);
      ASSERT_TRUE(m) << s->last_error();
      EXPECT_NE(m->id, 0u);
      EXPECT_TRUE(ids.insert(m->id).second);
      EXPECT_EQ(m->triangle_count(), s->level_triangles(model, l));
      EXPECT_EQ(m->index_count() % 3, 0u);
      ASSERT_EQ(m->positions.size(), 3u * m->vertex_count);
      EXPECT_TRUE(m->normals.empty() || m->normals.size() == 3u * m->vertex_count);
      EXPECT_TRUE(m->morph_positions.empty());
      EXPECT_TRUE(m->submeshes.empty());
      for (uint32_t i : m->indices) ASSERT_LT(i, m->vertex_count);
      for (float p : m->positions) ASSERT_TRUE(std::isfinite(p));
      const std::optional<LevelMeshView> again = s->level_mesh(model, l);
      ASSERT_TRUE(again);
      EXPECT_EQ(again->id, m->id);
      EXPECT_EQ(again->positions.data(), m->positions.data());
      EXPECT_EQ(again->indices.data(), m->indices.data());
    }
  }
  EXPECT_FALSE(s->level_mesh(a, s->level_count(a)));
  EXPECT_NE(s->last_error().find("not " + std::to_string(s->level_count(a))), std::string::npos) << s->last_error();
  EXPECT_FALSE(s->level_mesh(5, 0));
  EXPECT_NE(s->last_error().find("unknown model 5"), std::string::npos) << s->last_error();
}

// A box of two materials: an embedded PNG on one, a file named by a percent-encoded URI on the
// other, then the culled level.
LodChain two_material_box() {
  LodChain c = test::box_chain("box", 1, 1, 1);
  LodLevel culled;
  culled.first_index = static_cast<uint32_t>(c.indices.size());
  culled.first_vertex = static_cast<uint32_t>(c.positions.size() / 3);
  culled.error = c.levels[0].error;
  c.levels.push_back(culled);
  c.texture_base = "/models/box";
  ChainMaterial embedded;
  embedded.name = "label";
  embedded.base_color_texture = embedded_image_uri(0);
  embedded.alpha_mode = AlphaMode::mask;
  embedded.alpha_cutoff = 0.25f;
  ChainMaterial file;
  file.name = "wood";
  file.base_color[0] = 0.5f;
  file.metallic = 0;
  file.roughness = 0.75f;
  file.emissive[1] = 0.125f;
  file.double_sided = true;
  file.normal_texture = "tex%20dir/grain%2Bnormal.png";
  c.materials = {embedded, file};
  c.submeshes = {{0, 0, 18, 0}, {0, 18, 12, 1}, {0, 30, 6, -1}};
  EmbeddedImage png;
  png.type = ImageType::png;
  png.bytes = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a, 1, 2, 3};
  c.images = {png};
  return c;
}

TEST(ServiceLevelMesh, MaterialsResolveFilesAndEmbeddedImages) {
  const LodChain chain = two_material_box();
  std::string why;
  ASSERT_TRUE(validate_chain(chain, &why)) << why;
  Service s;
  const ModelId model = add_chain(s, chain);

  const std::optional<LevelMeshView> m = s.level_mesh(model, 0);
  ASSERT_TRUE(m) << s.last_error();
  ASSERT_EQ(m->submeshes.size(), 3u);
  EXPECT_EQ(m->submeshes[1].first_index, 18u);
  EXPECT_EQ(m->submeshes[1].index_count, 12u);
  EXPECT_EQ(m->submeshes[1].material, 1);
  EXPECT_EQ(m->submeshes[2].material, -1);

  const std::optional<LevelMeshView> culled = s.level_mesh(model, 1);
  ASSERT_TRUE(culled) << s.last_error();
  EXPECT_NE(culled->id, 0u);
  EXPECT_NE(culled->id, m->id);
  EXPECT_EQ(culled->index_count(), 0u);
  EXPECT_TRUE(culled->positions.empty());
  EXPECT_TRUE(culled->submeshes.empty());

  ASSERT_EQ(s.material_count(model), 2u);
  const Material* label = s.material(model, 0);
  const Material* wood = s.material(model, 1);
  ASSERT_TRUE(label && wood) << s.last_error();
  EXPECT_EQ(label, &s.materials(model)[0]);
  EXPECT_EQ(label->name, "label");
  EXPECT_EQ(label->alpha_mode, MaterialAlpha::mask);
  EXPECT_FLOAT_EQ(label->alpha_cutoff, 0.25f);
  EXPECT_TRUE(label->base_color_texture.path.empty());
  ASSERT_EQ(label->base_color_texture.bytes.size(), 11u);
  EXPECT_EQ(label->base_color_texture.bytes[8], 1);
  EXPECT_EQ(label->base_color_texture.mime, "image/png");
  EXPECT_TRUE(label->normal_texture.empty());

  EXPECT_FLOAT_EQ(wood->base_color[0], 0.5f);
  EXPECT_FLOAT_EQ(wood->base_color[3], 1.0f);
  EXPECT_FLOAT_EQ(wood->metallic, 0.0f);
  EXPECT_FLOAT_EQ(wood->roughness, 0.75f);
  EXPECT_FLOAT_EQ(wood->emissive[1], 0.125f);
  EXPECT_TRUE(wood->double_sided);
  EXPECT_EQ(wood->alpha_mode, MaterialAlpha::opaque);
  EXPECT_TRUE(wood->base_color_texture.empty());
  EXPECT_EQ(fs::path(wood->normal_texture.path), fs::path("/models/box/tex dir/grain+normal.png"));
  EXPECT_EQ(wood->normal_texture.path.data()[wood->normal_texture.path.size()], '\0') << "handed to C as is";
  EXPECT_TRUE(wood->normal_texture.bytes.empty());
  EXPECT_TRUE(wood->normal_texture.mime.empty());

  EXPECT_EQ(s.material(model, 2), nullptr);
  EXPECT_NE(s.last_error().find("no material 2"), std::string::npos) << s.last_error();
  EXPECT_EQ(s.material(9, 0), nullptr);
  EXPECT_NE(s.last_error().find("unknown model 9"), std::string::npos) << s.last_error();
  EXPECT_TRUE(s.materials(9).empty());
  EXPECT_EQ(s.material_count(9), 0u);
}

// A GLB holding its texture: the material hands over the image's bytes as the file held them,
// typed by MIME, with no path; the plain material has no texture and glTF's factors.
TEST(ServiceLevelMesh, GlbEmbeddedImageComesAsBytes) {
  const fs::path dir = test::temp_dir("service-level-mesh-glb");
  const std::vector<uint8_t> png = test::checker_png(16, 4);
  test::write_bytes(dir / "globe.glb", test::embedded_texture_sphere({{"mimeType", "image/png"}}, &png, 24, 48).glb());
  auto s = baking_service(dir);
  ModelId model = 0;
  ASSERT_TRUE(s->add_model(dir / "globe.glb", &model)) << s->last_error();
  ASSERT_EQ(s->material_count(model), 2u);
  const Material& cap = s->materials(model)[0];
  const Material& base = s->materials(model)[1];
  EXPECT_EQ(cap.name, "cap");
  EXPECT_TRUE(cap.base_color_texture.path.empty());
  EXPECT_EQ(std::vector<uint8_t>(cap.base_color_texture.bytes.begin(), cap.base_color_texture.bytes.end()), png);
  EXPECT_EQ(cap.base_color_texture.mime, "image/png");
  EXPECT_FLOAT_EQ(cap.metallic, 0.0f);
  EXPECT_TRUE(base.base_color_texture.empty());
  EXPECT_FLOAT_EQ(base.base_color[0], 0.8f);
  EXPECT_TRUE(base.double_sided);
  for (uint32_t l = 0; l < s->level_count(model); ++l) {
    const std::optional<LevelMeshView> m = s->level_mesh(model, l);
    ASSERT_TRUE(m) << s->last_error();
    if (m->index_count() == 0) continue;  // the culled level
    EXPECT_EQ(m->uvs.size(), 2u * m->vertex_count) << "level " << l;
    uint32_t covered = 0;
    for (const MeshSubmesh& run : m->submeshes) {
      EXPECT_EQ(run.first_index, covered) << "level " << l;
      covered += run.index_count;
    }
    EXPECT_EQ(covered, m->index_count()) << "level " << l;
  }
}

}  // namespace
}  // namespace lod
