// Chunked LOD baseline (Ulrich 2002): nested errors, chunks tiling the grid, refinement by view.
#include "runtime/chunked_terrain.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lod {
namespace {

RoamTerrain terrain_of(uint32_t levels, float amplitude) {
  HeightField f;
  f.width = f.height = (1u << levels) + 1;
  f.heights.resize(f.sample_count());
  for (uint32_t y = 0; y < f.height; ++y)
    for (uint32_t x = 0; x < f.width; ++x)
      f.heights[size_t(y) * f.width + x] = amplitude * std::sin(0.3f * float(x)) * std::cos(0.2f * float(y));
  return build_roam_terrain(f);
}

View above(const RoamTerrain& t, float height) {
  const float side = float(t.size - 1);
  View v;
  v.eye = {0.5f * side, height, 0.5f * side + 0.01f};
  v.target = {0.5f * side, 0, 0.5f * side};
  v.fov_y_deg = 120;
  v.width = 640;
  v.height = 640;
  v.near_plane = 0.1f;
  v.far_plane = 100 * side + height;
  return v;
}

TEST(ChunkedTerrain, SizesMustBeAPowerOfTwoOfPatches) {
  EXPECT_TRUE(chunked_size_valid(65, 8));
  EXPECT_TRUE(chunked_size_valid(9, 8));
  EXPECT_FALSE(chunked_size_valid(65, 24));
  EXPECT_FALSE(chunked_size_valid(49, 8)) << "6 patches: not a power of two";
}

TEST(ChunkedTerrain, ErrorsNestAndLeavesAreExact) {
  const RoamTerrain t = terrain_of(6, 3);
  const ChunkedTerrain c = build_chunked_terrain(t, 8);
  ASSERT_EQ(c.nodes.size(), 1u + 4 + 16 + 64);
  for (const ChunkedTerrain::Node& n : c.nodes) {
    if (n.first_child < 0) {
      EXPECT_EQ(n.step, 1u);
      EXPECT_EQ(n.error, 0.f) << "full resolution";
      continue;
    }
    for (int k = 0; k < 4; ++k) EXPECT_GE(n.error, c.nodes[size_t(n.first_child + k)].error);
  }
  EXPECT_GT(c.nodes[0].error, 0.f);
}

TEST(ChunkedTerrain, FlatGroundIsOneChunkAndSelectedChunksTileTheGrid) {
  const RoamTerrain flat = terrain_of(6, 0);
  const ChunkedTerrain cf = build_chunked_terrain(flat, 8);
  std::vector<uint32_t> chosen;
  EXPECT_EQ(select_chunks(chosen, cf, above(flat, 5), 0.5f).chunks, 1u);

  const RoamTerrain t = terrain_of(6, 3);
  const ChunkedTerrain c = build_chunked_terrain(t, 8);
  const ChunkedSelection sel = select_chunks(chosen, c, above(t, 30), 0.5f);
  uint64_t area = 0;
  for (uint32_t i : chosen) area += uint64_t(8 * c.nodes[i].step) * (8 * c.nodes[i].step);
  EXPECT_EQ(area, 64u * 64u) << "a view that sees all of it draws a tiling";
  EXPECT_EQ(sel.triangles, uint64_t(sel.chunks) * chunk_triangles(8));
  EXPECT_EQ(sel.skirt_triangles, uint64_t(sel.chunks) * 64);
}

TEST(ChunkedTerrain, CloserOrStricterViewsDrawMoreChunks) {
  const RoamTerrain t = terrain_of(7, 4);
  const ChunkedTerrain c = build_chunked_terrain(t, 8);
  std::vector<uint32_t> chosen;
  const uint32_t far = select_chunks(chosen, c, above(t, 400), 1).chunks;
  const uint32_t near = select_chunks(chosen, c, above(t, 20), 1).chunks;
  const uint32_t strict = select_chunks(chosen, c, above(t, 400), 0.05f).chunks;
  EXPECT_LT(far, near);
  EXPECT_LT(far, strict);
}

}  // namespace
}  // namespace lod
