// PLY vertex attributes (what scanners and MeshLab write): normals nx ny nz, colours red green
// blue [alpha] of any type (sRGB, into linear RGBA), texture coordinates s t / u v / texture_u
// texture_v (origin bottom left, flipped into glTF's), in ASCII and binary files; a group
// missing a component and unknown properties are skipped and said; non-finite values refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "preprocess/mesh_io.h"
#include "test_support.h"

namespace lod {
namespace {

Status load_ply(const std::string& bytes, MeshData& out) {
  return load_mesh_from_memory("a.ply", ".ply", reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), out);
}

using test::has_warning;

float linear(float srgb) { return srgb <= 0.04045f ? srgb / 12.92f : std::pow((srgb + 0.055f) / 1.055f, 2.4f); }

const char* kAsciiHeader =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "property float nx\nproperty float ny\nproperty float nz\nproperty uchar red\nproperty uchar green\n"
    "property uchar blue\nproperty float texture_u\nproperty float texture_v\nproperty float quality\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n";

void expect_attributes(const MeshData& m) {
  ASSERT_EQ(m.vertex_count(), 3u);
  EXPECT_EQ(m.normals, (std::vector<float>{0, 0, 1, 0, 0, 1, 0, 1, 0}));
  ASSERT_EQ(m.colors.size(), 12u);
  const float want[12] = {1, 0, 0, 1, 0, linear(128 / 255.0f), 0, 1, 0, 0, 1, 1};
  for (size_t i = 0; i < 12; ++i) EXPECT_NEAR(m.colors[i], want[i], 1e-6f) << i;
  EXPECT_EQ(m.uvs, (std::vector<float>{0, 1, 1, 1, 0.25f, 0.5f}));  // v flipped
}

TEST(PlyVertexAttributes, AsciiKeepsNormalsColoursAndTexcoordsAndSaysWhatItSkips) {
  const std::string ply = std::string(kAsciiHeader) +
                          "0 0 0 0 0 1 255 0 0 0 0 7\n1 0 0 0 0 1 0 128 0 1 0 7\n0 1 0 0 1 0 0 0 255 0.25 0.5 7\n"
                          "3 0 1 2\n";
  MeshData m;
  const Status s = load_ply(ply, m);
  ASSERT_TRUE(s.ok) << s.message;
  expect_attributes(m);
  EXPECT_TRUE(has_warning(m, "a.ply: vertex properties 'quality' are not imported"));
}

TEST(PlyVertexAttributes, BinaryRowsGiveTheSame) {
  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "property float nx\nproperty float ny\nproperty float nz\nproperty uchar red\nproperty uchar green\n"
      "property uchar blue\nproperty float texture_u\nproperty float texture_v\nproperty float quality\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  auto put = [&ply](const void* p, size_t n) { ply.append(static_cast<const char*>(p), n); };
  const float rows[3][6] = {{0, 0, 0, 0, 0, 1}, {1, 0, 0, 0, 0, 1}, {0, 1, 0, 0, 1, 0}};
  const uint8_t rgb[3][3] = {{255, 0, 0}, {0, 128, 0}, {0, 0, 255}};
  const float uvq[3][3] = {{0, 0, 7}, {1, 0, 7}, {0.25f, 0.5f, 7}};
  for (int v = 0; v < 3; ++v) put(rows[v], 24), put(rgb[v], 3), put(uvq[v], 12);
  const uint8_t n = 3;
  const int32_t face[3] = {0, 1, 2};
  put(&n, 1), put(face, 12);
  MeshData m;
  const Status s = load_ply(ply, m);
  ASSERT_TRUE(s.ok) << s.message;
  expect_attributes(m);
}

TEST(PlyVertexAttributes, AnIncompleteGroupIsSkippedAndAlphaAndWideColoursRead) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "property float nx\nproperty ushort red\nproperty ushort green\nproperty ushort blue\nproperty ushort alpha\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0 1 65535 0 0 65535\n1 0 0 1 0 0 0 0\n0 1 0 1 0 0 0 32768\n3 0 1 2\n";
  MeshData m;
  const Status s = load_ply(ply, m);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_TRUE(m.normals.empty());
  EXPECT_TRUE(has_warning(m, "'nx' are not imported"));
  ASSERT_EQ(m.colors.size(), 12u);
  EXPECT_EQ(m.colors[0], 1.0f);
  EXPECT_EQ(m.colors[3], 1.0f);
  EXPECT_EQ(m.colors[7], 0.0f);
  EXPECT_NEAR(m.colors[11], 32768 / 65535.0f, 1e-6f);  // alpha stays linear
}

TEST(PlyVertexAttributes, RefusesANonFiniteNormalNamingTheVertex) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "property float nx\nproperty float ny\nproperty float nz\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 inf 1\n3 0 1 2\n";
  MeshData m;
  const Status s = load_ply(ply, m);
  ASSERT_FALSE(s.ok);
  EXPECT_NE(s.message.find("a.ply: vertex 2 has a non-finite normal (inf)"), std::string::npos) << s.message;
}

}  // namespace
}  // namespace lod
