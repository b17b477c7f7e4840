// Tangents for normal mapping (preprocess/tangents.h): along +u on a plain quad with w = +1,
// w = -1 where the texture is mirrored, unit and perpendicular to the normal everywhere, and a
// usable unit vector where the uvs give no direction.
#include "preprocess/tangents.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace lod {
namespace {

// Quad in the xy plane facing +z, uv origin top left (glTF): u along +x, v down (-y).
const std::vector<float> kPositions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
const std::vector<float> kNormals = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
const std::vector<float> kUvs = {0, 1, 1, 1, 1, 0, 0, 0};
const std::vector<uint32_t> kIndices = {0, 1, 2, 0, 2, 3};

void expect_unit_and_perpendicular(const std::vector<float>& t, const std::vector<float>& n) {
  for (size_t v = 0; v < t.size() / 4; ++v) {
    const double x = t[4 * v], y = t[4 * v + 1], z = t[4 * v + 2];
    EXPECT_NEAR(x * x + y * y + z * z, 1.0, 1e-6) << v;
    const double nx = n[3 * v], ny = n[3 * v + 1], nz = n[3 * v + 2];
    const double len = std::sqrt(nx * nx + ny * ny + nz * nz);
    if (len > 0) EXPECT_NEAR((x * nx + y * ny + z * nz) / len, 0.0, 1e-6) << v;
    EXPECT_TRUE(t[4 * v + 3] == 1.0f || t[4 * v + 3] == -1.0f) << v;
  }
}

TEST(Tangents, FollowUWithPositiveHandednessOnAPlainQuad) {
  std::vector<float> t(16);
  compute_tangents(t.data(), kPositions.data(), kNormals.data(), kUvs.data(), 4, kIndices.data(),
                   kIndices.size());
  for (size_t v = 0; v < 4; ++v) {
    EXPECT_NEAR(t[4 * v], 1.0f, 1e-6) << v;
    EXPECT_NEAR(t[4 * v + 1], 0.0f, 1e-6) << v;
    EXPECT_EQ(t[4 * v + 3], 1.0f) << "cross(n, t) = +y runs up the image";
  }
  expect_unit_and_perpendicular(t, kNormals);
}

TEST(Tangents, AMirroredTextureFlipsTheHandedness) {
  std::vector<float> uvs = kUvs;
  for (size_t v = 0; v < 4; ++v) uvs[2 * v + 1] = 1 - uvs[2 * v + 1];  // v up instead of down
  std::vector<float> t(16);
  compute_tangents(t.data(), kPositions.data(), kNormals.data(), uvs.data(), 4, kIndices.data(),
                   kIndices.size());
  for (size_t v = 0; v < 4; ++v) {
    EXPECT_NEAR(t[4 * v], 1.0f, 1e-6) << v;
    EXPECT_EQ(t[4 * v + 3], -1.0f) << v;
  }
}

TEST(Tangents, AreOrthogonalisedAgainstTiltedNormals) {
  std::vector<float> n = kNormals;
  n[0] = 0.5f, n[3] = -0.3f, n[7] = 0.8f, n[10] = 2.0f;  // tilted, not unit
  std::vector<float> t(16);
  compute_tangents(t.data(), kPositions.data(), n.data(), kUvs.data(), 4, kIndices.data(), kIndices.size());
  expect_unit_and_perpendicular(t, n);
}

TEST(Tangents, DegenerateUvsAndZeroNormalsStillGiveUnitTangents) {
  const std::vector<float> flat_uvs(8, 0.25f);  // every corner at one uv: no direction
  std::vector<float> n = kNormals;
  n[6] = n[7] = n[8] = 0;  // vertex 2 has no normal: taken as +z
  std::vector<float> t(16, 7.0f);
  compute_tangents(t.data(), kPositions.data(), n.data(), flat_uvs.data(), 4, kIndices.data(),
                   kIndices.size());
  std::vector<float> as_used = n;
  as_used[8] = 1;
  expect_unit_and_perpendicular(t, as_used);
  for (float x : t) EXPECT_TRUE(std::isfinite(x));
}

}  // namespace
}  // namespace lod
