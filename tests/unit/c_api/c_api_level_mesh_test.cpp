// lod_model_level_mesh and lod_model_material: a renderer gets every level's geometry and the
// model's materials as views into the service's arrays (the same pointers and ids on every
// call), consistent with the level's triangle count; a bad model, level, index or NULL out
// is a nonzero return with a message, never a crash.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <numbers>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "lodkit/lodkit.h"
#include "test_support.h"

namespace {

namespace fs = std::filesystem;

lod_service* empty_service(const fs::path& dir) {
  lod::test::write_text(dir / "scene.toml", "[run]\nthreads = 1\n\n[cache]\ndir = \"" + (dir / "cache").string() + "\"\n");
  char error[512] = "";
  lod_service* s = lod_service_create((dir / "scene.toml").c_str(), error, sizeof error);
  EXPECT_NE(s, nullptr) << error;
  return s;
}

lod_model add_or_fail(lod_service* s, const fs::path& path) {
  char error[1024] = "";
  lod_model model = 0;
  EXPECT_EQ(lod_model_add(s, path.c_str(), &model, error, sizeof error), 0) << error;
  return model;
}

// A latitude-longitude sphere as OBJ, faces counter-clockwise seen from outside, with uvs:
// the northern half drawn with material "painted" (Kd only), the southern with "textured"
// (map_Kd naming a file in a sub-folder whose name has a space). Poles closed by fans.
void write_two_material_obj(const fs::path& dir, int rings, int segments) {
  fs::create_directories(dir / "my textures");
  lod::test::write_bytes(dir / "my textures" / "checker.png", {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a});
  lod::test::write_text(dir / "sphere.mtl",
                        "newmtl painted\nKd 0.8 0.2 0.1\n\nnewmtl textured\nKd 1 1 1\nmap_Kd my textures/checker.png\n");
  std::ostringstream o;
  o << "mtllib sphere.mtl\n";
  for (int r = 0; r <= rings; ++r) {
    const double theta = std::numbers::pi * r / rings;
    for (int k = 0; k <= segments; ++k) {
      const double phi = 2 * std::numbers::pi * k / segments;
      o << "v " << std::sin(theta) * std::cos(phi) << " " << std::cos(theta) << " " << -std::sin(theta) * std::sin(phi)
        << "\n";
      o << "vt " << double(k) / segments << " " << 1 - double(r) / rings << "\n";
    }
  }
  auto v = [&](int r, int k) { return r * (segments + 1) + k + 1; };
  auto face = [&](int a, int b, int c) { o << "f " << a << "/" << a << " " << b << "/" << b << " " << c << "/" << c << "\n"; };
  for (int r = 0; r < rings; ++r) {
    if (r == 0) o << "usemtl painted\n";
    if (r == rings / 2) o << "usemtl textured\n";
    for (int k = 0; k < segments; ++k) {
      // Seen from outside, going down (r + 1) then east (k + 1) is counter-clockwise.
      if (r > 0) face(v(r, k), v(r + 1, k), v(r, k + 1));
      if (r < rings - 1) face(v(r, k + 1), v(r + 1, k), v(r + 1, k + 1));
    }
  }
  lod::test::write_text(dir / "sphere.obj", o.str());
}

struct Fixture {
  fs::path dir;
  lod_service* s = nullptr;
  lod_model off = 0, obj = 0;
};

Fixture two_models(const std::string& tag) {
  Fixture f;
  f.dir = lod::test::temp_dir(tag);
  lod::test::write_text(f.dir / "sphere.off", lod::test::sphere_off(24, 48));
  write_two_material_obj(f.dir, 24, 48);
  f.s = empty_service(f.dir);
  if (!f.s) return f;
  f.off = add_or_fail(f.s, f.dir / "sphere.off");
  f.obj = add_or_fail(f.s, f.dir / "sphere.obj");
  return f;
}

// Every property a renderer relies on, for every level of `model`; ids go into `ids`.
void expect_drawable_levels(lod_service* s, lod_model model, std::set<uint64_t>& ids) {
  const uint32_t levels = lod_model_level_count(s, model);
  ASSERT_GE(levels, 2u) << "model " << model << ": the test wants a chain";
  const uint32_t materials = lod_model_material_count(s, model);
  for (uint32_t l = 0; l < levels; ++l) {
    SCOPED_TRACE("model " + std::to_string(model) + " level " + std::to_string(l));
    lod_mesh m;
    ASSERT_EQ(lod_model_level_mesh(s, model, l, &m), 0) << lod_last_error();
    EXPECT_NE(m.id, 0u);
    EXPECT_TRUE(ids.insert(m.id).second) << "id " << m.id << " given twice";
    EXPECT_EQ(m.index_count % 3, 0u);
    EXPECT_EQ(m.index_count / 3, lod_model_level_triangles(s, model, l));
    ASSERT_GT(m.index_count, 0u);
    ASSERT_NE(m.positions, nullptr);
    ASSERT_NE(m.indices, nullptr);
    EXPECT_EQ(m.morph_positions, nullptr);
    for (uint32_t i = 0; i < m.index_count; ++i) ASSERT_LT(m.indices[i], m.vertex_count) << "index " << i;
    for (uint32_t i = 0; i < 3 * m.vertex_count; ++i) ASSERT_TRUE(std::isfinite(m.positions[i])) << "position " << i;
    if (m.normals) {
      for (uint32_t v = 0; v < m.vertex_count; ++v) {
        const float* n = m.normals + 3 * v;
        ASSERT_NEAR(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), 1.0, 1e-3) << "normal " << v;
      }
    }
    if (m.uvs) {
      for (uint32_t i = 0; i < 2 * m.vertex_count; ++i) ASSERT_TRUE(std::isfinite(m.uvs[i])) << "uv " << i;
    }
    // Runs cover the indices in order, whole triangles, each naming a material that exists.
    if (m.submesh_count > 0) {
      ASSERT_NE(m.submeshes, nullptr);
      uint32_t at = 0;
      for (uint32_t k = 0; k < m.submesh_count; ++k) {
        const lod_submesh& r = m.submeshes[k];
        EXPECT_EQ(r.first_index, at) << "run " << k;
        EXPECT_GT(r.index_count, 0u) << "run " << k;
        EXPECT_EQ(r.index_count % 3, 0u) << "run " << k;
        EXPECT_TRUE(r.material == -1 || (r.material >= 0 && uint32_t(r.material) < materials)) << "run " << k;
        at += r.index_count;
      }
      EXPECT_EQ(at, m.index_count);
    }
    // A second call: the same bytes at the same addresses under the same id (nothing copied).
    lod_mesh again;
    ASSERT_EQ(lod_model_level_mesh(s, model, l, &again), 0) << lod_last_error();
    EXPECT_EQ(again.id, m.id);
    EXPECT_EQ(again.positions, m.positions);
    EXPECT_EQ(again.indices, m.indices);
    EXPECT_EQ(again.normals, m.normals);
    EXPECT_EQ(again.uvs, m.uvs);
    EXPECT_EQ(again.submeshes, m.submeshes);
    EXPECT_EQ(again.submesh_count, m.submesh_count);
  }
}

TEST(CApiLevelMesh, EveryLevelOfEveryModelIsDrawable) {
  Fixture f = two_models("c-api-level-mesh");
  ASSERT_NE(f.s, nullptr);
  std::set<uint64_t> ids;
  expect_drawable_levels(f.s, f.off, ids);
  expect_drawable_levels(f.s, f.obj, ids);

  lod_mesh off0, obj0;
  ASSERT_EQ(lod_model_level_mesh(f.s, f.off, 0, &off0), 0);
  ASSERT_EQ(lod_model_level_mesh(f.s, f.obj, 0, &obj0), 0);
  EXPECT_EQ(off0.submesh_count, 0u) << "an OFF has no materials: one default surface";
  EXPECT_EQ(off0.submeshes, nullptr);
  EXPECT_EQ(lod_model_material_count(f.s, f.off), 0u);
  EXPECT_EQ(obj0.submesh_count, 2u) << "two materials, one run each";
  EXPECT_NE(obj0.uvs, nullptr) << "the OBJ's vt";
  lod_service_destroy(f.s);
}

// Front faces are counter-clockwise: on a sphere about the origin, a triangle's (b - a) x (c - a)
// points outward (the OBJ above is written so).
TEST(CApiLevelMesh, FrontFacesAreCounterClockwise) {
  Fixture f = two_models("c-api-level-mesh-winding");
  ASSERT_NE(f.s, nullptr);
  for (uint32_t l = 0; l < lod_model_level_count(f.s, f.obj); ++l) {
    lod_mesh m;
    ASSERT_EQ(lod_model_level_mesh(f.s, f.obj, l, &m), 0) << lod_last_error();
    uint32_t outward = 0;
    for (uint32_t t = 0; t < m.index_count / 3; ++t) {
      const float* a = m.positions + 3 * m.indices[3 * t];
      const float* b = m.positions + 3 * m.indices[3 * t + 1];
      const float* c = m.positions + 3 * m.indices[3 * t + 2];
      const float u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      const float n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
      if (n[0] * (a[0] + b[0] + c[0]) + n[1] * (a[1] + b[1] + c[1]) + n[2] * (a[2] + b[2] + c[2]) > 0) ++outward;
    }
    EXPECT_GE(outward, m.index_count / 3 * 95 / 100) << "level " << l << ": " << outward << " of " << m.index_count / 3;
  }
  lod_service_destroy(f.s);
}

TEST(CApiLevelMesh, MaterialsComeFromTheMtl) {
  Fixture f = two_models("c-api-level-mesh-mtl");
  ASSERT_NE(f.s, nullptr);
  ASSERT_EQ(lod_model_material_count(f.s, f.obj), 2u) << lod_last_error();
  const lod_material* painted = nullptr;
  const lod_material* textured = nullptr;
  lod_material m[2];
  for (uint32_t i = 0; i < 2; ++i) {
    ASSERT_EQ(lod_model_material(f.s, f.obj, i, &m[i]), 0) << lod_last_error();
    (m[i].base_color_texture.path ? textured : painted) = &m[i];
  }
  ASSERT_NE(painted, nullptr);
  ASSERT_NE(textured, nullptr);
  EXPECT_FLOAT_EQ(painted->base_color[0], 0.8f);
  EXPECT_FLOAT_EQ(painted->base_color[1], 0.2f);
  EXPECT_FLOAT_EQ(painted->base_color[2], 0.1f);
  EXPECT_FLOAT_EQ(painted->base_color[3], 1.0f);
  EXPECT_EQ(painted->base_color_texture.bytes, nullptr);
  // The path a renderer opens: the MTL's folder joined with map_Kd's file, decoded.
  EXPECT_EQ(fs::path(textured->base_color_texture.path), f.dir / "my textures" / "checker.png");
  EXPECT_TRUE(fs::exists(textured->base_color_texture.path));
  EXPECT_EQ(textured->base_color_texture.bytes, nullptr);
  EXPECT_EQ(textured->base_color_texture.size, 0u);
  EXPECT_EQ(textured->base_color_texture.mime, nullptr);
  EXPECT_EQ(textured->base_color_texture.texcoord, 0u);
  for (const lod_material* x : {painted, textured}) {
    EXPECT_EQ(x->alpha_mode, 0);
    EXPECT_FLOAT_EQ(x->alpha_cutoff, 0.5f);
    EXPECT_EQ(x->double_sided, 0);
    for (float e : x->emissive) EXPECT_EQ(e, 0.f);
    for (const lod_texture* t : {&x->metallic_roughness_texture, &x->normal_texture, &x->occlusion_texture,
                                 &x->emissive_texture}) {
      EXPECT_EQ(t->path, nullptr);
      EXPECT_EQ(t->bytes, nullptr);
      EXPECT_EQ(t->size, 0u);
      EXPECT_EQ(t->mime, nullptr);
    }
  }
  // The level's runs name both materials: the northern half painted, the southern textured.
  lod_mesh level0;
  ASSERT_EQ(lod_model_level_mesh(f.s, f.obj, 0, &level0), 0);
  ASSERT_EQ(level0.submesh_count, 2u);
  ASSERT_GE(level0.submeshes[0].material, 0);
  ASSERT_GE(level0.submeshes[1].material, 0);
  EXPECT_EQ(&m[level0.submeshes[0].material], painted) << "the file's first usemtl first";
  EXPECT_EQ(&m[level0.submeshes[1].material], textured);
  // Strings stay where they were: a second call gives the same pointer.
  lod_material again;
  const uint32_t ti = textured == &m[0] ? 0 : 1;
  ASSERT_EQ(lod_model_material(f.s, f.obj, ti, &again), 0);
  EXPECT_EQ(again.base_color_texture.path, textured->base_color_texture.path);
  lod_service_destroy(f.s);
}

TEST(CApiLevelMesh, BadArgumentsFailWithAMessage) {
  Fixture f = two_models("c-api-level-mesh-bad");
  ASSERT_NE(f.s, nullptr);
  const uint32_t levels = lod_model_level_count(f.s, f.obj);
  lod_mesh mesh;
  std::memset(&mesh, 0xab, sizeof mesh);
  lod_mesh untouched;
  std::memcpy(&untouched, &mesh, sizeof mesh);
  auto expect_refused = [&](int rc, const std::string& part) {
    EXPECT_NE(rc, 0);
    const std::string error = lod_last_error();
    EXPECT_NE(error.find(part), std::string::npos) << "'" << error << "' lacks '" << part << "'";
  };
  expect_refused(lod_model_level_mesh(f.s, 2, 0, &mesh), "unknown model 2");
  expect_refused(lod_model_level_mesh(f.s, 0xffffffffu, 0, &mesh), "unknown model 4294967295");
  expect_refused(lod_model_level_mesh(f.s, f.obj, levels, &mesh), "not " + std::to_string(levels));
  expect_refused(lod_model_level_mesh(f.s, f.obj, 0xffffffffu, &mesh), "not 4294967295");
  EXPECT_EQ(std::memcmp(&mesh, &untouched, sizeof mesh), 0) << "a refused call wrote *out";
  expect_refused(lod_model_level_mesh(f.s, f.obj, 0, nullptr), "out is NULL");
  expect_refused(lod_model_level_mesh(nullptr, 0, 0, &mesh), "service is NULL");

  lod_material mat;
  expect_refused(lod_model_material(f.s, f.obj, 2, &mat), "no material 2");
  expect_refused(lod_model_material(f.s, f.off, 0, &mat), "no material 0");
  expect_refused(lod_model_material(f.s, 7, 0, &mat), "unknown model 7");
  expect_refused(lod_model_material(f.s, f.obj, 0, nullptr), "out is NULL");
  expect_refused(lod_model_material(nullptr, 0, 0, &mat), "service is NULL");

  EXPECT_EQ(lod_model_material_count(f.s, 7), 0u);
  EXPECT_NE(std::string(lod_last_error()).find("unknown model 7"), std::string::npos) << lod_last_error();
  EXPECT_EQ(lod_model_material_count(nullptr, 0), 0u);
  EXPECT_NE(std::string(lod_last_error()).find("service is NULL"), std::string::npos) << lod_last_error();
  lod_service_destroy(f.s);
}

// Meshes may be read from any thread while the LOD thread runs frames and objects change.
TEST(CApiLevelMesh, ReadableFromAnyThreadWhileFramesRun) {
  Fixture f = two_models("c-api-level-mesh-threads");
  ASSERT_NE(f.s, nullptr);
  lod_mesh expected;
  ASSERT_EQ(lod_model_level_mesh(f.s, f.obj, 1, &expected), 0);
  const lod_transform t = {{0, 0, -5}, {0, 0, 0, 1}, 1};
  ASSERT_NE(lod_object_create(f.s, f.obj, &t), 0u);
  ASSERT_EQ(lod_commit(f.s, 1), 0);
  std::thread reader([&] {
    for (int i = 0; i < 2000; ++i) {
      lod_mesh m;
      lod_material mat;
      if (lod_model_level_mesh(f.s, f.obj, 1, &m) != 0 || m.positions != expected.positions || m.id != expected.id ||
          lod_model_material(f.s, f.obj, 0, &mat) != 0) {
        ADD_FAILURE() << "read " << i << ": " << lod_last_error();
        return;
      }
    }
  });
  for (int i = 0; i < 20; ++i) ASSERT_EQ(lod_step(f.s, 1.0 / 60), 0) << lod_last_error();
  reader.join();
  lod_service_destroy(f.s);
}

}  // namespace
