#include "runtime/height_field.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace lod {
namespace detail {

// One outward sweep: every missing sample with a valid 4-neighbour takes their mean. Reads the
// validity of the previous sweep only, so a hole fills in rings from its rim inwards.
size_t fill_sweep(HeightField& f, std::vector<uint8_t>& missing, std::vector<uint8_t>& next) {
  size_t filled = 0;
  next = missing;
  for (uint32_t y = 0; y < f.height; ++y)
    for (uint32_t x = 0; x < f.width; ++x) {
      const size_t i = size_t(y) * f.width + x;
      if (!missing[i]) continue;
      float sum = 0;
      int n = 0;
      auto take = [&](uint32_t nx, uint32_t ny) {
        const size_t j = size_t(ny) * f.width + nx;
        if (!missing[j]) sum += f.heights[j], ++n;
      };
      if (x > 0) take(x - 1, y);
      if (x + 1 < f.width) take(x + 1, y);
      if (y > 0) take(x, y - 1);
      if (y + 1 < f.height) take(x, y + 1);
      if (n == 0) continue;
      f.heights[i] = sum / float(n);
      next[i] = 0;
      ++filled;
    }
  missing.swap(next);
  return filled;
}

}  // namespace detail

size_t fill_missing_heights(HeightField& field, std::span<const uint8_t> missing) {
  assert(missing.size() == field.sample_count());
  std::vector<uint8_t> left(missing.begin(), missing.end()), next;
  if (std::find(left.begin(), left.end(), uint8_t(0)) == left.end()) return 0;
  size_t total = 0;
  for (size_t filled = 1; filled != 0;) total += filled = detail::fill_sweep(field, left, next);
  return total;
}

HeightField resample_square(const HeightField& field, uint32_t samples) {
  assert(field.width >= 2 && field.height >= 2 && samples >= 2);
  HeightField out;
  out.width = out.height = samples;
  out.vertical_scale = field.vertical_scale;
  out.cell_size_x = field.cell_size_x * float(field.width - 1) / float(samples - 1);
  out.cell_size_y = field.cell_size_y * float(field.height - 1) / float(samples - 1);
  out.heights.resize(size_t(samples) * samples);
  const double sx = double(field.width - 1) / double(samples - 1);
  const double sy = double(field.height - 1) / double(samples - 1);
  for (uint32_t y = 0; y < samples; ++y)
    for (uint32_t x = 0; x < samples; ++x) {
      const double fx = x * sx, fy = y * sy;
      const uint32_t x0 = std::min(uint32_t(fx), field.width - 2);
      const uint32_t y0 = std::min(uint32_t(fy), field.height - 2);
      const float tx = float(fx - x0), ty = float(fy - y0);
      const float a = field.at(x0, y0) + tx * (field.at(x0 + 1, y0) - field.at(x0, y0));
      const float b = field.at(x0, y0 + 1) + tx * (field.at(x0 + 1, y0 + 1) - field.at(x0, y0 + 1));
      out.heights[size_t(y) * samples + x] = a + ty * (b - a);
    }
  return out;
}

}  // namespace lod
