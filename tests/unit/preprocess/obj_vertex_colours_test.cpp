// OBJ vertex colours ("v x y z r g b", as MeshLab, ZBrush and Open3D write them): kept as linear
// RGBA per vertex through the v/vt/vn split, 0-255 files recognised, gaps and clamps said, a
// non-finite colour refused naming file:line; w alone is not a colour.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "preprocess/mesh_io.h"
#include "test_support.h"

namespace lod {
namespace {

Status load_obj(const std::string& text, MeshData& out) {
  return load_mesh_from_memory("c.obj", ".obj",
                               reinterpret_cast<const uint8_t*>(text.data()), text.size(), out);
}

using test::has_warning;

float linear(float srgb) { return srgb <= 0.04045f ? srgb / 12.92f : std::pow((srgb + 0.055f) / 1.055f, 2.4f); }

TEST(ObjVertexColours, KeepsThemLinearPerVertexThroughTheTexcoordSplit) {
  MeshData m;
  // Vertex 2 is used with two texture coordinates: both copies keep its colour.
  const Status s = load_obj("v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0.5 0.5 0.5\nv 1 1 0 0 0 1\n"
                            "vt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\n"
                            "f 1/1 2/2 3/3\nf 2/2 4/4 3/4\n",
                            m);
  ASSERT_TRUE(s.ok) << s.message;
  ASSERT_EQ(m.vertex_count(), 5u);
  ASSERT_EQ(m.colors.size(), 4 * m.vertex_count());
  const float grey = linear(0.5f);
  const std::vector<float> want = {1, 0, 0, 1, 0, 1, 0, 1, grey, grey, grey, 1, 0, 0, 1, 1, grey, grey, grey, 1};
  for (size_t i = 0; i < want.size(); ++i) EXPECT_NEAR(m.colors[i], want[i], 1e-6f) << i;
  EXPECT_TRUE(m.warnings.empty());
}

TEST(ObjVertexColours, ReadsZeroTo255AndFillsGapsWithWhiteSayingSo) {
  MeshData m;
  const Status s = load_obj("v 0 0 0\nv 1 0 0 255 0 0\nv 0 1 0 0 255 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n", m);
  ASSERT_TRUE(s.ok) << s.message;
  ASSERT_EQ(m.colors.size(), 16u);
  EXPECT_EQ(std::vector<float>(m.colors.begin(), m.colors.begin() + 4), (std::vector<float>{1, 1, 1, 1}));
  EXPECT_EQ(std::vector<float>(m.colors.begin() + 4, m.colors.begin() + 8), (std::vector<float>{1, 0, 0, 1}));
  EXPECT_EQ(std::vector<float>(m.colors.begin() + 12, m.colors.end()), (std::vector<float>{1, 1, 1, 1}));
  EXPECT_TRUE(has_warning(m, "c.obj: vertex colours above 1: read as 0-255"));
  EXPECT_TRUE(has_warning(m, "c.obj: 2 of 4 vertices have no colour where others have one; they get white"));
}

TEST(ObjVertexColours, ClampsNegativesSayingSoAndTakesAFourthNumberAsW) {
  MeshData m;
  Status s = load_obj("v 0 0 0 -0.5 0 1\nv 1 0 0 0 0 0\nv 0 1 0 0 0 0\nf 1 2 3\n", m);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(m.colors[0], 0.0f);
  EXPECT_TRUE(has_warning(m, "c.obj: 1 vertex colour values outside 0..1 clamped"));
  MeshData w;
  s = load_obj("v 0 0 0 1\nv 1 0 0 1\nv 0 1 0 1\nf 1 2 3\n", w);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_TRUE(w.colors.empty());
}

TEST(ObjVertexColours, RefusesANonFiniteColourNamingTheLine) {
  MeshData m;
  const Status s = load_obj("v 0 0 0 0 0 0\nv 1 0 0 nan 0 0\nv 0 1 0 0 0 0\nf 1 2 3\n", m);
  ASSERT_FALSE(s.ok);
  EXPECT_NE(s.message.find("c.obj:2: vertex 1 has a non-finite colour component (nan)"), std::string::npos) << s.message;
}

// save_obj writes them back as sRGB on the 'v' lines; reading the file gives the same linear
// colours (to the 6 digits written).
TEST(ObjVertexColours, SaveObjWritesThemAndTheyReadBack) {
  const std::vector<float> positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::vector<float> colors = {0.2f, 0.4f, 0.6f, 1, 1, 0, 0, 0.5f, 0, 0.01f, 1, 1};
  const std::vector<uint32_t> indices = {0, 1, 2};
  const std::filesystem::path file = test::temp_dir("obj-colours") / "c.obj";
  ASSERT_TRUE(save_obj(file, positions.data(), nullptr, 3, indices.data(), 3, nullptr, colors.data()).ok);
  MeshData m;
  const Status s = load_mesh(file, m);
  ASSERT_TRUE(s.ok) << s.message;
  ASSERT_EQ(m.colors.size(), 12u);
  for (size_t v = 0; v < 3; ++v)
    for (size_t c = 0; c < 3; ++c) EXPECT_NEAR(m.colors[4 * v + c], colors[4 * v + c], 2e-6f) << v << " " << c;
}

}  // namespace
}  // namespace lod
