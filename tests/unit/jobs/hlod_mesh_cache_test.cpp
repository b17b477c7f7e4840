// Regression tests of the cleaned-mesh cache entry's reader (.hmesh, jobs/hlod_mesh_cache) for
// what the `hmesh` fuzz target (tests/fuzz/hmesh_fuzz.cpp, scripts/fuzz.sh) found. The
// round-trip and refusal tests of the format stay in hlod_distributed_bake_test.cpp.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "jobs/hlod_mesh_cache.h"
#include "runtime/lod_asset.h"  // hash_bytes
#include "runtime/material_section.h"
#include "test_support.h"

namespace lod {
namespace {

constexpr uint64_t kSource = 21;

MeshData triangle() {
  MeshData m;
  m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  m.indices = {0, 1, 2};
  return m;
}

// The entry store_hlod_mesh writes for a triangle without materials, with `materials` and
// `images` put in as its sections instead (their byte counts, at 56 and 64, set to match;
// the checksum recomputed), as a forged or corrupted-then-resummed entry would hold them.
void write_with_sections(const std::filesystem::path& dir, const std::vector<uint8_t>& materials,
                         const std::vector<uint8_t>& images) {
  ASSERT_TRUE(store_hlod_mesh(dir, kSource, triangle(), 1));
  const auto path = hlod_mesh_entry_path(dir, kSource);
  std::vector<uint8_t> b = test::read_bytes(path);
  b.resize(b.size() - 8);
  b.insert(b.end(), materials.begin(), materials.end());
  b.insert(b.end(), images.begin(), images.end());
  const uint64_t m = materials.size(), g = images.size();
  std::memcpy(b.data() + 56, &m, 8);
  std::memcpy(b.data() + 64, &g, 8);
  const uint64_t sum = hash_bytes(b.data(), b.size());
  b.resize(b.size() + 8);
  std::memcpy(b.data() + b.size() - 8, &sum, 8);
  test::write_bytes(path, b);
}

std::vector<uint8_t> png_bytes() {
  return {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a, 0, 0, 0, 0x0d, 'I', 'H', 'D', 'R'};
}

// Found by the hmesh fuzz target: a materials section holding no materials (but a texture base,
// or beside images) was accepted, and the entry the writer then stored from what was read
// lost them: the reader took an entry the writer never makes.
TEST(HlodMeshCache, AMaterialsSectionWithoutMaterialsIsRefused) {
  const auto dir = test::temp_dir("hlod_mesh_cache_no_materials");
  auto refused = [&](const std::vector<uint8_t>& materials, const std::vector<uint8_t>& images, const char* expected) {
    write_with_sections(dir, materials, images);
    MeshData out;
    out.source = "untouched";
    HlodSurfaces surfaces;
    uint64_t input = 0;
    std::string why;
    EXPECT_EQ(load_hlod_mesh(dir, kSource, "forged.ply", out, input, &why, &surfaces), CacheLookup::refused) << expected;
    EXPECT_NE(why.find(hlod_mesh_entry_path(dir, kSource).string() + ": "), std::string::npos) << why;
    EXPECT_NE(why.find(expected), std::string::npos) << why;
    EXPECT_EQ(out.source, "untouched");
    EXPECT_TRUE(surfaces.texture_base.empty());
  };
  LodChain none;
  none.texture_base = "/models/ruin";
  refused(encode_material_section(none), {}, "materials section holds no materials");
  refused(encode_material_section(none), encode_image_section(std::vector<EmbeddedImage>{{ImageType::png, png_bytes()}}),
          "materials section holds no materials");

  // The section as the writer makes it (one material, no level runs) is still read.
  LodChain one;
  one.materials.resize(1);
  one.materials[0].name = "stone";
  one.texture_base = "/models/ruin";
  write_with_sections(dir, encode_material_section(one), {});
  MeshData out;
  HlodSurfaces surfaces;
  uint64_t input = 0;
  std::string why;
  ASSERT_EQ(load_hlod_mesh(dir, kSource, "forged.ply", out, input, &why, &surfaces), CacheLookup::found) << why;
  ASSERT_EQ(surfaces.materials.size(), 1u);
  EXPECT_EQ(surfaces.materials[0].name, "stone");
  EXPECT_EQ(surfaces.texture_base, "/models/ruin");
}

}  // namespace
}  // namespace lod
