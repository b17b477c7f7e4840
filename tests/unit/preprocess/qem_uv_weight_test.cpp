// Texture-coordinate error in QEM's collapse cost (attribute quadrics): on a textured model,
// at the same triangle counts, weighting the uv error moves the levels' uvs less from the
// input vertices they descend from, and keeps the geometric error about where it was.
// Prints the figures: uv error (largest uv drift, texture units) and
// geometric RMS / max (object units) per level, for each weight.
#include <gtest/gtest.h>

#include <cstdio>
#include <thread>

#include "preprocess/lod_bake.h"
#include "test_support.h"
#include "textured_fixture.h"

namespace lod {
namespace {

LodChain bake_with(const std::filesystem::path& file, float weight) {
  BakeSettings settings;
  settings.ratios = {1.0f, 0.5f, 0.25f, 0.12f, 0.06f};
  settings.method = SimplifyMethod::qem;
  settings.uv_weight = weight;
  LodChain chain;
  const Status st = bake_model(file, "m", settings, chain, nullptr, nullptr);
  EXPECT_TRUE(st.ok) << st.message;
  return chain;
}

// Sum over levels 1.. of a level's figure, for a one-number comparison.
double total(const LodChain& c, double (*of)(const LodChain&, size_t)) {
  double s = 0;
  for (size_t k = 1; k < c.levels.size(); ++k) s += of(c, k);
  return s;
}

void print(const char* model, float weight, const LodChain& c) {
  for (size_t k = 0; k < c.levels.size(); ++k)
    std::printf("%s weight %.2f level %zu: %6u triangles, uv error %.4f, geometric rms %.5f max %.5f\n", model, weight, k,
                c.levels[k].triangles(), c.uv_errors[k], c.levels[k].error_rms, c.levels[k].error);
}

void compare(const char* model, const std::filesystem::path& file) {
  const LodChain plain = bake_with(file, 0), weighted = bake_with(file, kDefaultUvWeight);
  print(model, 0, plain);
  print(model, kDefaultUvWeight, weighted);
  ASSERT_EQ(plain.levels.size(), weighted.levels.size());
  for (size_t k = 1; k < plain.levels.size(); ++k)  // equal triangle counts, within 2 %
    EXPECT_NEAR(double(weighted.levels[k].triangles()), double(plain.levels[k].triangles()),
                0.02 * plain.levels[k].triangles() + 2)
        << k;
  const double uv_plain = total(plain, [](const LodChain& c, size_t k) { return double(c.uv_errors[k]); });
  const double uv_weighted = total(weighted, [](const LodChain& c, size_t k) { return double(c.uv_errors[k]); });
  const double rms_plain = total(plain, [](const LodChain& c, size_t k) { return double(c.levels[k].error_rms); });
  const double rms_weighted = total(weighted, [](const LodChain& c, size_t k) { return double(c.levels[k].error_rms); });
  std::printf("%s: uv error summed over levels %.4f -> %.4f, geometric rms %.5f -> %.5f\n", model, uv_plain, uv_weighted,
              rms_plain, rms_weighted);
  EXPECT_LT(uv_weighted, uv_plain) << "weighting the uv error moves the uvs less";
  EXPECT_LT(rms_weighted, 1.25 * rms_plain) << "at a bounded cost in geometry";
}

TEST(QemUvWeight, TheTexturedSphereKeepsItsUvsCloser) {
  const auto dir = test::temp_dir("qem-uv-weight");
  compare("sphere", test::write_two_material_gltf(dir, "globe", 40, 80));
}

TEST(QemUvWeight, SpotKeepsItsUvsCloser) {
  LOD_REQUIRE_SHARED_MESH(spot, "spot.obj");
  compare("spot", spot);
}

// Past 20,000 triangles QEM splits the mesh into halves (attribute quadrics split and merged
// with it); the output is the same whether the halves run in parallel or one after the other.
TEST(QemUvWeight, SplitHalvesGiveTheSameChainInParallel) {
  const auto dir = test::temp_dir("qem-uv-split");
  const auto file = test::write_two_material_gltf(dir, "globe", 120, 240);
  BakeSettings settings;
  settings.ratios = {1.0f, 0.5f, 0.1f};
  settings.method = SimplifyMethod::qem;
  LodChain serial, parallel;
  ASSERT_TRUE(bake_model(file, "g", settings, serial, nullptr, nullptr).ok);
  settings.parallel_for = [](size_t n, const std::function<void(size_t)>& body) {
    std::vector<std::thread> threads;
    for (size_t i = 0; i < n; ++i) threads.emplace_back(body, i);
    for (std::thread& t : threads) t.join();
  };
  ASSERT_TRUE(bake_model(file, "g", settings, parallel, nullptr, nullptr).ok);
  ASSERT_GT(serial.levels[0].triangles(), 40000u);
  EXPECT_EQ(serial.positions, parallel.positions);
  EXPECT_EQ(serial.indices, parallel.indices);
  EXPECT_EQ(serial.uvs, parallel.uvs);
  std::string why;
  EXPECT_TRUE(validate_chain(serial, &why)) << why;
  EXPECT_LT(serial.uv_errors[2], 0.25f);
}

}  // namespace
}  // namespace lod
