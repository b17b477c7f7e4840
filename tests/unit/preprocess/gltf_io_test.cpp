// glTF 2.0 import: files built in code cover every index and attribute component
// type, strides, strips and fans, node transforms, data-URI and external buffers, materials;
// malformed files are each refused with a message naming the element.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "gltf_fixture.h"
#include "preprocess/gltf_io.h"
#include "preprocess/lod_bake.h"
#include "preprocess/mesh_io.h"
#include "test_support.h"

namespace lod {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::GltfFixture;
using test::kByte, test::kUByte, test::kShort, test::kUShort, test::kUInt, test::kFloat;

const std::vector<float> kQuad = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
const std::vector<uint32_t> kQuadIndices = {0, 1, 2, 0, 2, 3};

Status load_glb(GltfFixture& f, MeshData& m, const std::string& name = "t.glb") {
  const std::vector<uint8_t> bytes = f.glb();
  return load_mesh_from_memory(name, ".glb", bytes.data(), bytes.size(), m);
}

Status load_gltf_text(const std::string& text, MeshData& m, const fs::path& base = {}) {
  return load_gltf_from_memory("t.gltf", ".gltf", reinterpret_cast<const uint8_t*>(text.data()), text.size(), base, m);
}

void expect_refused(const Status& s, const std::string& needle) {
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find(needle), std::string::npos) << s.message;
}

using test::has_warning;

// One node per mesh, all in scene 0.
void place_meshes(GltfFixture& f) {
  std::vector<int> roots;
  for (size_t i = 0; i < f.j["meshes"].size(); ++i) roots.push_back(f.add_node({{"mesh", i}}));
  f.set_scene(roots);
}

// ---- geometry -------------------------------------------------------------------------------

TEST(GltfImport, ReadsAnIndexedQuadFromGlb) {
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  place_meshes(f);
  MeshData m;
  ASSERT_TRUE(load_glb(f, m).ok);
  EXPECT_EQ(m.positions, kQuad);
  EXPECT_EQ(m.indices, kQuadIndices);
  EXPECT_TRUE(m.normals.empty());
  EXPECT_TRUE(m.uvs.empty());
  ASSERT_EQ(m.submeshes.size(), 1u);
  EXPECT_EQ(m.submeshes[0].triangle_count, 2u);
  EXPECT_EQ(m.submeshes[0].material, -1);
}

TEST(GltfImport, ReadsEveryIndexComponentType) {
  for (int type : {kUByte, kUShort, kUInt}) {
    GltfFixture f;
    const int pos = f.add_accessor(f.add_view(kQuad), kFloat, 4, "VEC3");
    int view = -1;
    if (type == kUByte) view = f.add_view(std::vector<uint8_t>{0, 1, 2, 0, 2, 3});
    if (type == kUShort) view = f.add_view(std::vector<uint16_t>{0, 1, 2, 0, 2, 3});
    if (type == kUInt) view = f.add_view(kQuadIndices);
    f.add_mesh({{{"attributes", {{"POSITION", pos}}}, {"indices", f.add_accessor(view, type, 6, "SCALAR")}}});
    place_meshes(f);
    MeshData m;
    ASSERT_TRUE(load_glb(f, m).ok) << type;
    EXPECT_EQ(m.indices, kQuadIndices) << type;
  }
}

// Each allowed POSITION component type: the values 1 and -1 (or the type's largest) decode
// to floats as the spec says (normalized: /127, /255, /32767, /65535).
TEST(GltfImport, DecodesEveryPositionComponentType) {
  struct Case {
    int type;
    bool normalized;
    float expect_max;
  };
  for (const Case c : {Case{kFloat, false, 3.0f}, Case{kByte, true, 1.0f}, Case{kUByte, true, 1.0f},
                       Case{kShort, true, 1.0f}, Case{kUShort, true, 1.0f}, Case{kByte, false, 127.0f},
                       Case{kUByte, false, 255.0f}, Case{kShort, false, 32767.0f}, Case{kUShort, false, 65535.0f}}) {
    GltfFixture f;
    std::vector<uint8_t> raw;
    // Three vertices, each padded to 4-byte-aligned elements via byteStride (spec 3.6.2.4).
    const size_t comp = c.type == kFloat ? 4 : (c.type == kShort || c.type == kUShort) ? 2 : 1;
    const size_t stride = (3 * comp + 3) / 4 * 4;
    raw.resize(3 * stride, 0);
    auto put = [&](size_t v, int axis, double value) {
      uint8_t* p = raw.data() + v * stride + size_t(axis) * comp;
      if (c.type == kFloat) { const float x = float(value); std::memcpy(p, &x, 4); }
      if (c.type == kByte) { const int8_t x = int8_t(value); std::memcpy(p, &x, 1); }
      if (c.type == kUByte) { const uint8_t x = uint8_t(value); std::memcpy(p, &x, 1); }
      if (c.type == kShort) { const int16_t x = int16_t(value); std::memcpy(p, &x, 2); }
      if (c.type == kUShort) { const uint16_t x = uint16_t(value); std::memcpy(p, &x, 2); }
    };
    const double top = c.type == kFloat ? 3 : c.type == kByte ? 127 : c.type == kUByte ? 255 : c.type == kShort ? 32767 : 65535;
    put(1, 0, top);
    put(2, 1, top);
    const int view = f.add_view(raw.data(), raw.size(), stride);
    const int pos = f.add_accessor(view, c.type, 3, "VEC3", c.normalized);
    f.add_mesh({{{"attributes", {{"POSITION", pos}}}}});
    place_meshes(f);
    MeshData m;
    const Status s = load_glb(f, m);
    ASSERT_TRUE(s.ok) << c.type << " " << s.message;
    ASSERT_EQ(m.positions.size(), 9u);
    EXPECT_FLOAT_EQ(m.positions[3], c.expect_max) << c.type << (c.normalized ? " normalized" : "");
    EXPECT_FLOAT_EQ(m.positions[7], c.expect_max) << c.type;
    EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2}));
  }
}

TEST(GltfImport, DecodesSignedNormalizedValuesClampedAtMinusOne) {
  GltfFixture f;
  // int8 -128 and -127 both mean -1 (spec: max(c / 127, -1)).
  const std::vector<int8_t> pos = {-128, 0, 0, 0, 0, 0, -127, 0, 0, 0, 0, 0, 0, -127, 0, 0};
  const int view = f.add_view(pos.data(), pos.size(), 4);
  const int a = f.add_accessor(view, kByte, 4, "VEC3", true);
  f.add_mesh({{{"attributes", {{"POSITION", a}}}, {"mode", 6}}});
  place_meshes(f);
  MeshData m;
  ASSERT_TRUE(load_glb(f, m).ok);
  EXPECT_FLOAT_EQ(m.positions[0], -1.0f);   // -128
  EXPECT_FLOAT_EQ(m.positions[5], -1.0f);   // -127
  EXPECT_FLOAT_EQ(m.positions[10], -1.0f);
}

TEST(GltfImport, DecodesNormalAndTexcoordComponentTypes) {
  GltfFixture f;
  const int pos = f.add_accessor(f.add_view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}), kFloat, 3, "VEC3");
  // Normals as normalized int16 (0, 0, 32767), padded to 8 bytes.
  const std::vector<int16_t> n = {0, 0, 32767, 0, 0, 0, 32767, 0, 0, 0, 32767, 0};
  const int nrm = f.add_accessor(f.add_view(n.data(), n.size() * 2, 8), kShort, 3, "VEC3", true);
  // UVs as normalized uint16 (65535 = 1).
  const std::vector<uint16_t> uv = {0, 0, 65535, 0, 0, 65535};
  const int tex = f.add_accessor(f.add_view(uv), kUShort, 3, "VEC2", true);
  f.add_mesh({{{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}, {"TEXCOORD_0", tex}}}}});
  place_meshes(f);
  MeshData m;
  ASSERT_TRUE(load_glb(f, m).ok);
  ASSERT_EQ(m.normals.size(), 9u);
  EXPECT_FLOAT_EQ(m.normals[2], 1.0f);
  EXPECT_FLOAT_EQ(m.normals[8], 1.0f);
  ASSERT_EQ(m.uvs.size(), 6u);
  EXPECT_EQ(m.uvs, (std::vector<float>{0, 0, 1, 0, 0, 1}));
}

TEST(GltfImport, HonoursInterleavedByteStrides) {
  // position (12) + normal (12) + uv (8) = 32-byte vertices in one view.
  std::vector<float> v;
  for (int i = 0; i < 3; ++i) {
    v.insert(v.end(), {float(i == 1), float(i == 2), 0.0f, 0, 0, 1, float(i) * 0.25f, 0.5f});
  }
  GltfFixture f;
  const int view = f.add_view(v.data(), v.size() * 4, 32);
  const int pos = f.add_accessor(view, kFloat, 3, "VEC3");
  const int nrm = f.add_accessor(view, kFloat, 3, "VEC3", false, 12);
  const int tex = f.add_accessor(view, kFloat, 3, "VEC2", false, 24);
  f.add_mesh({{{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}, {"TEXCOORD_0", tex}}}}});
  place_meshes(f);
  MeshData m;
  ASSERT_TRUE(load_glb(f, m).ok);
  EXPECT_EQ(m.positions, (std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}));
  EXPECT_EQ(m.normals, (std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1}));
  EXPECT_EQ(m.uvs, (std::vector<float>{0, 0.5f, 0.25f, 0.5f, 0.5f, 0.5f}));
}

TEST(GltfImport, ConvertsStripsAndFansKeepingTheWinding) {
  // A strip of 5 corners: triangles {p0,p1,p2}, {p1,p3,p2}, {p2,p3,p4} (spec 3.7.2.1).
  const std::vector<float> pos = {0, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1, 0, 2, 0, 0};
  GltfFixture strip;
  strip.add_float_mesh(pos, {}, 5);
  place_meshes(strip);
  MeshData m;
  ASSERT_TRUE(load_glb(strip, m).ok);
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 1, 3, 2, 2, 3, 4}));
  // A fan of 5 corners: {1,2,0}, {2,3,0}, {3,4,0}.
  GltfFixture fan;
  fan.add_float_mesh(pos, {4, 3, 2, 1, 0}, 6);
  place_meshes(fan);
  ASSERT_TRUE(load_glb(fan, m).ok);
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{3, 2, 4, 2, 1, 4, 1, 0, 4}));
}

TEST(GltfImport, ReadsNonIndexedTriangles) {
  GltfFixture f;
  f.add_float_mesh(kQuad);  // 4 corners: one triangle, one corner left over
  place_meshes(f);
  MeshData m;
  ASSERT_TRUE(load_glb(f, m).ok);
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_TRUE(has_warning(m, "not a multiple of 3")) << m.warnings.size();
}

// ---- scene tree -------------------------------------------------------------------------------

TEST(GltfImport, ComposesNodeTransformsDownTheTree) {
  GltfFixture f;
  f.add_float_mesh({0, 0, 0, 1, 0, 0, 0, 1, 0});
  // parent: translate (10, 0, 0); child: rotate 90 degrees about z, scale 2.
  const double h = std::sqrt(0.5);
  const int child = f.add_node({{"mesh", 0}, {"rotation", {0, 0, h, h}}, {"scale", {2, 2, 2}}});
  const int parent = f.add_node({{"translation", {10, 0, 0}}, {"children", {child}}});
  f.set_scene({parent});
  MeshData m;
  ASSERT_TRUE(load_glb(f, m).ok);
  ASSERT_EQ(m.positions.size(), 9u);
  const float want[9] = {10, 0, 0, 10, 2, 0, 8, 0, 0};
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(m.positions[size_t(i)], want[i], 1e-5) << i;
}

TEST(GltfImport, AppliesMatricesInstancesAndMirrors) {
  GltfFixture f;
  f.add_float_mesh({0, 0, 0, 1, 0, 0, 0, 1, 0});
  // Node 0: column-major matrix translating by (0, 0, 5); node 1: mirrored in x.
  const int a = f.add_node({{"mesh", 0}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 5, 1}}});
  const int b = f.add_node({{"mesh", 0}, {"scale", {-1, 1, 1}}});
  f.set_scene({a, b});
  MeshData m;
  ASSERT_TRUE(load_glb(f, m).ok);
  ASSERT_EQ(m.triangle_count(), 2u);  // one mesh, two instances
  EXPECT_FLOAT_EQ(m.positions[2], 5.0f);
  EXPECT_FLOAT_EQ(m.positions[12], -1.0f);  // mirrored copy's second vertex
  // The mirror flips the winding back, so both face +z.
  auto normal_z = [&](size_t t) {
    const float* p0 = &m.positions[3 * m.indices[3 * t]];
    const float* p1 = &m.positions[3 * m.indices[3 * t + 1]];
    const float* p2 = &m.positions[3 * m.indices[3 * t + 2]];
    return (p1[0] - p0[0]) * (p2[1] - p0[1]) - (p1[1] - p0[1]) * (p2[0] - p0[0]);
  };
  EXPECT_GT(normal_z(0), 0);
  EXPECT_GT(normal_z(1), 0);
}

TEST(GltfImport, UsesTheDefaultSceneOnly) {
  GltfFixture f;
  f.add_float_mesh({0, 0, 0, 1, 0, 0, 0, 1, 0});
  f.add_float_mesh(kQuad, kQuadIndices);
  const int n0 = f.add_node({{"mesh", 0}});
  const int n1 = f.add_node({{"mesh", 1}});
  f.j["scenes"] = json::array({{{"nodes", {n0}}}, {{"nodes", {n1}}}});
  f.j["scene"] = 1;
  MeshData m;
  ASSERT_TRUE(load_glb(f, m).ok);
  EXPECT_EQ(m.triangle_count(), 2u);
}

// ---- buffers ----------------------------------------------------------------------------------

TEST(GltfImport, ReadsDataUriAndExternalBuffers) {
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  place_meshes(f);
  MeshData m;
  ASSERT_TRUE(load_gltf_text(f.gltf_data_uri(), m).ok);
  EXPECT_EQ(m.indices, kQuadIndices);

  const fs::path dir = test::temp_dir("gltf-external");
  GltfFixture g;
  g.add_float_mesh(kQuad, kQuadIndices);
  place_meshes(g);
  const fs::path file = g.write_gltf_with_bin(dir, "quad");
  MeshData e;
  const Status s = load_mesh(file, e);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(e.positions, kQuad);
  EXPECT_EQ(e.source, file.string());
}

TEST(GltfImport, ReadsAGlbWithAnExternalBufferAndMemoryWithABaseDir) {
  const fs::path dir = test::temp_dir("gltf-glb-external");
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  place_meshes(f);
  const fs::path gltf = f.write_gltf_with_bin(dir, "quad");  // also writes quad.bin
  // The same JSON as a GLB without a BIN chunk, its buffer still named by URI.
  std::string text_chunk = f.j.dump();
  while (text_chunk.size() % 4) text_chunk += ' ';
  std::vector<uint8_t> glb = {'g', 'l', 'T', 'F', 2, 0, 0, 0};
  const uint32_t total = uint32_t(20 + text_chunk.size()), length = uint32_t(text_chunk.size()), kind = 0x4E4F534A;
  for (uint32_t v : {total, length, kind})
    for (int b = 0; b < 4; ++b) glb.push_back(uint8_t(v >> (8 * b)));
  glb.insert(glb.end(), text_chunk.begin(), text_chunk.end());
  test::write_bytes(dir / "quad.glb", glb);
  MeshData m;
  Status s = load_mesh(dir / "quad.glb", m);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(m.indices, kQuadIndices);
  const std::vector<uint8_t> text = test::read_bytes(gltf);
  s = load_gltf_from_memory("mem.gltf", ".gltf", text.data(), text.size(), dir, m);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(m.positions, kQuad);
}

TEST(GltfImport, RefusesADataUriOfTheWrongLength) {
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  place_meshes(f);
  const std::string text = f.gltf_data_uri();
  json j = json::parse(text);
  j["buffers"][0]["byteLength"] = j["buffers"][0]["byteLength"].get<size_t>() + 4;
  MeshData m;
  expect_refused(load_gltf_text(j.dump(), m), "t.gltf: not valid glTF");
}

TEST(GltfImport, RefusesAMissingExternalBuffer) {
  const fs::path dir = test::temp_dir("gltf-missing-bin");
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  place_meshes(f);
  const fs::path file = f.write_gltf_with_bin(dir, "quad");
  fs::remove(dir / "quad.bin");
  MeshData m;
  const Status s = load_mesh(file, m);
  expect_refused(s, file.string());
  expect_refused(s, "quad.bin");
}

// The bake cache key covers the .bin a .gltf names: new geometry there is a new bake.
TEST(GltfImport, BakeKeyCoversTheFilesAGltfNames) {
  const fs::path dir = test::temp_dir("gltf-key");
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  place_meshes(f);
  f.j["images"] = json::array({{{"uri", "my%20tex.png"}}, {{"uri", "data:image/png;base64,AAAA"}}});
  const fs::path file = f.write_gltf_with_bin(dir, "quad");
  EXPECT_EQ(gltf_external_files(file), (std::vector<fs::path>{dir / "quad.bin", dir / "my tex.png"}));
  Status st;
  const uint64_t before = bake_key(file, BakeSettings{}, &st);
  ASSERT_TRUE(st.ok) << st.message;
  std::vector<uint8_t> bin = test::read_bytes(dir / "quad.bin");
  bin[4] ^= 0x40;
  test::write_bytes(dir / "quad.bin", bin);
  EXPECT_NE(bake_key(file, BakeSettings{}, &st), before);
}

TEST(GltfImport, InMemoryInputNeverReadsExternalFiles) {
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  place_meshes(f);
  f.finish_buffer("quad.bin");
  const std::string text = f.j.dump();
  MeshData m;
  expect_refused(load_gltf_text(text, m), "t.gltf");
}

// ---- materials ---------------------------------------------------------------------------------

TEST(GltfImport, ReadsMaterialsAsSubmeshes) {
  const fs::path dir = test::temp_dir("gltf-materials");
  test::write_bytes(dir / "bark texture.png", {0x89, 'P', 'N', 'G'});
  GltfFixture f;
  const int pos = f.add_accessor(f.add_view(kQuad), kFloat, 4, "VEC3");
  const int i0 = f.add_accessor(f.add_view(std::vector<uint16_t>{0, 1, 2, 0}), kUShort, 3, "SCALAR");
  const int i1 = f.add_accessor(f.add_view(std::vector<uint16_t>{0, 2, 3, 0}), kUShort, 3, "SCALAR");
  f.add_mesh({{{"attributes", {{"POSITION", pos}}}, {"indices", i0}, {"material", 1}},
              {{"attributes", {{"POSITION", pos}}}, {"indices", i1}, {"material", 0}}});
  f.j["images"] = json::array({{{"uri", "bark%20texture.png"}}});
  f.j["textures"] = json::array({{{"source", 0}}});
  f.j["materials"] = json::array(
      {{{"name", "leaf"}, {"alphaMode", "MASK"}, {"alphaCutoff", 0.25}, {"doubleSided", true}},
       {{"name", "bark"},
        {"pbrMetallicRoughness",
         {{"baseColorFactor", {0.5, 0.25, 1, 1}}, {"baseColorTexture", {{"index", 0}}}, {"metallicFactor", 0.0},
          {"roughnessFactor", 0.75}}}}});
  place_meshes(f);
  const fs::path file = f.write_gltf_with_bin(dir, "tree");
  MeshData m;
  const Status s = load_mesh(file, m);
  ASSERT_TRUE(s.ok) << s.message;
  ASSERT_EQ(m.submeshes.size(), 2u);
  EXPECT_EQ(m.submeshes[0].material, 1);
  EXPECT_EQ(m.submeshes[1].material, 0);
  EXPECT_EQ(m.submeshes[1].first_triangle, 1u);
  ASSERT_EQ(m.materials.size(), 2u);
  EXPECT_EQ(m.materials[0].name, "leaf");
  EXPECT_EQ(m.materials[0].alpha_mode, AlphaMode::mask);
  EXPECT_FLOAT_EQ(m.materials[0].alpha_cutoff, 0.25f);
  EXPECT_TRUE(m.materials[0].double_sided);
  EXPECT_EQ(m.materials[1].base_color_texture, "bark%20texture.png");
  EXPECT_FALSE(m.materials[1].base_color_texture_embedded);
  EXPECT_FLOAT_EQ(m.materials[1].base_color[1], 0.25f);
  EXPECT_FLOAT_EQ(m.materials[1].metallic, 0.0f);
  EXPECT_FLOAT_EQ(m.materials[1].roughness, 0.75f);

  // The same file without its image is refused, naming the image.
  fs::remove(dir / "bark texture.png");
  expect_refused(load_mesh(file, m), "image 0 'bark%20texture.png' not found");
}

TEST(GltfImport, ReadsEveryTextureSlotWithItsFactors) {
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  f.j["meshes"][0]["primitives"][0]["material"] = 0;
  f.j["images"] = json::array({{{"uri", "c.png"}}, {{"uri", "mr.png"}}, {{"uri", "n.png"}}, {{"uri", "ao.png"}}, {{"uri", "e.png"}}});
  f.j["textures"] = json::array({{{"source", 0}}, {{"source", 1}}, {{"source", 2}}, {{"source", 3}}, {{"source", 4}}});
  f.j["materials"] = json::array(
      {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"metallicRoughnessTexture", {{"index", 1}}}}},
        {"normalTexture", {{"index", 2}, {"scale", 0.5}}},
        {"occlusionTexture", {{"index", 3}, {"strength", 0.25}}},
        {"emissiveTexture", {{"index", 4}}},
        {"emissiveFactor", {1.0, 0.5, 0.125}}}});
  place_meshes(f);
  MeshData m;
  const Status s = load_glb(f, m);
  ASSERT_TRUE(s.ok) << s.message;
  ASSERT_EQ(m.materials.size(), 1u);
  const MeshMaterial& mat = m.materials[0];
  EXPECT_EQ(mat.base_color_texture, "c.png");
  EXPECT_EQ(mat.metallic_roughness_texture, "mr.png");
  EXPECT_EQ(mat.normal_texture, "n.png");
  EXPECT_EQ(mat.occlusion_texture, "ao.png");
  EXPECT_EQ(mat.emissive_texture, "e.png");
  EXPECT_FALSE(mat.normal_texture_embedded);
  EXPECT_FLOAT_EQ(mat.normal_scale, 0.5f);
  EXPECT_FLOAT_EQ(mat.occlusion_strength, 0.25f);
  EXPECT_FLOAT_EQ(mat.emissive[0], 1.0f);
  EXPECT_FLOAT_EQ(mat.emissive[1], 0.5f);
  EXPECT_FLOAT_EQ(mat.emissive[2], 0.125f);
}

TEST(GltfImport, ATextureReadThroughTexcoord1IsKeptWithItsSet) {
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  f.j["meshes"][0]["primitives"][0]["material"] = 0;
  f.j["images"] = json::array({{{"uri", "n.png"}}});
  f.j["textures"] = json::array({{{"source", 0}}});
  f.j["materials"] = json::array({{{"normalTexture", {{"index", 0}, {"texCoord", 1}}},
                                   {"occlusionTexture", {{"index", 0}, {"texCoord", 2}}}}});
  place_meshes(f);
  MeshData m;
  const Status s = load_glb(f, m);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(m.materials[0].normal_texture, "n.png");
  EXPECT_EQ(m.materials[0].tex_coords[2], 1);  // normal slot
  // TEXCOORD_2 and beyond are not imported: that texture is left out, and said.
  EXPECT_TRUE(m.materials[0].occlusion_texture.empty());
  EXPECT_TRUE(has_warning(m, "t.glb: material 0: occlusionTexture reads TEXCOORD_2")) << (m.warnings.empty() ? "" : m.warnings[0]);
}

// ---- COLOR_0 and TEXCOORD_1 -------------------------------------------------------------------

// A triangle with COLOR_0 given by `color` (an accessor of 3 elements) and TEXCOORD_1 by `uv1`
// (-1 = none).
void add_attribute_triangle(GltfFixture& f, int color, int uv1) {
  const int pos = f.add_accessor(f.add_view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}), kFloat, 3, "VEC3");
  json attributes = {{"POSITION", pos}};
  if (color >= 0) attributes["COLOR_0"] = color;
  if (uv1 >= 0) attributes["TEXCOORD_1"] = uv1;
  f.add_mesh({{{"attributes", attributes}}});
}

TEST(GltfImport, DecodesColour0InEveryComponentTypeAsLinearRgba) {
  // Expected RGBA of the three vertices: (1, 0, 0.5, a), (0, 1, 0, a), (0.2, 0.4, 1, a) with
  // a = 1 for VEC3 and (1, 0.5, 0) for VEC4 (normalized values at their exact quotients).
  struct Case {
    const char* what;
    int type;
    bool vec4;
  };
  for (const Case c : {Case{"float VEC3", kFloat, false}, Case{"float VEC4", kFloat, true},
                       Case{"unorm8 VEC3", kUByte, false}, Case{"unorm8 VEC4", kUByte, true},
                       Case{"unorm16 VEC3", kUShort, false}, Case{"unorm16 VEC4", kUShort, true}}) {
    SCOPED_TRACE(c.what);
    const std::vector<double> rgb = {1, 0, 0.5, 0, 1, 0, 0.2, 0.4, 1}, alpha = {1, 0.5, 0};
    std::vector<double> values;
    for (int v = 0; v < 3; ++v) {
      values.insert(values.end(), rgb.begin() + 3 * v, rgb.begin() + 3 * v + 3);
      if (c.vec4) values.push_back(alpha[size_t(v)]);
    }
    GltfFixture f;
    int view;
    const double scale = c.type == kUByte ? 255 : 65535;
    if (c.type == kFloat) {
      view = f.add_view(std::vector<float>(values.begin(), values.end()));
    } else if (c.type == kUByte) {
      std::vector<uint8_t> q;
      for (int v = 0; v < 3; ++v) {
        for (int k = 0; k < (c.vec4 ? 4 : 3); ++k) q.push_back(uint8_t(std::lround(values[size_t(v * (c.vec4 ? 4 : 3) + k)] * scale)));
        if (!c.vec4) q.push_back(0);  // elements padded to 4 bytes
      }
      view = f.add_view(q.data(), q.size(), 4);
    } else {
      std::vector<uint16_t> q;
      for (int v = 0; v < 3; ++v) {
        for (int k = 0; k < (c.vec4 ? 4 : 3); ++k) q.push_back(uint16_t(std::lround(values[size_t(v * (c.vec4 ? 4 : 3) + k)] * scale)));
        if (!c.vec4) q.push_back(0);  // elements padded to 8 bytes
      }
      view = f.add_view(q.data(), 2 * q.size(), c.vec4 ? 0 : 8);
    }
    const int color = f.add_accessor(view, c.type, 3, c.vec4 ? "VEC4" : "VEC3", c.type != kFloat);
    add_attribute_triangle(f, color, -1);
    place_meshes(f);
    MeshData m;
    const Status s = load_glb(f, m);
    ASSERT_TRUE(s.ok) << s.message;
    ASSERT_EQ(m.colors.size(), 12u);
    const double tolerance = c.type == kFloat ? 1e-7 : 0.5 / scale + 1e-7;
    for (int v = 0; v < 3; ++v) {
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(m.colors[size_t(4 * v + k)], rgb[size_t(3 * v + k)], tolerance) << v << " " << k;
      EXPECT_NEAR(m.colors[size_t(4 * v + 3)], c.vec4 ? alpha[size_t(v)] : 1.0, tolerance) << v;
    }
  }
}

TEST(GltfImport, DecodesTexcoord1InEveryComponentType) {
  struct Case {
    const char* what;
    int type;
    bool normalized;
  };
  for (const Case c : {Case{"float", kFloat, false}, Case{"unorm8", kUByte, true}, Case{"unorm16", kUShort, true},
                       Case{"snorm8", kByte, true}, Case{"snorm16", kShort, true}, Case{"uint8 (quantized)", kUByte, false},
                       Case{"int16 (quantized)", kShort, false}}) {
    SCOPED_TRACE(c.what);
    GltfFixture f;
    // uvs (0, 0), (1, 0), (0, 1) in the type's units; each element padded to 4 bytes.
    const double one = !c.normalized ? 1 : c.type == kUByte ? 255 : c.type == kUShort ? 65535 : c.type == kByte ? 127 : 32767;
    const std::vector<double> uv = {0, 0, 1, 0, 0, 1};
    int view;
    if (c.type == kFloat) {
      view = f.add_view(std::vector<float>{0, 0, 1, 0, 0, 1});
    } else if (c.type == kUByte || c.type == kByte) {
      std::vector<uint8_t> q;
      for (int v = 0; v < 3; ++v) q.insert(q.end(), {uint8_t(uv[size_t(2 * v)] * one), uint8_t(uv[size_t(2 * v + 1)] * one), 0, 0});
      view = f.add_view(q.data(), q.size(), 4);
    } else {
      std::vector<uint16_t> q;
      for (double x : uv) q.push_back(uint16_t(x * one));
      view = f.add_view(q);
    }
    const int tex1 = f.add_accessor(view, c.type, 3, "VEC2", c.normalized);
    add_attribute_triangle(f, -1, tex1);
    place_meshes(f);
    MeshData m;
    const Status s = load_glb(f, m);
    ASSERT_TRUE(s.ok) << s.message;
    EXPECT_TRUE(m.uvs.empty());
    ASSERT_EQ(m.uvs1.size(), 6u);
    for (size_t i = 0; i < 6; ++i) EXPECT_FLOAT_EQ(m.uvs1[i], float(uv[i])) << i;
  }
}

TEST(GltfImport, PrimitivesWithoutColoursOrTexcoord1GetDefaultsAndSaySo) {
  GltfFixture f;
  const int color = f.add_accessor(f.add_view(std::vector<float>{0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f}),
                                   kFloat, 3, "VEC3");
  const int tex1 = f.add_accessor(f.add_view(std::vector<float>{0.25f, 0.75f, 0.25f, 0.75f, 0.25f, 0.75f}), kFloat, 3, "VEC2");
  add_attribute_triangle(f, color, tex1);
  add_attribute_triangle(f, -1, -1);
  place_meshes(f);
  MeshData m;
  const Status s = load_glb(f, m);
  ASSERT_TRUE(s.ok) << s.message;
  ASSERT_EQ(m.vertex_count(), 6u);
  ASSERT_EQ(m.colors.size(), 24u);
  ASSERT_EQ(m.uvs1.size(), 12u);
  EXPECT_FLOAT_EQ(m.colors[0], 0.5f);
  EXPECT_FLOAT_EQ(m.colors[3], 1.0f);  // RGB: alpha 1
  for (size_t i = 12; i < 24; ++i) EXPECT_FLOAT_EQ(m.colors[i], 1.0f) << i;  // white
  EXPECT_FLOAT_EQ(m.uvs1[1], 0.75f);
  for (size_t i = 6; i < 12; ++i) EXPECT_FLOAT_EQ(m.uvs1[i], 0.0f) << i;
  EXPECT_TRUE(has_warning(m, "mesh 1 primitive 0 has no COLOR_0; its vertices get white"));
  EXPECT_TRUE(has_warning(m, "mesh 1 primitive 0 has no TEXCOORD_1; its vertices get (0, 0)"));
}

TEST(GltfMalformed, RefusesColourComponentTypesTheSpecForbids) {
  struct Case {
    int type;
    bool normalized;
    const char* type_name;
  };
  for (const Case c : {Case{kUByte, false, "VEC4"}, Case{kByte, true, "VEC4"}, Case{kShort, true, "VEC4"},
                       Case{kUInt, false, "VEC4"}, Case{kFloat, false, "VEC2"}}) {
    GltfFixture f;
    const std::vector<uint32_t> raw(12, 0);
    const int color = f.add_accessor(f.add_view(raw), c.type, 3, c.type_name, c.normalized);
    add_attribute_triangle(f, color, -1);
    place_meshes(f);
    MeshData m;
    const Status s = load_glb(f, m);
    EXPECT_FALSE(s.ok) << c.type << " " << c.type_name;
    EXPECT_NE(s.message.find("t.glb: mesh 0 primitive 0: COLOR accessor"), std::string::npos) << s.message;
  }
}

TEST(GltfMalformed, RefusesNonFiniteColoursAndTexcoord1) {
  {
    GltfFixture f;
    const int color = f.add_accessor(f.add_view(std::vector<float>{1, 1, 1, 1, std::nanf(""), 1, 1, 1, 1}), kFloat, 3, "VEC3");
    add_attribute_triangle(f, color, -1);
    place_meshes(f);
    MeshData m;
    expect_refused(load_glb(f, m), "t.glb: mesh 0 primitive 0: vertex 1 has a non-finite COLOR_0");
  }
  {
    GltfFixture f;
    const int tex1 = f.add_accessor(f.add_view(std::vector<float>{0, 0, 1, 0, 0, INFINITY}), kFloat, 3, "VEC2");
    add_attribute_triangle(f, -1, tex1);
    place_meshes(f);
    MeshData m;
    expect_refused(load_glb(f, m), "t.glb: mesh 0 primitive 0: vertex 2 has a non-finite TEXCOORD_1");
  }
}

TEST(GltfImport, AppliesTheBaseColourTextureTransformToTexcoords) {
  GltfFixture f;
  const int pos = f.add_accessor(f.add_view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}), kFloat, 3, "VEC3");
  const int tex = f.add_accessor(f.add_view(std::vector<float>{0, 0, 1, 0, 1, 1}), kFloat, 3, "VEC2");
  f.add_mesh({{{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", tex}}}, {"material", 0}}});
  f.j["images"] = json::array({{{"uri", "a.png"}}});
  f.j["textures"] = json::array({{{"source", 0}}});
  f.j["materials"] = json::array({{{"pbrMetallicRoughness",
                                    {{"baseColorTexture",
                                      {{"index", 0},
                                       {"extensions", {{"KHR_texture_transform", {{"offset", {0.5, 0.25}}, {"scale", {2, 4}}}}}}}}}}}});
  f.j["extensionsUsed"] = {"KHR_texture_transform"};
  f.j["extensionsRequired"] = {"KHR_texture_transform"};
  place_meshes(f);
  MeshData m;
  const Status s = load_glb(f, m);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(m.uvs, (std::vector<float>{0.5f, 0.25f, 2.5f, 0.25f, 2.5f, 4.25f}));
  EXPECT_FALSE(has_warning(m, "KHR_texture_transform"));
}

// Each uv set takes the transform of the first texture reading it: the occlusion texture's on
// TEXCOORD_1 (its texCoord given by the extension, which overrides the texture info's), the base
// colour's on TEXCOORD_0; an emissive texture on TEXCOORD_0 with another transform is said.
TEST(GltfImport, AppliesEachUvSetsTextureTransformAndSaysWhereTwoDisagree) {
  GltfFixture f;
  const int pos = f.add_accessor(f.add_view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}), kFloat, 3, "VEC3");
  const int tex0 = f.add_accessor(f.add_view(std::vector<float>{0, 0, 1, 0, 1, 1}), kFloat, 3, "VEC2");
  const int tex1 = f.add_accessor(f.add_view(std::vector<float>{0, 0, 1, 0, 0, 1}), kFloat, 3, "VEC2");
  f.add_mesh({{{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", tex0}, {"TEXCOORD_1", tex1}}}, {"material", 0}}});
  f.j["images"] = json::array({{{"uri", "a.png"}}});
  f.j["textures"] = json::array({{{"source", 0}}});
  auto transform = [](json t) { return json{{"KHR_texture_transform", t}}; };
  f.j["materials"] = json::array(
      {{{"pbrMetallicRoughness",
         {{"baseColorTexture", {{"index", 0}, {"extensions", transform({{"offset", {0.5, 0}}})}}}}},
        {"occlusionTexture", {{"index", 0}, {"extensions", transform({{"scale", {2, 3}}, {"texCoord", 1}})}}},
        {"emissiveTexture", {{"index", 0}, {"extensions", transform({{"offset", {0, 0.5}}})}}}}});
  f.j["extensionsUsed"] = {"KHR_texture_transform"};
  place_meshes(f);
  MeshData m;
  const Status s = load_glb(f, m);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(m.uvs, (std::vector<float>{0.5f, 0, 1.5f, 0, 1.5f, 1}));
  EXPECT_EQ(m.uvs1, (std::vector<float>{0, 0, 2, 0, 0, 3}));
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].tex_coords[3], 1);  // occlusion, through the extension's texCoord
  EXPECT_TRUE(has_warning(m, "t.glb: material 0: emissiveTexture has another KHR_texture_transform than "
                             "baseColorTexture on TEXCOORD_0"));
}

// Images inside the file are kept undecoded, once each however many slots name them: a PNG in a
// buffer view, a JPEG in a data URI; one that is neither is left out, said naming the file,
// material and slot; the slots name the kept ones "embedded:<k>".
TEST(GltfImport, KeepsEmbeddedPngAndJpegBytesOnceEachAndDropsOtherImagesSayingWhere) {
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  f.j["meshes"][0]["primitives"][0]["material"] = 0;
  const std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a, 1, 2, 3};
  const std::vector<uint8_t> jpeg = {0xff, 0xd8, 0xff, 0xe0, 9, 9};
  const std::vector<uint8_t> bmp = {'B', 'M', 0, 0, 0, 0};
  const int png_view = f.add_view(png), bmp_view = f.add_view(bmp);
  f.j["images"] = json::array({{{"bufferView", png_view}, {"mimeType", "image/png"}},
                               {{"uri", "data:image/jpeg;base64," + GltfFixture::base64(jpeg)}},
                               {{"bufferView", bmp_view}, {"mimeType", "image/png"}}});
  f.j["textures"] = json::array({{{"source", 0}}, {{"source", 1}}, {{"source", 2}}});
  f.j["materials"] = json::array(
      {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 1}}}, {"metallicRoughnessTexture", {{"index", 0}}}}},
        {"normalTexture", {{"index", 2}}},
        {"emissiveTexture", {{"index", 1}}}}});
  place_meshes(f);
  MeshData m;
  const Status s = load_glb(f, m);
  ASSERT_TRUE(s.ok) << s.message;
  ASSERT_EQ(m.images.size(), 2u) << "the JPEG once for two slots, the PNG, not the BMP";
  const MeshMaterial& mat = m.materials[0];
  EXPECT_EQ(mat.base_color_texture, "embedded:0");
  EXPECT_EQ(mat.emissive_texture, "embedded:0");
  EXPECT_EQ(m.images[0].type, ImageType::jpeg);
  EXPECT_EQ(m.images[0].bytes, jpeg);
  EXPECT_EQ(mat.metallic_roughness_texture, "embedded:1");
  EXPECT_EQ(m.images[1].bytes, png);
  EXPECT_TRUE(mat.normal_texture_embedded);
  EXPECT_TRUE(mat.normal_texture.empty());
  EXPECT_TRUE(has_warning(m, "t.glb: material 0: normalTexture: embedded image 2 is neither PNG nor JPEG (its first bytes "
                             "are 42 4d 00 00"))
      << (m.warnings.empty() ? "" : m.warnings.back());
}

// An image's buffer view past its buffer refuses the whole file (nothing half-imported).
TEST(GltfImport, RefusesAnEmbeddedImageWhoseBufferViewRunsPastTheBuffer) {
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  f.j["meshes"][0]["primitives"][0]["material"] = 0;
  const std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
  const int view = f.add_view(png);
  f.j["bufferViews"][view]["byteLength"] = 4096;
  f.j["images"] = json::array({{{"bufferView", view}, {"mimeType", "image/png"}}});
  f.j["textures"] = json::array({{{"source", 0}}});
  f.j["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}});
  place_meshes(f);
  MeshData m;
  m.source = "untouched";
  expect_refused(load_glb(f, m), "t.glb: buffer view 2 (bytes 72 + 4096) runs past the end of buffer 0");
  EXPECT_EQ(m.source, "untouched");
}

// ../shared's spot.obj with its texture, converted at test time by Debian's gltfpack: once
// quantized (KHR_mesh_quantization, UVs through KHR_texture_transform, texture embedded in
// the GLB) and once not (.gltf + .bin, texture by URI). Both give the OBJ's triangles, bounds
// and the same UV range.
TEST(GltfShared, ImportsSpotConvertedByGltfpackWithItsTexture) {
  LOD_REQUIRE_SHARED_MESH(obj, "spot.obj");
  const fs::path texture = test::shared_meshes() / "spot_texture.png";
  if (!fs::exists(texture)) GTEST_SKIP() << "needs ../shared/data/meshes/spot_texture.png (absent on this machine)";
  ASSERT_EQ(std::system("command -v gltfpack >/dev/null 2>&1"), 0) << "gltfpack missing: run scripts/install-deps.sh";
  const fs::path dir = test::temp_dir("gltf-spot");
  const std::vector<uint8_t> original = test::read_bytes(obj);
  std::vector<uint8_t> with_material;
  for (char c : std::string("mtllib spot.mtl\nusemtl spot\n")) with_material.push_back(uint8_t(c));
  with_material.insert(with_material.end(), original.begin(), original.end());
  test::write_bytes(dir / "spot.obj", with_material);
  test::write_text(dir / "spot.mtl", "newmtl spot\nKd 1 1 1\nmap_Kd spot_texture.png\n");
  fs::copy_file(texture, dir / "spot_texture.png");
  const std::string in = " -i " + (dir / "spot.obj").string();
  ASSERT_EQ(std::system(("gltfpack" + in + " -o " + (dir / "spot.glb").string() + " >/dev/null 2>&1").c_str()), 0);
  ASSERT_EQ(std::system(("gltfpack -noq" + in + " -o " + (dir / "spot-noq.gltf").string() + " >/dev/null 2>&1").c_str()), 0);

  MeshData reference, packed, plain;
  ASSERT_TRUE(load_mesh(obj, reference).ok);
  Status s = load_mesh(dir / "spot.glb", packed);
  ASSERT_TRUE(s.ok) << s.message;
  s = load_mesh(dir / "spot-noq.gltf", plain);
  ASSERT_TRUE(s.ok) << s.message;
  auto range = [](const std::vector<float>& v, size_t stride, size_t c) {
    float lo = 1e30f, hi = -1e30f;
    for (size_t i = c; i < v.size(); i += stride) lo = std::min(lo, v[i]), hi = std::max(hi, v[i]);
    return std::pair{lo, hi};
  };
  for (const MeshData* m : {&packed, &plain}) {
    EXPECT_EQ(m->triangle_count(), reference.triangle_count());
    EXPECT_EQ(m->uvs.size(), 2 * m->vertex_count());
    EXPECT_TRUE(m->normals.empty());  // spot.obj has no vn lines
    ASSERT_EQ(m->materials.size(), 1u);
    for (size_t c = 0; c < 3; ++c) {  // 16-bit positions: within 1e-3 of the OBJ's box
      EXPECT_NEAR(range(m->positions, 3, c).first, range(reference.positions, 3, c).first, 1e-3);
      EXPECT_NEAR(range(m->positions, 3, c).second, range(reference.positions, 3, c).second, 1e-3);
    }
    for (size_t c = 0; c < 2; ++c) {
      EXPECT_NEAR(range(m->uvs, 2, c).first, range(plain.uvs, 2, c).first, 2e-3);
      EXPECT_NEAR(range(m->uvs, 2, c).second, range(plain.uvs, 2, c).second, 2e-3);
    }
  }
  EXPECT_TRUE(packed.materials[0].base_color_texture_embedded);
  EXPECT_EQ(plain.materials[0].base_color_texture, "spot_texture.png");
  EXPECT_GT(range(plain.uvs, 2, 0).second - range(plain.uvs, 2, 0).first, 0.5f);  // spans the texture
}

// ---- skipped content ----------------------------------------------------------------------------

TEST(GltfImport, SkipsLinesPointsMorphTargetsAndSkinsWithWarnings) {
  GltfFixture f;
  const int pos = f.add_accessor(f.add_view(kQuad), kFloat, 4, "VEC3");
  f.add_mesh({{{"attributes", {{"POSITION", pos}}}, {"mode", 1}},
              {{"attributes", {{"POSITION", pos}}}, {"mode", 0}},
              {{"attributes", {{"POSITION", pos}}}, {"mode", 6}, {"targets", {{{"POSITION", pos}}}}}});
  f.j["skins"] = json::array({{{"joints", {1}}}});
  f.add_node({{"mesh", 0}, {"skin", 0}});
  f.add_node(json::object());
  f.set_scene({0});
  MeshData m;
  const Status s = load_glb(f, m, "scene.glb");
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(m.triangle_count(), 2u);
  EXPECT_TRUE(has_warning(m, "scene.glb: mesh 0 primitive 0: mode LINES is not a triangle mode"));
  EXPECT_TRUE(has_warning(m, "mesh 0 primitive 1: mode POINTS"));
  EXPECT_TRUE(has_warning(m, "morph targets not applied"));
  EXPECT_TRUE(has_warning(m, "node 0: skin 0 is not applied"));
}

TEST(GltfImport, ManySkippedPrimitivesGiveAFewWarningLines) {
  GltfFixture f;
  const int pos = f.add_accessor(f.add_view(kQuad), kFloat, 4, "VEC3");
  std::vector<json> prims(40, json{{"attributes", {{"POSITION", pos}}}, {"mode", 3}});
  prims.push_back({{"attributes", {{"POSITION", pos}}}, {"mode", 6}});
  f.add_mesh(prims);
  place_meshes(f);
  MeshData m;
  ASSERT_TRUE(load_glb(f, m).ok);
  ASSERT_EQ(m.warnings.size(), 17u);
  EXPECT_EQ(m.warnings.back(), "... and 24 more warnings like these");
  EXPECT_EQ(m.triangle_count(), 2u);
}

TEST(GltfImport, RefusesAFileWithOnlyLines) {
  GltfFixture f;
  f.add_float_mesh(kQuad, {}, 1);
  place_meshes(f);
  MeshData m;
  const Status s = load_glb(f, m, "lines.glb");
  expect_refused(s, "lines.glb: no triangle primitives");
  expect_refused(s, "mode LINES is not a triangle mode");
}

// ---- malformed files -----------------------------------------------------------

TEST(GltfMalformed, RefusesRequiredDracoAndMeshopt) {
  for (const char* ext : {"KHR_draco_mesh_compression", "EXT_meshopt_compression"}) {
    GltfFixture f;
    f.add_float_mesh(kQuad, kQuadIndices);
    place_meshes(f);
    f.j["extensionsUsed"] = {ext};
    f.j["extensionsRequired"] = {ext};
    MeshData m;
    expect_refused(load_glb(f, m), std::string("t.glb: requires ") + ext);
  }
}

TEST(GltfMalformed, RefusesSparseAccessors) {
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  place_meshes(f);
  const int iv = f.add_view(std::vector<uint16_t>{1, 0});
  const int vv = f.add_view(std::vector<float>{5, 5, 5});
  f.j["accessors"][0]["sparse"] = {{"count", 1},
                                   {"indices", {{"bufferView", iv}, {"componentType", kUShort}}},
                                   {"values", {{"bufferView", vv}}}};
  MeshData m;
  expect_refused(load_glb(f, m), "mesh 0 primitive 0: POSITION accessor 0: sparse accessors are not supported");
}

TEST(GltfMalformed, RefusesAnAccessorPastItsBufferView) {
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  place_meshes(f);
  f.j["accessors"][0]["count"] = 5;  // 5 x 12 bytes in a 48-byte view
  MeshData m;
  expect_refused(load_glb(f, m), "POSITION accessor 0: 5 elements of 12 bytes");
  f.j["accessors"][0]["count"] = 4;
  f.j["accessors"][0]["byteOffset"] = 4;
  expect_refused(load_glb(f, m), "do not fit in buffer view 0");
}

TEST(GltfMalformed, RefusesABufferViewPastItsBuffer) {
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  place_meshes(f);
  f.j["bufferViews"][1]["byteLength"] = 4096;
  MeshData m;
  // tinygltf or our check: either way the message names the file.
  const Status s = load_glb(f, m);
  expect_refused(s, "t.glb: buffer view 1");
  expect_refused(s, "runs past the end of buffer 0");
}

TEST(GltfMalformed, RefusesWrongByteStrides) {
  for (int stride : {8, 6, 256}) {
    GltfFixture f;
    f.add_float_mesh(kQuad, kQuadIndices);
    place_meshes(f);
    f.j["bufferViews"][0]["byteStride"] = stride;
    MeshData m;
    const Status s = load_glb(f, m);
    EXPECT_FALSE(s.ok) << stride;
    EXPECT_NE(s.message.find("byteStride"), std::string::npos) << s.message;
    EXPECT_NE(s.message.find(std::to_string(stride)), std::string::npos) << s.message;
  }
}

TEST(GltfMalformed, RefusesOutOfRangeIndices) {
  GltfFixture f;
  f.add_float_mesh(kQuad, {0, 1, 2, 0, 2, 4});
  place_meshes(f);
  MeshData m;
  expect_refused(load_glb(f, m), "t.glb: mesh 0 primitive 0: index 5 references vertex 4 of 4");
}

TEST(GltfMalformed, RefusesIllegalComponentTypes) {
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  place_meshes(f);
  f.j["accessors"][0]["componentType"] = kUInt;
  MeshData m;
  expect_refused(load_glb(f, m), "componentType 5125 is not allowed for POSITION");
  f.j["accessors"][0]["componentType"] = kFloat;
  f.j["accessors"][0]["normalized"] = true;
  expect_refused(load_glb(f, m), "componentType 5126 normalized is not allowed");
  f.j["accessors"][0]["normalized"] = false;
  f.j["accessors"][1]["componentType"] = kFloat;
  expect_refused(load_glb(f, m), "componentType 5126 is not allowed for indices");
  f.j["accessors"][1]["componentType"] = kUInt;
  f.j["accessors"][0]["type"] = "VEC2";
  expect_refused(load_glb(f, m), "(expected VEC3)");
}

TEST(GltfMalformed, RefusesHugeDeclaredCountsWithoutAllocating) {
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  place_meshes(f);
  f.j["accessors"][1]["count"] = uint64_t(1) << 62;
  MeshData m;
  expect_refused(load_glb(f, m), "indices accessor 1: 4611686018427387904 elements");
  // An accessor without a buffer view reads as zeros: its count is still bounded.
  f.j["accessors"][1]["count"] = 6;
  f.j["accessors"][0].erase("bufferView");
  f.j["accessors"][0]["count"] = uint64_t(1) << 40;
  expect_refused(load_glb(f, m), "1099511627776 vertices do not fit 32-bit indices");
}

TEST(GltfMalformed, RefusesInstancingThatFlattensFarBeyondTheFile) {
  GltfFixture f;
  std::vector<float> grid;
  std::vector<uint32_t> tris;
  for (uint32_t i = 0; i < 3000; ++i) {
    grid.insert(grid.end(), {float(i), 0, 0, float(i), 1, 0, float(i) + 1, 0, 0});
    tris.insert(tris.end(), {3 * i, 3 * i + 1, 3 * i + 2});
  }
  f.add_float_mesh(grid, tris);
  // A mesh of ~50 KB used by 20,000 nodes: ~1.4 GB flattened.
  std::vector<int> roots;
  for (int n = 0; n < 20000; ++n) roots.push_back(f.add_node({{"mesh", 0}}));
  f.set_scene(roots);
  MeshData m;
  expect_refused(load_glb(f, m), "refusing more than 256 times its size");
}

TEST(GltfMalformed, RefusesNodeCyclesAndBadReferences) {
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  f.add_node({{"mesh", 0}, {"children", {1}}});
  f.add_node({{"children", {0}}});
  f.set_scene({0});
  MeshData m;
  expect_refused(load_glb(f, m), "node 0 is reached twice");
  f.j["nodes"][1]["children"] = {7};
  expect_refused(load_glb(f, m), "references node 7 of 2");
  f.j["nodes"][1].erase("children");
  f.j["nodes"][0]["mesh"] = 3;
  expect_refused(load_glb(f, m), "node 0 references mesh 3 of 1");
}

TEST(GltfMalformed, RefusesMismatchedAttributeCountsAndMissingPosition) {
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  place_meshes(f);
  const int nrm = f.add_accessor(f.add_view(std::vector<float>{0, 0, 1, 0, 0, 1}), kFloat, 2, "VEC3");
  f.j["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = nrm;
  MeshData m;
  expect_refused(load_glb(f, m), "NORMAL has 2 elements, POSITION 4");
  f.j["meshes"][0]["primitives"][0]["attributes"].erase("POSITION");
  expect_refused(load_glb(f, m), "has no POSITION attribute");
}

TEST(GltfMalformed, RefusesNonFinitePositions) {
  GltfFixture f;
  f.add_float_mesh({0, 0, 0, 1, 0, 0, 0, std::nanf(""), 0});
  place_meshes(f);
  MeshData m;
  expect_refused(load_glb(f, m), "vertex 2 has a non-finite position (nan)");
}

TEST(GltfMalformed, RefusesAMissingImage) {
  const fs::path dir = test::temp_dir("gltf-missing-image");
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  place_meshes(f);
  f.j["images"] = json::array({{{"uri", "gone.png"}}});
  const fs::path file = f.write_gltf_with_bin(dir, "m");
  MeshData m;
  expect_refused(load_mesh(file, m), "image 0 'gone.png' not found");
}

TEST(GltfMalformed, RefusesABadTextureReference) {
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  place_meshes(f);
  f.j["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 4}}}}}}});
  MeshData m;
  expect_refused(load_glb(f, m), "material 0: baseColorTexture references texture 4 of 0");
}

TEST(GltfMalformed, RefusesAnOutOfRangeTextureInEverySlot) {
  const std::vector<std::pair<json, std::string>> cases = {
      {{{"normalTexture", {{"index", 3}}}}, "t.glb: material 0: normalTexture references texture 3 of 1"},
      {{{"occlusionTexture", {{"index", 9}}}}, "t.glb: material 0: occlusionTexture references texture 9 of 1"},
      {{{"emissiveTexture", {{"index", 1}}}}, "t.glb: material 0: emissiveTexture references texture 1 of 1"},
      {{{"pbrMetallicRoughness", {{"metallicRoughnessTexture", {{"index", 2}}}}}},
       "t.glb: material 0: metallicRoughnessTexture references texture 2 of 1"},
  };
  for (const auto& [material, expect] : cases) {
    GltfFixture f;
    f.add_float_mesh(kQuad, kQuadIndices);
    place_meshes(f);
    f.j["images"] = json::array({{{"uri", "a.png"}}});
    f.j["textures"] = json::array({{{"source", 0}}});
    f.j["materials"] = json::array({material});
    MeshData m;
    expect_refused(load_glb(f, m), expect);
  }
  // A texture naming an image that does not exist, in the normal slot.
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  place_meshes(f);
  f.j["textures"] = json::array({{{"source", 4}}});
  f.j["materials"] = json::array({{{"normalTexture", {{"index", 0}}}}});
  MeshData m;
  expect_refused(load_glb(f, m), "t.glb: material 0: normalTexture: texture 0 references image 4 of 0");
}

TEST(GltfMalformed, RefusesTruncatedGlbAtEveryLength) {
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  place_meshes(f);
  const std::vector<uint8_t> glb = f.glb();
  for (size_t n = 1; n < glb.size(); ++n) {
    // A fresh copy of exactly n bytes, so a read past the end is an ASan finding.
    std::vector<uint8_t> cut(glb.begin(), glb.begin() + std::ptrdiff_t(n));
    MeshData m;
    const Status s = load_mesh_from_memory("cut.glb", ".glb", cut.data(), cut.size(), m);
    ASSERT_FALSE(s.ok) << n;
    ASSERT_NE(s.message.find("cut.glb"), std::string::npos) << s.message;
  }
}

TEST(GltfMalformed, RefusesBadGlbChunks) {
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  place_meshes(f);
  const std::vector<uint8_t> glb = f.glb();
  MeshData m;
  auto load = [&](std::vector<uint8_t> b) { return load_mesh_from_memory("c.glb", ".glb", b.data(), b.size(), m); };
  auto with_u32 = [&](size_t at, uint32_t v) {
    std::vector<uint8_t> b = glb;
    std::memcpy(&b[at], &v, 4);
    return b;
  };
  uint32_t json_length;
  std::memcpy(&json_length, &glb[12], 4);
  expect_refused(load(with_u32(4, 1)), "GLB version 1");
  expect_refused(load(with_u32(8, uint32_t(glb.size() + 4))), "truncated GLB: the header declares");
  expect_refused(load(with_u32(12, uint32_t(glb.size()))), "JSON chunk of");
  expect_refused(load(with_u32(20 + json_length, 1u << 20)), "BIN chunk of 1048576 bytes runs past");
  expect_refused(load(with_u32(24 + json_length, 0x12345678)), "chunk 1 is not a BIN chunk");
  expect_refused(load(with_u32(16, 0)), "chunk 0 is not the JSON chunk");
  std::vector<uint8_t> text(glb.begin() + 20, glb.begin() + 20 + json_length);
  expect_refused(load(text), "not a GLB file");
}

TEST(GltfMalformed, RefusesBrokenJsonNamingTheFile) {
  MeshData m;
  expect_refused(load_gltf_text("{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [", m), "t.gltf: not valid glTF");
  expect_refused(load_gltf_text("[1, 2]", m), "t.gltf");
  expect_refused(load_gltf_text("{\"meshes\": []}", m), "t.gltf");
}

// Thousands of small corruptions of a valid GLB: each is refused or loads a consistent mesh.
TEST(GltfMalformed, SurvivesRandomByteCorruption) {
  GltfFixture f;
  f.add_float_mesh(kQuad, kQuadIndices);
  const int nrm = f.add_accessor(f.add_view(std::vector<float>(12, 0.5f)), kFloat, 4, "VEC3");
  f.j["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = nrm;
  place_meshes(f);
  const std::vector<uint8_t> glb = f.glb();
  uint32_t seed = 12345;
  auto next = [&seed] { return seed = seed * 1664525u + 1013904223u; };
  size_t loaded = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::vector<uint8_t> b = glb;
    for (int k = 0; k < 1 + trial % 4; ++k) b[next() % b.size()] = uint8_t(next() >> 24);
    MeshData m;
    const Status s = load_mesh_from_memory("x.glb", ".glb", b.data(), b.size(), m);
    if (!s.ok) {
      ASSERT_NE(s.message.find("x.glb"), std::string::npos) << s.message;
      continue;
    }
    ++loaded;
    for (uint32_t i : m.indices) ASSERT_LT(i, m.vertex_count());
    for (float c : m.positions) ASSERT_TRUE(std::isfinite(c));
  }
  EXPECT_GT(loaded, 0u);  // some corruptions hit padding or values and still load
}

}  // namespace
}  // namespace lod
