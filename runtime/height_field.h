// HeightField: elevations on a regular grid of samples, the input of terrain LOD.
// Row-major: sample (x, y) is heights[y * width + x]; world position of a sample is
// (x * cell_size_x, heights * vertical_scale, y * cell_size_y), +Y up. Cells need not be square
// (a geographic grid converted to metres has shorter longitude cells away from the equator).
#pragma once
#include <cstdint>
#include <span>
#include <vector>

namespace lod {

struct HeightField {
  uint32_t width = 0;     // samples along x
  uint32_t height = 0;    // samples along y
  float cell_size_x = 1;  // metres between samples along x
  float cell_size_y = 1;
  float vertical_scale = 1;    // world height = heights[i] * vertical_scale
  std::vector<float> heights;  // width * height, all finite

  size_t sample_count() const { return size_t(width) * height; }
  float at(uint32_t x, uint32_t y) const { return heights[size_t(y) * width + x]; }
};

// No-data: samples flagged in `missing` (1 = no data, one flag per sample) get the mean of
// their valid 4-neighbours, ring by ring outwards from the valid samples (O(samples)), so holes take the
// elevation of their rim. Returns the number filled; 0 filled and nothing changed when every
// sample is missing (the caller refuses such a field).
size_t fill_missing_heights(HeightField& field, std::span<const uint8_t> missing);

// Bilinear resampling onto a square grid of `samples` x `samples` covering the same extent
// (cell sizes change so the world extent is kept): how a field of any shape becomes the
// (2^n + 1)-square grid ROAM needs. Precondition: field has >= 2 x 2 samples, samples >= 2.
HeightField resample_square(const HeightField& field, uint32_t samples);

}  // namespace lod
