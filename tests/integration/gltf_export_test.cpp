// glTF through the `lod` command: `lod inspect --export DIR --format glb|gltf|obj|ply`
// writes every level; each GLB / glTF passes the Khronos glTF validator (npm gltf-validator,
// installed by scripts/install-node-tools.sh, run through node) with 0 errors; import -> bake
// -> export -> import keeps triangle counts and bounds; a scene may name .glb and .lod files.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "embedded_texture_fixture.h"
#include "gltf_fixture.h"
#include "preprocess/mesh_io.h"
#include "runtime/lod_asset.h"
#include "run_cli.h"
#include "test_support.h"
#include "textured_fixture.h"

namespace {

namespace fs = std::filesystem;
using lod::test::run_lod;

struct Box {
  std::array<float, 3> lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
};

Box bounds_of(const lod::MeshData& m) {
  Box b;
  for (size_t v = 0; v < m.vertex_count(); ++v)
    for (int c = 0; c < 3; ++c) {
      b.lo[size_t(c)] = std::min(b.lo[size_t(c)], m.positions[3 * v + size_t(c)]);
      b.hi[size_t(c)] = std::max(b.hi[size_t(c)], m.positions[3 * v + size_t(c)]);
    }
  return b;
}

// The validator on `files`: its exit code and output. Not installed is a failure, not a skip:
// scripts/run-tests.sh installs it before any test runs.
lod::test::CliResult run_validator(const std::vector<fs::path>& files) {
  const fs::path validator = fs::path(LOD_NODE_TOOLS) / "node_modules" / "gltf-validator";
  lod::test::CliResult r;
  if (!fs::exists(LOD_NODE_EXECUTABLE) || !fs::exists(validator / "package.json")) {
    r.out = "gltf-validator is not installed (node '" LOD_NODE_EXECUTABLE "', validator " + validator.string() +
            "): run scripts/install-node-tools.sh";
    return r;
  }
  std::string cmd = std::string(LOD_NODE_EXECUTABLE) + " " + LOD_SOURCE_DIR "/tests/integration/validate_gltf.js " +
                    validator.string();
  for (const fs::path& f : files) cmd += " '" + f.string() + "'";
  return lod::test::run_shell(cmd);
}

// The validator on every exported file: exit 0 and "errors 0" for each; its output (printed).
std::string expect_valid(const std::vector<fs::path>& exported) {
  const auto v = run_validator(exported);
  EXPECT_EQ(v.code, 0) << v.out;
  for (const fs::path& f : exported) EXPECT_NE(v.out.find(f.string() + ": errors 0 "), std::string::npos) << v.out;
  std::printf("%s", v.out.c_str());
  return v.out;
}

fs::path baked_asset(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".lod") return e.path();
  return {};
}

// A sphere as GLB: the OFF sphere's arrays, under a node that moves it to (5, 0, -2).
fs::path write_sphere_glb(const fs::path& dir, const std::string& name, int rings, int segments) {
  const std::string off = lod::test::sphere_off(rings, segments);
  lod::MeshData m;
  EXPECT_TRUE(lod::load_mesh_from_memory("s.off", ".off", reinterpret_cast<const uint8_t*>(off.data()), off.size(), m).ok);
  lod::test::GltfFixture f;
  f.add_float_mesh(m.positions, m.indices);
  f.set_scene({f.add_node({{"mesh", 0}, {"translation", {5, 0, -2}}})});
  const fs::path file = dir / (name + ".glb");
  lod::test::write_bytes(file, f.glb());
  return file;
}

TEST(GltfExport, EveryExportedLevelPassesTheKhronosValidator) {
  const fs::path dir = lod::test::temp_dir("gltf-validate");
  std::vector<fs::path> meshes = {dir / "ball.off"};
  lod::test::write_text(meshes[0], lod::test::sphere_off(40, 80));
  if (!lod::test::data_dir().empty() && fs::exists(lod::test::data_dir() / "cow.off"))
    meshes.push_back(lod::test::data_dir() / "cow.off");  // a scanned-style mesh, when the build extracted it
  std::vector<fs::path> exported;
  for (const fs::path& mesh : meshes) {
    const fs::path out = dir / ("out-" + mesh.stem().string());
    auto r = run_lod("bake " + mesh.string() + " -o " + out.string() + " --quiet");
    ASSERT_EQ(r.code, 0) << r.out;
    const fs::path asset = baked_asset(out);
    ASSERT_FALSE(asset.empty());
    for (const char* format : {"glb", "gltf"}) {
      const fs::path to = dir / (mesh.stem().string() + "-" + format);
      r = run_lod("inspect " + asset.string() + " --json --export " + to.string() + " --format " + format);
      ASSERT_EQ(r.code, 0) << r.out;
      const auto j = nlohmann::json::parse(r.out);
      ASSERT_GE(j["levels"].size(), 3u);
      for (size_t i = 0; i < j["levels"].size(); ++i) {
        const fs::path level = to / (mesh.stem().string() + "-level" + std::to_string(i) + "." + format);
        ASSERT_TRUE(fs::exists(level)) << level;
        if (std::string(format) == "gltf") {
          EXPECT_TRUE(fs::exists(fs::path(level).replace_extension(".bin")));
        }
        exported.push_back(level);
      }
    }
  }
  expect_valid(exported);
}

// The validator itself must catch a broken file, or the test above proves nothing.
TEST(GltfExport, TheValidatorReportsABrokenFile) {
  const fs::path dir = lod::test::temp_dir("gltf-validate-broken");
  lod::test::GltfFixture f;
  f.add_float_mesh({0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 7});  // index past the vertices, no min/max
  f.set_scene({f.add_node({{"mesh", 0}})});
  lod::test::write_bytes(dir / "broken.glb", f.glb());
  const auto v = run_validator({dir / "broken.glb"});
  EXPECT_EQ(v.code, 1) << v.out;
  EXPECT_EQ(v.out.find("errors 0 "), std::string::npos) << v.out;
}

TEST(GltfExport, RoundTripKeepsTriangleCountsAndBounds) {
  const fs::path dir = lod::test::temp_dir("gltf-roundtrip");
  const fs::path glb = write_sphere_glb(dir, "globe", 30, 60);
  lod::MeshData original;
  ASSERT_TRUE(lod::load_mesh(glb, original).ok);
  const Box want = bounds_of(original);
  EXPECT_NEAR(want.lo[0], 4.0f, 1e-5);  // the node's translation was applied
  auto r = run_lod("bake " + glb.string() + " -o " + (dir / "out").string() + " --ratios 1 0.5 0.25 0.1 --quiet");
  ASSERT_EQ(r.code, 0) << r.out;
  const fs::path asset = baked_asset(dir / "out");
  r = run_lod("inspect " + asset.string() + " --json --export " + (dir / "glb").string() + " --format glb");
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["levels"].size(), 4u);
  EXPECT_EQ(j["levels"][0]["triangles"].get<size_t>(), original.triangle_count());
  for (size_t i = 0; i < 4; ++i) {
    lod::MeshData back;
    const fs::path level = dir / "glb" / ("globe-level" + std::to_string(i) + ".glb");
    const lod::Status s = lod::load_mesh(level, back);
    ASSERT_TRUE(s.ok) << s.message;
    EXPECT_EQ(back.triangle_count(), j["levels"][i]["triangles"].get<size_t>()) << i;
    EXPECT_EQ(back.normals.size(), back.positions.size()) << "normals exported";
    const Box got = bounds_of(back);
    for (size_t c = 0; c < 3; ++c) {
      if (i == 0) {
        EXPECT_FLOAT_EQ(got.lo[c], want.lo[c]);
        EXPECT_FLOAT_EQ(got.hi[c], want.hi[c]);
      } else {  // coarser levels stay near the original's box
        EXPECT_GE(got.lo[c], want.lo[c] - 0.05f) << i;
        EXPECT_LE(got.hi[c], want.hi[c] + 0.05f) << i;
        EXPECT_LE(got.lo[c], want.lo[c] + 0.25f) << i;
        EXPECT_GE(got.hi[c], want.hi[c] - 0.25f) << i;
      }
    }
  }
}

TEST(GltfExport, ObjAndDefaultPlyExportsKeepTheirCounts) {
  const fs::path dir = lod::test::temp_dir("gltf-obj");
  lod::test::write_text(dir / "ball.off", lod::test::sphere_off(20, 40));
  auto r = run_lod("bake " + (dir / "ball.off").string() + " -o " + (dir / "out").string() + " --quiet");
  ASSERT_EQ(r.code, 0) << r.out;
  const fs::path asset = baked_asset(dir / "out");
  r = run_lod("inspect " + asset.string() + " --json --export " + (dir / "obj").string() + " --format obj");
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  r = run_lod("inspect " + asset.string() + " --export " + (dir / "ply").string());
  ASSERT_EQ(r.code, 0) << r.out;
  for (size_t i = 0; i < j["levels"].size(); ++i) {
    for (const char* ext : {"obj", "ply"}) {
      lod::MeshData m;
      const fs::path f = dir / ext / ("ball-level" + std::to_string(i) + "." + ext);
      const lod::Status s = lod::load_mesh(f, m);
      ASSERT_TRUE(s.ok) << s.message;
      EXPECT_EQ(m.triangle_count(), j["levels"][i]["triangles"].get<size_t>()) << f;
    }
  }
  r = run_lod("inspect " + asset.string() + " --export " + (dir / "x").string() + " --format fbx");
  EXPECT_NE(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("--format"), std::string::npos) << r.out;
}

// Materials through bake and export: every level's GLB and glTF carries both materials (one
// primitive each), the texture embedded (GLB) or copied next to it (glTF), passes the
// validator with 0 errors, and imports back with its submeshes and materials; OBJ gets usemtl
// and an .mtl naming a copy of the texture; `lod inspect` shows the materials per level.
TEST(GltfExport, MaterialsAndTexturesThroughEveryExportedLevel) {
  const fs::path dir = lod::test::temp_dir("gltf-materials");
  const fs::path source = lod::test::write_two_material_gltf(dir / "src", "globe");
  ASSERT_FALSE(source.empty());
  auto r = run_lod("bake " + source.string() + " -o " + (dir / "out").string() + " --ratios 1 0.5 0.25 0.1 --quiet");
  ASSERT_EQ(r.code, 0) << r.out;
  const fs::path asset = baked_asset(dir / "out");
  r = run_lod("inspect " + asset.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("materials: 2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("0 'cap'"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("texture globe-image0.png"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("level 3: material 0 x"), std::string::npos) << r.out;
  std::vector<fs::path> exported;
  for (const char* format : {"glb", "gltf", "obj"}) {
    r = run_lod("inspect " + asset.string() + " --json --export " + (dir / format).string() + " --format " + format);
    ASSERT_EQ(r.code, 0) << r.out;
    const auto j = nlohmann::json::parse(r.out.substr(0, r.out.rfind('}') + 1));
    ASSERT_EQ(j["materials"].size(), 2u);
    EXPECT_EQ(j["materials"][0]["base_color_texture"], "globe-image0.png");
    ASSERT_EQ(j["levels"].size(), 4u);
    for (size_t i = 0; i < 4; ++i) {
      SCOPED_TRACE(std::string(format) + " level " + std::to_string(i));
      const auto& runs = j["levels"][i]["submeshes"];
      ASSERT_EQ(runs.size(), 2u);
      const fs::path level = dir / format / ("globe-level" + std::to_string(i) + "." + format);
      lod::MeshData back;
      const lod::Status s = lod::load_mesh(level, back);
      ASSERT_TRUE(s.ok) << s.message;
      EXPECT_EQ(back.triangle_count(), j["levels"][i]["triangles"].get<size_t>());
      if (std::string(format) == "obj") {
        std::ifstream obj(level);
        const std::string text{std::istreambuf_iterator<char>(obj), std::istreambuf_iterator<char>()};
        EXPECT_NE(text.find("mtllib globe-level" + std::to_string(i) + ".mtl"), std::string::npos);
        EXPECT_NE(text.find("usemtl m0_cap"), std::string::npos);
        EXPECT_NE(text.find("usemtl m1_base"), std::string::npos);
        std::ifstream mtl(fs::path(level).replace_extension(".mtl"));
        const std::string m{std::istreambuf_iterator<char>(mtl), std::istreambuf_iterator<char>()};
        EXPECT_NE(m.find("map_Kd globe-level" + std::to_string(i) + "-image0.png"), std::string::npos) << m;
        EXPECT_NE(m.find("Kd 0.8 0.2 0.1"), std::string::npos) << m;
        EXPECT_TRUE(fs::exists(dir / format / ("globe-level" + std::to_string(i) + "-image0.png")));
        continue;
      }
      exported.push_back(level);
      ASSERT_EQ(back.submeshes.size(), 2u) << "one primitive per material";
      ASSERT_EQ(back.materials.size(), 2u);
      EXPECT_EQ(back.submeshes[0].triangle_count, runs[0]["triangles"].get<uint32_t>());
      EXPECT_EQ(back.materials[0].name, "cap");
      EXPECT_TRUE(back.materials[1].double_sided);
      EXPECT_FLOAT_EQ(back.materials[1].base_color[0], 0.8f);
      EXPECT_EQ(back.uvs.size(), 2 * back.vertex_count());
      if (std::string(format) == "glb") {
        EXPECT_TRUE(back.materials[0].base_color_texture_embedded) << "the image is inside the GLB";
      } else {
        EXPECT_EQ(back.materials[0].base_color_texture, "globe-level" + std::to_string(i) + "-image0.png");
        EXPECT_EQ(lod::test::read_bytes(dir / format / back.materials[0].base_color_texture),
                  lod::test::read_bytes(dir / "src" / "globe-image0.png"));
      }
    }
  }
  expect_valid(exported);
}

// Every material field and texture slot through glTF -> bake -> export -> import: material 0
// has all five textures (base colour, metallic-roughness, normal, occlusion, emissive) with
// normal scale, occlusion strength and emissive factor; every exported level (GLB: images
// embedded; glTF: images copied next to it, byte for byte) imports back with all of them.
// The primitives with the normal texture carry TANGENTs (the others do not), so the validator
// reports 0 errors and no "generated tangent space" warning.
TEST(GltfExport, EveryTextureSlotSurvivesBakeExportAndImport) {
  const fs::path dir = lod::test::temp_dir("gltf-every-texture");
  const fs::path source = lod::test::write_two_material_gltf(dir / "src", "globe", 24, 48, /*every_texture=*/true);
  ASSERT_FALSE(source.empty());
  auto r = run_lod("bake " + source.string() + " -o " + (dir / "out").string() + " --ratios 1 0.5 0.25 --quiet");
  ASSERT_EQ(r.code, 0) << r.out;
  const fs::path asset = baked_asset(dir / "out");
  r = run_lod("inspect " + asset.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("normal texture globe-image2.png (scale 0.625)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("occlusion texture globe-image3.png (strength 0.375)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("emissive 0.5 0.25 0.125"), std::string::npos) << r.out;
  const char* uri_keys[] = {"base_color_texture", "metallic_roughness_texture", "normal_texture", "occlusion_texture",
                            "emissive_texture"};
  std::vector<fs::path> exported;
  for (const std::string format : {"glb", "gltf"}) {
    r = run_lod("inspect " + asset.string() + " --json --export " + (dir / format).string() + " --format " + format);
    ASSERT_EQ(r.code, 0) << r.out;
    const auto j = nlohmann::json::parse(r.out.substr(0, r.out.rfind('}') + 1));
    ASSERT_EQ(j["materials"].size(), 2u);
    for (size_t k = 0; k < 5; ++k)
      EXPECT_EQ(j["materials"][0][uri_keys[k]], "globe-image" + std::to_string(k) + ".png") << uri_keys[k];
    EXPECT_EQ(j["materials"][1]["normal_texture"], "");
    ASSERT_EQ(j["levels"].size(), 3u);
    for (size_t i = 0; i < 3; ++i) {
      SCOPED_TRACE(format + " level " + std::to_string(i));
      const std::string stem = "globe-level" + std::to_string(i);
      const fs::path level = dir / format / (stem + "." + format);
      lod::MeshData back;
      const lod::Status s = lod::load_mesh(level, back);
      ASSERT_TRUE(s.ok) << s.message;
      exported.push_back(level);
      ASSERT_EQ(back.materials.size(), 2u);
      const lod::MeshMaterial& m = back.materials[0];
      EXPECT_EQ(m.name, "cap");
      EXPECT_FLOAT_EQ(m.metallic, 0.0f);
      EXPECT_FLOAT_EQ(m.roughness, 0.5f);
      EXPECT_FLOAT_EQ(m.normal_scale, 0.625f);
      EXPECT_FLOAT_EQ(m.occlusion_strength, 0.375f);
      EXPECT_FLOAT_EQ(m.emissive[0], 0.5f);
      EXPECT_FLOAT_EQ(m.emissive[1], 0.25f);
      EXPECT_FLOAT_EQ(m.emissive[2], 0.125f);
      const auto slots = lod::texture_slots(m);
      for (size_t k = 0; k < 5; ++k) {
        SCOPED_TRACE(uri_keys[k]);
        if (format == "glb") {
          EXPECT_TRUE(*slots[k].embedded) << "the image is inside the GLB";
        } else {
          EXPECT_EQ(*slots[k].uri, stem + "-image" + std::to_string(k) + ".png");
          EXPECT_EQ(lod::test::read_bytes(dir / format / *slots[k].uri),
                    lod::test::read_bytes(dir / "src" / ("globe-image" + std::to_string(k) + ".png")));
        }
      }
      const lod::MeshMaterial& plain = back.materials[1];
      EXPECT_TRUE(plain.normal_texture.empty() && !plain.normal_texture_embedded);
      EXPECT_FLOAT_EQ(plain.emissive[0], 0.0f);
      if (format == "gltf") {  // TANGENT on the normal-mapped primitive only
        std::ifstream f(level);
        const auto g = nlohmann::json::parse(f);
        size_t with = 0;
        for (const auto& prim : g["meshes"][0]["primitives"]) {
          const bool mapped = prim.value("material", -1) == 0;
          EXPECT_EQ(prim["attributes"].contains("TANGENT"), mapped) << prim.dump();
          with += mapped;
        }
        EXPECT_EQ(with, 1u);
      }
    }
  }
  const std::string out = expect_valid(exported);
  EXPECT_EQ(out.find("MESH_PRIMITIVE_GENERATED_TANGENT_SPACE"), std::string::npos) << out;
}

// COLOR_0 and TEXCOORD_1 through `lod bake` and `lod inspect --export`: every level of both
// formats has them (and the occlusion texture's texCoord 1), imports back with the level's
// counts, and passes the validator with 0 errors.
TEST(GltfExport, ColoursAndTexcoord1SurviveBakeExportAndImport) {
  const fs::path dir = lod::test::temp_dir("gltf-colour");
  const fs::path source = lod::test::write_coloured_gltf(dir / "src", "painted");
  ASSERT_FALSE(source.empty());
  auto r = run_lod("bake " + source.string() + " -o " + (dir / "out").string() + " --ratios 1 0.5 0.25 --quiet");
  ASSERT_EQ(r.code, 0) << r.out;
  const fs::path asset = baked_asset(dir / "out");
  r = run_lod("inspect " + asset.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("vertex colours (COLOR_0, linear RGBA): every level"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("second texture coordinates (TEXCOORD_1): every level"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("occlusion texture reads TEXCOORD_1"), std::string::npos) << r.out;
  std::vector<fs::path> exported;
  for (const std::string format : {"glb", "gltf"}) {
    r = run_lod("inspect " + asset.string() + " --json --export " + (dir / format).string() + " --format " + format);
    ASSERT_EQ(r.code, 0) << r.out;
    const auto j = nlohmann::json::parse(r.out.substr(0, r.out.rfind('}') + 1));
    EXPECT_TRUE(j["colors"].get<bool>());
    EXPECT_TRUE(j["texcoords1"].get<bool>());
    ASSERT_EQ(j["levels"].size(), 3u);
    for (size_t i = 0; i < 3; ++i) {
      SCOPED_TRACE(format + " level " + std::to_string(i));
      EXPECT_TRUE(j["levels"][i].contains("color_error"));
      EXPECT_TRUE(j["levels"][i].contains("uv1_error"));
      const fs::path level = dir / format / ("painted-level" + std::to_string(i) + "." + format);
      lod::MeshData back;
      const lod::Status s = lod::load_mesh(level, back);
      ASSERT_TRUE(s.ok) << s.message;
      exported.push_back(level);
      EXPECT_EQ(back.vertex_count(), j["levels"][i]["vertices"].get<size_t>());
      EXPECT_EQ(back.triangle_count(), j["levels"][i]["triangles"].get<size_t>());
      EXPECT_EQ(back.colors.size(), 4 * back.vertex_count());
      EXPECT_EQ(back.uvs1.size(), 2 * back.vertex_count());
      EXPECT_EQ(back.uvs.size(), 2 * back.vertex_count());
      ASSERT_EQ(back.materials.size(), 1u);
      EXPECT_EQ(back.materials[0].tex_coords[3], 1);
      EXPECT_FALSE(back.materials[0].occlusion_texture.empty() && !back.materials[0].occlusion_texture_embedded);
      for (float c : back.colors) {
        EXPECT_GE(c, 0.f);
        EXPECT_LE(c, 1.f);
      }
    }
  }
  expect_valid(exported);
}

// The same material through OBJ export: the .mtl names every map MTL has a statement for
// (map_Kd, map_Bump -bm with the normal scale, map_Ke with Ke, map_Pm / map_Pr naming the
// metallic-roughness image, Pm / Pr), each image copied next to it byte for byte, and imports
// back with them; occlusion has no MTL statement: not written, and said.
TEST(GltfExport, ObjKeepsEveryMapMtlHasAStatementFor) {
  const fs::path dir = lod::test::temp_dir("obj-materials-every-slot");
  const fs::path source = lod::test::write_two_material_gltf(dir / "src", "globe", 24, 48, /*every_texture=*/true);
  ASSERT_FALSE(source.empty());
  auto r = run_lod("bake " + source.string() + " -o " + (dir / "out").string() + " --ratios 1 0.5 --quiet");
  ASSERT_EQ(r.code, 0) << r.out;
  r = run_lod("inspect " + baked_asset(dir / "out").string() + " --export " + (dir / "obj").string() + " --format obj");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("occlusion texture"), std::string::npos) << "the dropped occlusion map is said: " << r.out;
  for (size_t i = 0; i < 2; ++i) {
    SCOPED_TRACE("level " + std::to_string(i));
    const fs::path level = dir / "obj" / ("globe-level" + std::to_string(i) + ".obj");
    std::ifstream mtl(fs::path(level).replace_extension(".mtl"));
    const std::string text{std::istreambuf_iterator<char>(mtl), std::istreambuf_iterator<char>()};
    EXPECT_NE(text.find("map_Bump -bm 0.625 "), std::string::npos) << text;
    EXPECT_NE(text.find("Ke 0.5 0.25 0.125"), std::string::npos) << text;
    EXPECT_NE(text.find("map_Pm -imfchan b "), std::string::npos) << text;
    EXPECT_NE(text.find("map_Pr -imfchan g "), std::string::npos) << text;
    lod::MeshData back;
    const lod::Status s = lod::load_mesh(level, back);
    ASSERT_TRUE(s.ok) << s.message;
    for (const std::string& w : back.warnings) EXPECT_EQ(w.find("not imported"), std::string::npos) << w;
    ASSERT_EQ(back.materials.size(), 2u);
    const lod::MeshMaterial& m = back.materials[0];
    EXPECT_FLOAT_EQ(m.metallic, 0.0f);
    EXPECT_FLOAT_EQ(m.roughness, 0.5f);
    EXPECT_FLOAT_EQ(m.normal_scale, 0.625f);
    EXPECT_FLOAT_EQ(m.emissive[0], 0.5f);
    EXPECT_FLOAT_EQ(m.emissive[1], 0.25f);
    EXPECT_FLOAT_EQ(m.emissive[2], 0.125f);
    EXPECT_TRUE(m.occlusion_texture.empty());
    const auto slots = lod::texture_slots(m);
    for (size_t k : {0, 1, 2, 4}) {
      SCOPED_TRACE("slot " + std::to_string(k));
      ASSERT_FALSE(slots[k].uri->empty());
      EXPECT_EQ(lod::test::read_bytes(dir / "obj" / *slots[k].uri),
                lod::test::read_bytes(dir / "src" / ("globe-image" + std::to_string(k) + ".png")));
    }
    const lod::MeshMaterial& plain = back.materials[1];
    EXPECT_TRUE(plain.normal_texture.empty() && plain.emissive_texture.empty() && plain.metallic_roughness_texture.empty());
    EXPECT_FLOAT_EQ(plain.metallic, 1.0f) << "Pm keeps the glTF default";
    EXPECT_FLOAT_EQ(plain.base_color[0], 0.8f);
  }
}

// A texture that is gone by export time: the level is written without it, and said so.
TEST(GltfExport, AMissingTextureIsLeftOutAndSaid) {
  const fs::path dir = lod::test::temp_dir("gltf-materials-missing");
  const fs::path source = lod::test::write_two_material_gltf(dir / "src", "globe", 12, 24);
  auto r = run_lod("bake " + source.string() + " -o " + (dir / "out").string() + " --ratios 1 0.5 --quiet");
  ASSERT_EQ(r.code, 0) << r.out;
  fs::remove(dir / "src" / "globe-image0.png");
  r = run_lod("inspect " + baked_asset(dir / "out").string() + " --export " + (dir / "glb").string() + " --format glb");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("note: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("is not found; written without it"), std::string::npos) << r.out;
  const auto v = run_validator({dir / "glb" / "globe-level0.glb", dir / "glb" / "globe-level1.glb"});
  EXPECT_EQ(v.code, 0) << v.out;
}

// ../shared's spot (2,930 positions, 3,225 texture coordinates, a PNG texture) given a .mtl
// naming its texture: the bake keeps its uvs and the material in every level, and each
// exported GLB embeds the texture and passes the validator.
TEST(GltfExport, SpotObjKeepsItsTextureThroughEveryLevel) {
  LOD_REQUIRE_SHARED_MESH(spot, "spot.obj");
  const fs::path dir = lod::test::temp_dir("gltf-spot");
  const std::vector<uint8_t> obj = lod::test::read_bytes(spot);
  std::string text = "mtllib spot.mtl\nusemtl spot\n";
  text.append(obj.begin(), obj.end());
  lod::test::write_text(dir / "spot.obj", text);
  lod::test::write_text(dir / "spot.mtl", "newmtl spot\nKd 1 1 1\nmap_Kd spot_texture.png\n");
  fs::copy_file(spot.parent_path() / "spot_texture.png", dir / "spot_texture.png");
  auto r = run_lod("bake " + (dir / "spot.obj").string() + " -o " + (dir / "out").string() + " --method qem --quiet");
  ASSERT_EQ(r.code, 0) << r.out;
  const fs::path asset = baked_asset(dir / "out");
  r = run_lod("inspect " + asset.string() + " --json --export " + (dir / "glb").string() + " --format glb");
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["texcoords"].get<bool>());
  ASSERT_EQ(j["materials"].size(), 1u);
  EXPECT_EQ(j["materials"][0]["base_color_texture"], "spot_texture.png");
  std::vector<fs::path> exported;
  for (size_t i = 0; i < j["levels"].size(); ++i) {
    const fs::path level = dir / "glb" / ("spot-level" + std::to_string(i) + ".glb");
    lod::MeshData back;
    ASSERT_TRUE(lod::load_mesh(level, back).ok) << level;
    EXPECT_EQ(back.uvs.size(), 2 * back.vertex_count());
    ASSERT_EQ(back.materials.size(), 1u);
    EXPECT_TRUE(back.materials[0].base_color_texture_embedded);
    std::printf("spot level %zu: %zu triangles, uv error %.4g\n", i, back.triangle_count(),
                j["levels"][i]["uv_error"].get<double>());
    exported.push_back(level);
  }
  const auto v = run_validator(exported);
  EXPECT_EQ(v.code, 0) << v.out;
}

// ---- textures embedded in the source (GLB buffer view, data URI): kept in the .lod (IMGS) ----

using lod::test::embedded_texture_sphere;

// `source` -> lod bake -> the .lod holds `png` -> inspect lists it -> GLB, glTF and OBJ export
// of every level -> import: the image bytes identical in each; the validator: 0 errors.
void expect_embedded_png_round_trip(const fs::path& dir, const fs::path& source, const std::vector<uint8_t>& png) {
  auto r = run_lod("bake " + source.string() + " -o " + (dir / "out").string() + " --ratios 1 0.5 0.25 --quiet");
  ASSERT_EQ(r.code, 0) << r.out;
  const fs::path asset = baked_asset(dir / "out");
  lod::LodChain chain;
  ASSERT_TRUE(lod::read_lod_asset(asset, chain).ok);
  ASSERT_EQ(chain.images.size(), 1u);
  EXPECT_EQ(chain.images[0].type, lod::ImageType::png);
  EXPECT_EQ(chain.images[0].bytes, png) << "the .lod holds the image byte for byte";
  r = run_lod("inspect " + asset.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("embedded images: 1 (" + std::to_string(png.size()) + " bytes"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  embedded:0: image/png, " + std::to_string(png.size()) + " bytes"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("texture embedded:0"), std::string::npos) << r.out;
  std::vector<fs::path> exported;
  for (const std::string format : {"glb", "gltf", "obj"}) {
    r = run_lod("inspect " + asset.string() + " --json --export " + (dir / format).string() + " --format " + format);
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_EQ(r.out.find("note:"), std::string::npos) << r.out;
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_EQ(j["images"].size(), 1u);
    EXPECT_EQ(j["images"][0]["mime_type"], "image/png");
    EXPECT_EQ(j["images"][0]["bytes"].get<size_t>(), png.size());
    EXPECT_EQ(j["materials"][0]["base_color_texture"], "embedded:0");
    ASSERT_EQ(j["levels"].size(), 3u);
    for (size_t i = 0; i < 3; ++i) {
      SCOPED_TRACE(format + " level " + std::to_string(i));
      const std::string stem = "globe-level" + std::to_string(i);
      const fs::path level = dir / format / (stem + "." + format);
      if (format == "obj") {
        std::ifstream mtl(fs::path(level).replace_extension(".mtl"));
        const std::string text{std::istreambuf_iterator<char>(mtl), std::istreambuf_iterator<char>()};
        EXPECT_NE(text.find("map_Kd " + stem + "-image0.png"), std::string::npos) << text;
        EXPECT_EQ(lod::test::read_bytes(dir / format / (stem + "-image0.png")), png);
        continue;
      }
      lod::MeshData back;
      const lod::Status s = lod::load_mesh(level, back);
      ASSERT_TRUE(s.ok) << s.message;
      exported.push_back(level);
      ASSERT_EQ(back.materials.size(), 2u);
      if (format == "glb") {
        EXPECT_TRUE(back.materials[0].base_color_texture_embedded);
        EXPECT_EQ(back.materials[0].base_color_texture, "embedded:0");
        ASSERT_EQ(back.images.size(), 1u);
        EXPECT_EQ(back.images[0].bytes, png) << "the GLB's image is the source's, byte for byte";
      } else {
        EXPECT_EQ(back.materials[0].base_color_texture, stem + "-image0.png");
        EXPECT_EQ(lod::test::read_bytes(dir / format / back.materials[0].base_color_texture), png);
      }
      EXPECT_TRUE(back.materials[1].base_color_texture.empty());
    }
  }
  expect_valid(exported);
}

TEST(GltfExport, APngInsideAGlbIsKeptByTheBakeAndExportedByteForByte) {
  const fs::path dir = lod::test::temp_dir("gltf-embedded-glb");
  const std::vector<uint8_t> png = lod::test::checker_png(32, 4);
  lod::test::GltfFixture f = embedded_texture_sphere({{"mimeType", "image/png"}}, &png);
  lod::test::write_bytes(dir / "globe.glb", f.glb());
  expect_embedded_png_round_trip(dir, dir / "globe.glb", png);
}

TEST(GltfExport, APngInADataUriIsKeptByTheBakeAndExportedByteForByte) {
  const fs::path dir = lod::test::temp_dir("gltf-embedded-data-uri");
  const std::vector<uint8_t> png = lod::test::checker_png(16, 2);
  lod::test::GltfFixture f =
      embedded_texture_sphere({{"uri", "data:image/png;base64," + lod::test::GltfFixture::base64(png)}}, nullptr);
  lod::test::write_text(dir / "globe.gltf", f.gltf_data_uri());
  expect_embedded_png_round_trip(dir, dir / "globe.gltf", png);
}

// A GLB whose texture is inside it through the HLOD path: lod bake --hlod keeps the PNG in the
// .hlod (no note of anything left out), lod inspect lists it (text and --json), and lod export
// --3dtiles puts it, byte for byte, into every GLB whose tile draws the textured material (or
// once under textures/ with --shared-images); every GLB passes the Khronos validator.
TEST(GltfExport, AnHlodBakeOfAGlbWithAnEmbeddedTextureKeepsItThroughTheTiles) {
  const fs::path dir = lod::test::temp_dir("gltf-embedded-hlod");
  const std::vector<uint8_t> png = lod::test::checker_png(32, 4);
  lod::test::GltfFixture f = embedded_texture_sphere({{"mimeType", "image/png"}}, &png);
  lod::test::write_bytes(dir / "globe.glb", f.glb());
  auto r = run_lod("bake " + (dir / "globe.glb").string() + " -o " + (dir / "h").string() + " --hlod --min-verts 300");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(r.out.find("note:"), std::string::npos) << r.out;
  const fs::path hlod = dir / "h" / "globe.hlod";
  auto inspect = run_lod("inspect " + hlod.string());
  ASSERT_EQ(inspect.code, 0) << inspect.out;
  EXPECT_NE(inspect.out.find("materials: 2"), std::string::npos) << inspect.out;
  EXPECT_NE(inspect.out.find("0 'cap': base colour 1 1 1 1"), std::string::npos) << inspect.out;
  EXPECT_NE(inspect.out.find("base colour texture embedded:0"), std::string::npos) << inspect.out;
  EXPECT_NE(inspect.out.find("embedded images: 1 (" + std::to_string(png.size()) + " bytes"), std::string::npos)
      << inspect.out;
  EXPECT_NE(inspect.out.find("  embedded:0: image/png, " + std::to_string(png.size()) + " bytes"), std::string::npos)
      << inspect.out;
  inspect = run_lod("inspect " + hlod.string() + " --json");
  ASSERT_EQ(inspect.code, 0) << inspect.out;
  const auto j = nlohmann::json::parse(inspect.out);
  ASSERT_EQ(j["images"].size(), 1u);
  EXPECT_EQ(j["images"][0]["mime_type"], "image/png");
  EXPECT_EQ(j["images"][0]["bytes"].get<size_t>(), png.size());

  for (const bool shared : {false, true}) {
    SCOPED_TRACE(shared ? "--shared-images" : "embedded in each GLB");
    const fs::path out = dir / (shared ? "shared" : "tiles");
    auto tiles = run_lod("export --3dtiles " + out.string() + " " + hlod.string() + (shared ? " --shared-images" : ""));
    ASSERT_EQ(tiles.code, 0) << tiles.out;
    EXPECT_EQ(tiles.out.find("note:"), std::string::npos) << tiles.out;
    std::vector<fs::path> glbs;
    for (const auto& e : fs::directory_iterator(out / "tiles"))
      if (e.path().extension() == ".glb") glbs.push_back(e.path());
    ASSERT_GT(glbs.size(), 2u);
    size_t textured = 0;
    for (const fs::path& glb : glbs) {
      lod::MeshData back;
      const lod::Status s = lod::load_mesh(glb, back);
      ASSERT_TRUE(s.ok) << s.message;
      for (const lod::MeshMaterial& m : back.materials) {
        if (m.name != "cap") continue;
        ++textured;
        if (shared) {
          EXPECT_FALSE(m.base_color_texture_embedded) << glb;
          EXPECT_EQ(m.base_color_texture, "../textures/image0.png") << glb;
        } else {
          EXPECT_TRUE(m.base_color_texture_embedded) << glb;
          ASSERT_EQ(back.images.size(), 1u) << glb;
          EXPECT_EQ(back.images[0].bytes, png) << glb << ": the tile's image is the source's, byte for byte";
        }
      }
    }
    EXPECT_GT(textured, 0u) << "some tile draws the textured cap";
    if (shared) {
      EXPECT_EQ(lod::test::read_bytes(out / "textures" / "image0.png"), png);
    }
    expect_valid(glbs);
  }
}

// Hostile embedded images: one that is not PNG/JPEG is dropped, said naming the file, material
// and slot (the bake goes on without it); a buffer view past the buffer refuses the file and
// writes nothing.
TEST(GltfExport, AnEmbeddedImageThatIsNotPngOrJpegIsDroppedAndABrokenViewRefused) {
  const fs::path dir = lod::test::temp_dir("gltf-embedded-hostile");
  const std::string gif = "GIF89a\x01\x00\x01\x00\x80\x00\x00";
  const std::vector<uint8_t> not_png(gif.begin(), gif.end());
  lod::test::GltfFixture f = embedded_texture_sphere({{"mimeType", "image/png"}}, &not_png);
  lod::test::write_bytes(dir / "gif.glb", f.glb());
  auto r = run_lod("bake " + (dir / "gif.glb").string() + " -o " + (dir / "gif").string() + " --ratios 1 0.5");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find((dir / "gif.glb").string() +
                       ": material 0: baseColorTexture: embedded image 0 is neither PNG nor JPEG (its first bytes are 47 49 "
                       "46 38"),
            std::string::npos)
      << r.out;
  lod::LodChain chain;
  ASSERT_TRUE(lod::read_lod_asset(baked_asset(dir / "gif"), chain).ok);
  EXPECT_TRUE(chain.images.empty());
  EXPECT_TRUE(chain.materials[0].base_color_texture.empty());

  const std::vector<uint8_t> png = lod::test::checker_png(8, 2);
  lod::test::GltfFixture g = embedded_texture_sphere({{"mimeType", "image/png"}}, &png);
  g.j["bufferViews"].back()["byteLength"] = uint64_t(1) << 40;  // a huge declared length
  lod::test::write_bytes(dir / "huge.glb", g.glb());
  r = run_lod("bake " + (dir / "huge.glb").string() + " -o " + (dir / "huge").string() + " --ratios 1 0.5");
  EXPECT_NE(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("huge.glb: buffer view 4 (bytes"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("runs past the end of buffer 0"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "huge") && !fs::is_empty(dir / "huge")) << "nothing written";
}

// ../shared's spot packed by gltfpack into a GLB (gltfpack 0.18 has no flag for it: a .glb
// output embeds its images, here the PNG quantized textures keep as they are) keeps its
// texture through every level: the .lod holds the PNG gltfpack embedded, each level's runs
// name it, and every exported GLB embeds the same bytes and passes the validator.
TEST(GltfExport, SpotPackedByGltfpackKeepsItsEmbeddedTextureThroughEveryLevel) {
  LOD_REQUIRE_SHARED_MESH(spot, "spot.obj");
  const fs::path texture = spot.parent_path() / "spot_texture.png";
  if (!fs::exists(texture)) GTEST_SKIP() << "needs ../shared/data/meshes/spot_texture.png (absent on this machine)";
  ASSERT_EQ(std::system("command -v gltfpack >/dev/null 2>&1"), 0) << "gltfpack missing: run scripts/install-deps.sh";
  const fs::path dir = lod::test::temp_dir("gltf-spot-gltfpack");
  const std::vector<uint8_t> obj = lod::test::read_bytes(spot);
  std::string text = "mtllib spot.mtl\nusemtl spot\n";
  text.append(obj.begin(), obj.end());
  lod::test::write_text(dir / "spot.obj", text);
  lod::test::write_text(dir / "spot.mtl", "newmtl spot\nKd 1 1 1\nmap_Kd spot_texture.png\n");
  fs::copy_file(texture, dir / "spot_texture.png");
  ASSERT_EQ(std::system(("cd " + dir.string() + " && gltfpack -i spot.obj -o spot.glb >/dev/null 2>&1").c_str()), 0);
  fs::remove(dir / "spot_texture.png");  // the GLB must not need it
  auto r = run_lod("bake " + (dir / "spot.glb").string() + " -o " + (dir / "out").string() + " --method qem");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(r.out.find("not kept"), std::string::npos) << r.out;
  const fs::path asset = baked_asset(dir / "out");
  lod::LodChain chain;
  ASSERT_TRUE(lod::read_lod_asset(asset, chain).ok);
  ASSERT_EQ(chain.images.size(), 1u);
  const std::vector<uint8_t> original = lod::test::read_bytes(texture);
  EXPECT_EQ(chain.images[0].bytes, original) << "gltfpack embeds the PNG as it is";
  ASSERT_EQ(chain.materials.size(), 1u);
  EXPECT_EQ(chain.materials[0].base_color_texture, "embedded:0");
  r = run_lod("inspect " + asset.string() + " --json --export " + (dir / "glb").string() + " --format glb");
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["texcoords"].get<bool>());
  std::vector<fs::path> exported;
  for (size_t i = 0; i < j["levels"].size(); ++i) {
    if (j["levels"][i]["triangles"].get<size_t>() == 0) continue;  // the culled level
    SCOPED_TRACE("level " + std::to_string(i));
    const auto& runs = j["levels"][i]["submeshes"];
    ASSERT_EQ(runs.size(), 1u);
    EXPECT_EQ(runs[0]["material"], 0);
    const fs::path level = dir / "glb" / ("spot-level" + std::to_string(i) + ".glb");
    lod::MeshData back;
    ASSERT_TRUE(lod::load_mesh(level, back).ok) << level;
    EXPECT_EQ(back.uvs.size(), 2 * back.vertex_count());
    ASSERT_EQ(back.materials.size(), 1u);
    ASSERT_EQ(back.images.size(), 1u);
    EXPECT_EQ(back.images[0].bytes, original);
    std::printf("spot (gltfpack) level %zu: %zu triangles, uv error %.4g, image %zu bytes\n", i, back.triangle_count(),
                j["levels"][i]["uv_error"].get<double>(), back.images[0].bytes.size());
    exported.push_back(level);
  }
  EXPECT_GE(exported.size(), 3u);
  expect_valid(exported);
}

// A scene's models may name a .glb (imported and baked) and a .lod (read as it is).
TEST(GltfScene, RunsASceneNamingGlbAndLodFiles) {
  const fs::path dir = lod::test::temp_dir("gltf-scene");
  write_sphere_glb(dir, "ball", 20, 40);
  lod::test::write_text(dir / "pebble.off", lod::test::sphere_off(10, 20));
  auto r = run_lod("bake " + (dir / "pebble.off").string() + " -o " + (dir / "pre").string() + " --quiet");
  ASSERT_EQ(r.code, 0) << r.out;
  fs::copy_file(baked_asset(dir / "pre"), dir / "pebble.lod");
  using namespace lod::test;
  write_text(dir / "scene.toml", run_block(4) + budget_block(20000) +
                                     orbit_camera_block({.radius = 60, .period_frames = 4, .width = 320, .height = 200}) +
                                     model_block("ball", "ball.glb") + model_block("pebble", "pebble.lod") +
                                     scattered_block("ball", 20, 30, "seed = 3\n") +
                                     scattered_block("pebble", 20, 30, "seed = 4\n"));
  r = run_lod("run --config " + (dir / "scene.toml").string() + " --cache " + (dir / "cache").string() +
              " --json " + (dir / "run.json").string() + " --validate");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("pebble.lod loaded as is"), std::string::npos) << r.out;
  std::ifstream f(dir / "run.json");
  const auto j = nlohmann::json::parse(f);
  EXPECT_EQ(j["frames"].size(), 4u);
  EXPECT_EQ(j["summary"]["baked_models"], 1);  // the .glb; the .lod was not baked
}

}  // namespace
