// glTF export (preprocess/gltf_write.h): what it writes imports back exactly; the GLB layout
// (lengths, 4-byte alignment, POSITION min/max) is as the spec says; a bad mesh writes nothing.
// tests/integration/gltf_export_test.cpp runs the Khronos validator on the command's output.
#include "preprocess/gltf_write.h"

#include <gtest/gtest.h>

#include <cstring>
#include <nlohmann/json.hpp>

#include "preprocess/mesh_io.h"
#include "test_support.h"

namespace lod {
namespace {

namespace fs = std::filesystem;

// A strip of `n` quads in the xy plane: 2n + 2 vertices, with normals and uvs.
struct Strip {
  std::vector<float> positions, normals, uvs;
  std::vector<uint32_t> indices;
  explicit Strip(uint32_t n) {
    for (uint32_t i = 0; i <= n; ++i)
      for (uint32_t k = 0; k < 2; ++k) {
        positions.insert(positions.end(), {float(i), float(k), 0.5f});
        normals.insert(normals.end(), {0, 0, 2});  // not unit: the writer normalizes
        uvs.insert(uvs.end(), {float(i) / float(n), float(k)});
      }
    for (uint32_t i = 0; i < n; ++i)
      indices.insert(indices.end(), {2 * i, 2 * i + 2, 2 * i + 1, 2 * i + 1, 2 * i + 2, 2 * i + 3});
  }
  GltfMeshView view() const {
    GltfMeshView v;
    v.name = "strip";
    v.positions = positions.data();
    v.normals = normals.data();
    v.uvs = uvs.data();
    v.vertex_count = positions.size() / 3;
    v.indices = indices.data();
    v.index_count = indices.size();
    return v;
  }
};

TEST(GltfWrite, RoundTripsThroughTheImporter) {
  const fs::path dir = test::temp_dir("gltf-write");
  for (uint32_t quads : {10u, 40000u}) {  // u16 indices, then u32 (80,002 vertices)
    const Strip s(quads);
    for (const char* ext : {".glb", ".gltf"}) {
      const fs::path file = dir / ("strip" + std::to_string(quads) + ext);
      const Status w = save_gltf(file, s.view());
      ASSERT_TRUE(w.ok) << w.message;
      MeshData m;
      const Status r = load_mesh(file, m);
      ASSERT_TRUE(r.ok) << r.message;
      EXPECT_EQ(m.positions, s.positions);
      EXPECT_EQ(m.indices, s.indices);
      EXPECT_EQ(m.uvs, s.uvs);
      ASSERT_EQ(m.normals.size(), s.normals.size());
      for (size_t i = 0; i < m.normals.size(); ++i) EXPECT_FLOAT_EQ(m.normals[i], i % 3 == 2 ? 1.0f : 0.0f);
    }
  }
}

TEST(GltfWrite, GlbChunksAreAlignedAndPositionsBounded) {
  const fs::path file = test::temp_dir("gltf-layout") / "s.glb";
  const Strip s(3);
  ASSERT_TRUE(save_gltf(file, s.view()).ok);
  const std::vector<uint8_t> b = test::read_bytes(file);
  auto u32 = [&b](size_t at) {
    uint32_t v;
    std::memcpy(&v, &b[at], 4);
    return v;
  };
  ASSERT_GE(b.size(), 28u);
  EXPECT_EQ(std::memcmp(b.data(), "glTF", 4), 0);
  EXPECT_EQ(u32(4), 2u);
  EXPECT_EQ(u32(8), b.size());
  const uint32_t json_length = u32(12);
  EXPECT_EQ(json_length % 4, 0u);
  EXPECT_EQ(u32(16), 0x4E4F534Au);
  const uint32_t bin_length = u32(20 + json_length);
  EXPECT_EQ(bin_length % 4, 0u);
  EXPECT_EQ(u32(24 + json_length), 0x004E4942u);
  EXPECT_EQ(28 + json_length + bin_length, b.size());
  const auto j = nlohmann::json::parse(b.begin() + 20, b.begin() + 20 + json_length);
  const auto& pos = j["accessors"][j["meshes"][0]["primitives"][0]["attributes"]["POSITION"].get<size_t>()];
  EXPECT_EQ(pos["min"], nlohmann::json({0.0, 0.0, 0.5}));
  EXPECT_EQ(pos["max"], nlohmann::json({3.0, 1.0, 0.5}));
  EXPECT_EQ(j["buffers"][0]["byteLength"].get<uint32_t>(), bin_length);
  for (const auto& v : j["bufferViews"]) EXPECT_EQ(v["byteOffset"].get<size_t>() % 4, 0u);
}

TEST(GltfWrite, RefusesABadMeshAndWritesNothing) {
  const fs::path dir = test::temp_dir("gltf-write-bad");
  Strip s(2);
  s.indices[4] = 99;
  Status w = save_gltf(dir / "a.glb", s.view());
  EXPECT_FALSE(w.ok);
  EXPECT_NE(w.message.find("triangle 1 references vertex 99 of 6"), std::string::npos) << w.message;
  s.indices[4] = 1;
  s.positions[7] = std::nanf("");
  w = save_gltf(dir / "b.gltf", s.view());
  EXPECT_NE(w.message.find("vertex 2 has a non-finite position"), std::string::npos) << w.message;
  w = save_gltf(dir / "c.fbx", s.view());
  EXPECT_NE(w.message.find("needs a .glb or .gltf name"), std::string::npos) << w.message;
  EXPECT_TRUE(fs::is_empty(dir));
}

}  // namespace
}  // namespace lod
