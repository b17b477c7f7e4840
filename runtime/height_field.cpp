#include "runtime/height_field.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace lod {
namespace detail {

template <typename Fn>
void for_each_neighbour(const HeightField& f, size_t i, Fn&& fn) {
  const uint32_t x = uint32_t(i % f.width), y = uint32_t(i / f.width);
  if (x > 0) fn(i - 1);
  if (x + 1 < f.width) fn(i + 1);
  if (y > 0) fn(i - f.width);
  if (y + 1 < f.height) fn(i + f.width);
}

// One ring: every sample of `ring` takes the mean of its neighbours valid before the ring
// (all written first, then marked valid), so a hole fills from its rim inwards; the next ring
// is the still-missing neighbours of this one. Each sample is in one ring: O(samples) in all.
void fill_ring(HeightField& f, std::vector<uint8_t>& missing, std::vector<uint8_t>& queued,
               std::vector<size_t>& ring, std::vector<size_t>& next) {
  for (size_t i : ring) {
    double sum = 0;  // float could overflow on two near-FLT_MAX neighbours
    int n = 0;
    for_each_neighbour(f, i, [&](size_t j) {
      if (!missing[j]) sum += f.heights[j], ++n;
    });
    f.heights[i] = float(sum / n);
  }
  for (size_t i : ring) missing[i] = 0;
  next.clear();
  for (size_t i : ring)
    for_each_neighbour(f, i, [&](size_t j) {
      if (missing[j] && !queued[j]) queued[j] = 1, next.push_back(j);
    });
  ring.swap(next);
}

}  // namespace detail

size_t fill_missing_heights(HeightField& field, std::span<const uint8_t> missing) {
  assert(missing.size() == field.sample_count());
  std::vector<uint8_t> left(missing.begin(), missing.end());
  if (std::find(left.begin(), left.end(), uint8_t(0)) == left.end()) return 0;
  std::vector<uint8_t> queued(left.size(), 0);
  std::vector<size_t> ring, next;
  for (size_t i = 0; i < left.size(); ++i) {
    if (!left[i]) continue;
    bool rim = false;
    detail::for_each_neighbour(field, i, [&](size_t j) { rim |= !left[j]; });
    if (rim) queued[i] = 1, ring.push_back(i);
  }
  size_t total = 0;
  while (!ring.empty()) {
    total += ring.size();
    detail::fill_ring(field, left, queued, ring, next);
  }
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
