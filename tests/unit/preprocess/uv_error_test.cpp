// UvErrorMeter: zero for the original itself (seams included), the shift of a slid texture in
// texels, and refusals of meshes it cannot compare.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "preprocess/uv_error.h"

namespace {

// A uv sphere whose u seam is two columns of vertices (u = 0 and u = 1 at the same positions).
struct UvSphere {
  std::vector<float> positions, uvs;
  std::vector<uint32_t> indices;
  lod::UvMeshView view() const {
    return {positions.data(), uvs.data(), positions.size() / 3, indices.data(), indices.size()};
  }
};

UvSphere uv_sphere(int rings, int segments) {
  UvSphere s;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j) {
      const double th = std::numbers::pi * i / rings, ph = 2 * std::numbers::pi * j / segments;
      s.positions.insert(s.positions.end(), {float(std::sin(th) * std::cos(ph)), float(std::cos(th)),
                                             float(std::sin(th) * std::sin(ph))});
      s.uvs.insert(s.uvs.end(), {float(j) / float(segments), float(i) / float(rings)});
    }
  auto at = [&](int i, int j) { return uint32_t(i * (segments + 1) + j); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) s.indices.insert(s.indices.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)});
  return s;
}

TEST(UvError, TheOriginalAgainstItselfIsZeroSeamsIncluded) {
  const UvSphere s = uv_sphere(24, 48);
  lod::UvErrorMeter meter;
  lod::UvErrorSettings settings;
  settings.surface_samples = 20000;
  ASSERT_TRUE(meter.set_reference(s.view(), settings, "sphere").ok);
  lod::UvError e;
  ASSERT_TRUE(meter.measure(s.view(), e).ok);
  EXPECT_GT(e.samples, 20000u);
  EXPECT_LT(e.max, 1e-2) << "the seam's vertices have two uvs: the matching one counts";
  EXPECT_LT(e.rms, 1e-3);
}

TEST(UvError, ASlidTextureMeasuresItsShiftInTexels) {
  const UvSphere s = uv_sphere(24, 48);
  UvSphere slid = s;
  for (size_t v = 0; v < slid.uvs.size(); v += 2) slid.uvs[v + 1] += 0.01f;  // v by 1 % of the texture
  lod::UvErrorMeter meter;
  lod::UvErrorSettings settings;
  settings.surface_samples = 5000;
  settings.texture_width = 2048;
  settings.texture_height = 512;
  ASSERT_TRUE(meter.set_reference(s.view(), settings, "sphere").ok);
  lod::UvError e;
  ASSERT_TRUE(meter.measure(slid.view(), e).ok);
  EXPECT_NEAR(e.mean, 5.12, 0.05);  // 0.01 of 512 texels
  EXPECT_NEAR(e.rms, 5.12, 0.05);
  EXPECT_NEAR(e.max, 5.12, 0.05);
}

TEST(UvError, RefusesMeshesItCannotCompare) {
  UvSphere s = uv_sphere(6, 8);
  lod::UvErrorMeter meter;
  lod::UvMeshView no_uvs = s.view();
  no_uvs.uvs = nullptr;
  EXPECT_FALSE(meter.set_reference(no_uvs, {}, "a").ok);
  lod::UvError e;
  EXPECT_FALSE(meter.measure(s.view(), e).ok) << "no reference yet";
  ASSERT_TRUE(meter.set_reference(s.view(), {}, "a").ok);
  s.indices[4] = 100000;
  const lod::Status bad = meter.measure(s.view(), e);
  EXPECT_FALSE(bad.ok);
  EXPECT_NE(bad.message.find("references vertex 100000"), std::string::npos) << bad.message;
  s.indices[4] = 0;
  s.uvs[3] = std::nanf("");
  EXPECT_FALSE(meter.measure(s.view(), e).ok);
}

}  // namespace
