// OBJ with texture coordinates, normals and materials: vt / vn / usemtl / mtllib
// are kept (uvs flipped into glTF's convention, one vertex per distinct v/vt/vn corner,
// submeshes by usemtl, the .mtl's Kd, d / Tr, map_Kd, Ke / map_Ke and bump), and hostile files are refused
// naming file:line.
#include <gtest/gtest.h>

#include <fstream>

#include "preprocess/lod_bake.h"
#include "preprocess/mesh_io.h"
#include "test_support.h"
#include "textured_fixture.h"

namespace lod {
namespace {

namespace fs = std::filesystem;

// Two quads side by side (x 0..1 and 1..2), one material each; the shared edge has one uv.
const char* kObj = R"(# two quads
mtllib quads.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 2 0 0
v 2 1 0
vt 0 0
vt 0.5 0
vt 0.5 1
vt 0 1
vt 1 0
vt 1 1
vn 0 0 1
usemtl left
f 1/1/1 2/2/1 3/3/1 4/4/1
usemtl right
f 2/2/1 5/5/1 6/6/1 3/3/1
)";

const char* kMtl = R"(# materials
newmtl left
Kd 0.8 0.4 0.2
d 0.5
Ns 20
illum 2
newmtl right
Kd 0.1
map_Kd -s 1 1 1 -clamp on tex dir/wood.png
)";

fs::path write_quads(const std::string& tag, const std::string& obj = kObj, const std::string& mtl = kMtl) {
  const fs::path dir = test::temp_dir(tag);
  test::write_text(dir / "quads.obj", obj);
  test::write_text(dir / "quads.mtl", mtl);
  fs::create_directories(dir / "tex dir");
  test::write_bytes(dir / "tex dir" / "wood.png", test::checker_png(16, 4));
  return dir / "quads.obj";
}

TEST(ObjMaterials, KeepsUvsNormalsAndMaterials) {
  MeshData m;
  const Status s = load_mesh(write_quads("obj-materials"), m);
  ASSERT_TRUE(s.ok) << s.message;
  ASSERT_EQ(m.triangle_count(), 4u);
  EXPECT_EQ(m.vertex_count(), 6u) << "one vertex per distinct v/vt/vn corner";
  ASSERT_EQ(m.uvs.size(), 2 * m.vertex_count());
  ASSERT_EQ(m.normals.size(), 3 * m.vertex_count());
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    // vt (u, v) with the origin bottom left -> glTF's (u, 1 - v); here u = x / 2, v = y.
    EXPECT_FLOAT_EQ(m.uvs[2 * v], m.positions[3 * v] / 2) << v;
    EXPECT_FLOAT_EQ(m.uvs[2 * v + 1], 1 - m.positions[3 * v + 1]) << v;
    EXPECT_FLOAT_EQ(m.normals[3 * v + 2], 1.0f);
  }
  ASSERT_EQ(m.submeshes.size(), 2u);
  EXPECT_EQ(m.submeshes[0].triangle_count, 2u);
  EXPECT_EQ(m.submeshes[1].material, 1);
  ASSERT_EQ(m.materials.size(), 2u);
  EXPECT_EQ(m.materials[0].name, "left");
  EXPECT_FLOAT_EQ(m.materials[0].base_color[1], 0.4f);
  EXPECT_FLOAT_EQ(m.materials[0].base_color[3], 0.5f);
  EXPECT_EQ(m.materials[0].alpha_mode, AlphaMode::blend);
  EXPECT_FLOAT_EQ(m.materials[1].base_color[2], 0.1f) << "Kd with one value is grey";
  EXPECT_EQ(m.materials[1].base_color_texture, "tex%20dir/wood.png") << "options skipped, the rest of the line, as a URI";
  bool said = false;
  for (const std::string& w : m.warnings) said |= w.find("Ns, illum") != std::string::npos;
  EXPECT_TRUE(said) << "what the .mtl had that is not kept is said";
}

// QEM to full and half detail.
BakeSettings half_settings() {
  BakeSettings settings;
  settings.ratios = {1.0f, 0.5f};
  settings.method = SimplifyMethod::qem;
  return settings;
}

Status bake_half(const fs::path& obj, LodChain& chain) {
  BakeReport report;
  return bake_model(obj, "quads", half_settings(), chain, &report, nullptr);
}

TEST(ObjMaterials, TheBakeKeepsThemInEveryLevel) {
  const fs::path obj = write_quads("obj-materials-bake");
  const BakeSettings settings = half_settings();
  LodChain chain;
  const Status st = bake_half(obj, chain);
  ASSERT_TRUE(st.ok) << st.message;
  ASSERT_EQ(chain.materials.size(), 2u);
  EXPECT_EQ(chain.materials[1].base_color_texture, "tex%20dir/wood.png");
  EXPECT_EQ(level_submeshes(chain, 0).size(), 2u);
  EXPECT_FALSE(chain.uvs.empty());
  Status key;
  const uint64_t before = bake_key(obj, settings, &key);
  test::write_text(obj.parent_path() / "quads.mtl", std::string(kMtl) + "Kd 0 0 0\n");
  EXPECT_NE(bake_key(obj, settings, &key), before) << "the .mtl is part of the cache key";
}

// map_Bump / bump / norm (with -bm) are the normal texture and its scale; Ke and map_Ke the
// emissive factor and texture (map_Ke alone emits the texture as is). The bake keeps them.
const char* kBumpMtl = R"(newmtl left
Kd 0.8 0.4 0.2
Ke 0.5 0.25 0
map_Bump -bm 0.4 -clamp on tex dir/wood.png
newmtl right
map_Ke tex dir/wood.png
norm tex dir/wood.png
)";

TEST(ObjMaterials, BumpAndKeBecomeNormalAndEmissive) {
  const fs::path obj = write_quads("obj-bump", kObj, kBumpMtl);
  MeshData m;
  const Status s = load_mesh(obj, m);
  ASSERT_TRUE(s.ok) << s.message;
  ASSERT_EQ(m.materials.size(), 2u);
  EXPECT_EQ(m.materials[0].normal_texture, "tex%20dir/wood.png");
  EXPECT_FLOAT_EQ(m.materials[0].normal_scale, 0.4f);
  EXPECT_FLOAT_EQ(m.materials[0].emissive[0], 0.5f);
  EXPECT_FLOAT_EQ(m.materials[0].emissive[1], 0.25f);
  EXPECT_FLOAT_EQ(m.materials[0].emissive[2], 0.0f);
  EXPECT_TRUE(m.materials[0].emissive_texture.empty());
  EXPECT_EQ(m.materials[1].normal_texture, "tex%20dir/wood.png");
  EXPECT_FLOAT_EQ(m.materials[1].normal_scale, 1.0f) << "no -bm: scale 1";
  EXPECT_EQ(m.materials[1].emissive_texture, "tex%20dir/wood.png");
  EXPECT_FLOAT_EQ(m.materials[1].emissive[1], 1.0f) << "map_Ke without Ke emits the texture as is";
  for (const std::string& w : m.warnings) EXPECT_EQ(w.find("Ke"), std::string::npos) << w;

  LodChain chain;
  const Status st = bake_half(obj, chain);
  ASSERT_TRUE(st.ok) << st.message;
  ASSERT_EQ(chain.materials.size(), 2u);
  EXPECT_EQ(chain.materials[0].normal_texture, "tex%20dir/wood.png");
  EXPECT_FLOAT_EQ(chain.materials[0].normal_scale, 0.4f);
  EXPECT_FLOAT_EQ(chain.materials[0].emissive[0], 0.5f);
  EXPECT_EQ(chain.materials[1].emissive_texture, "tex%20dir/wood.png");
  EXPECT_TRUE(chain.materials[1].metallic_roughness_texture.empty());
}

// The PBR extension's Pm / Pr set the factors; map_Pm and map_Pr naming one image (B
// metalness, G roughness, as lodkit's OBJ export writes them) become the metallic-roughness
// texture; separate images cannot be one glTF texture: not imported, said naming the line.
TEST(ObjMaterials, PmPrAndOnePackedMetallicRoughnessImage) {
  const char* mtl = R"(newmtl left
Pm 0.25
Pr 0.75
map_Pm -imfchan b tex dir/wood.png
map_Pr -imfchan g tex dir/wood.png
newmtl right
map_Pm tex dir/wood.png
map_Pr tex dir/other.png
)";
  const fs::path obj = write_quads("obj-pbr", kObj, mtl);
  MeshData m;
  const Status s = load_mesh(obj, m);
  ASSERT_TRUE(s.ok) << s.message;
  ASSERT_EQ(m.materials.size(), 2u);
  EXPECT_FLOAT_EQ(m.materials[0].metallic, 0.25f);
  EXPECT_FLOAT_EQ(m.materials[0].roughness, 0.75f);
  EXPECT_EQ(m.materials[0].metallic_roughness_texture, "tex%20dir/wood.png");
  EXPECT_TRUE(m.materials[1].metallic_roughness_texture.empty());
  EXPECT_FLOAT_EQ(m.materials[1].metallic, 0.0f) << "OBJ's materials stay dielectric without Pm";
  bool said = false;
  for (const std::string& w : m.warnings) said |= w.find("quads.mtl:8: material 'right': map_Pm and map_Pr not imported") != std::string::npos;
  EXPECT_TRUE(said);
}

struct Hostile {
  const char* name;
  std::string obj, mtl;
  const char* expect;
};

TEST(ObjMaterials, HostileFilesAreRefusedNamingFileAndLine) {
  const std::string quads = kObj;
  const Hostile cases[] = {
      {"vt past the end", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/9 3/1\n", kMtl,
       "quads.obj:5: face 0 references texture coordinate 9 of 1"},
      {"vn past the end", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//2\n", kMtl,
       "quads.obj:5: face 0 references normal 2 of 1"},
      {"relative vt before any", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/-1 2/-1 3/-1\n", kMtl,
       "quads.obj:4: face 0 references texture coordinate -1 (relative) of 0"},
      {"huge vt number", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/99999999999999999999 2/1 3/1\n", kMtl,
       "quads.obj:5: face 0 has a corner with an invalid texture coordinate number"},
      {"non-numeric vt", "v 0 0 0\nvt 0 x\n", kMtl, "quads.obj:2: 'vt' needs 2 finite numbers, not 'x'"},
      {"missing mtl", "mtllib nope.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", kMtl,
       "quads.obj:1: mtllib 'nope.mtl' not found"},
      {"bad Kd", quads, "newmtl left\nKd red\n", "quads.mtl:2: 'Kd' needs 1 finite numbers"},
      {"missing texture", quads, "newmtl right\nmap_Kd gone.png\n", "material 'right': map_Kd 'gone.png' not found"},
      {"usemtl without a name", "v 0 0 0\nusemtl\n", kMtl, "quads.obj:2: usemtl without a material name"},
      {"NaN bump multiplier", quads, "newmtl left\nbump -bm nan tex dir/wood.png\n", "quads.mtl:2: bump -bm needs a finite number"},
      {"bump without a file", quads, "newmtl left\nmap_Bump -bm 2\n", "quads.mtl:2: map_Bump without a file name"},
      {"bad Ke", quads, "newmtl left\nKe 1 inf 0\n", "quads.mtl:2: 'Ke' needs 1 finite numbers"},
      {"missing normal texture", quads, "newmtl left\nmap_Bump gone.png\n", "material 'left': map_Bump 'gone.png' not found"},
      {"missing emissive texture", quads, "newmtl right\nmap_Ke gone.png\n", "material 'right': map_Ke 'gone.png' not found"},
  };
  for (const Hostile& h : cases) {
    MeshData m;
    m.source = "untouched";
    const Status s = load_mesh(write_quads("obj-hostile", h.obj, h.mtl), m);
    ASSERT_FALSE(s.ok) << h.name;
    EXPECT_NE(s.message.find(h.expect), std::string::npos) << h.name << ": " << s.message;
    EXPECT_EQ(m.source, "untouched") << h.name;
  }
}

TEST(ObjMaterials, UsemtlWithoutItsMaterialGetsDefaultsAndIsSaid) {
  MeshData m;
  const Status s = load_mesh(write_quads("obj-usemtl", kObj, "newmtl left\nKd 1 0 0\n"), m);
  ASSERT_TRUE(s.ok) << s.message;
  ASSERT_EQ(m.materials.size(), 2u);
  EXPECT_EQ(m.materials[1].name, "right");
  bool said = false;
  for (const std::string& w : m.warnings) said |= w.find("quads.obj:18: usemtl 'right' names no material") != std::string::npos;
  EXPECT_TRUE(said);
}

TEST(ObjMaterials, AGeometryOnlyObjIsReadAsBefore) {
  MeshData m;
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n";
  ASSERT_TRUE(load_mesh_from_memory("plain.obj", ".obj", reinterpret_cast<const uint8_t*>(obj.data()), obj.size(), m).ok);
  EXPECT_EQ(m.vertex_count(), 4u);
  EXPECT_TRUE(m.uvs.empty());
  EXPECT_TRUE(m.submeshes.empty());
  EXPECT_TRUE(m.materials.empty());
}

}  // namespace
}  // namespace lod
