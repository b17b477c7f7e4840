// Pixel checks shared by the screenshot tests: where a world point lands for the tests'
// front camera (eye at z = 30 looking at the origin, 60 degrees), and background pixels.
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "runtime/view.h"
#include "viewer/level_palette.h"

namespace lod::test {

// Pixel (x, y from the top) where a world point lands in a width x height picture.
inline std::array<int, 2> project(glm::vec3 p, int width, int height) {
  lod::View v;
  v.eye = {0, 0, 30};
  v.target = {0, 0, 0};
  v.fov_y_deg = 60;
  v.width = width;
  v.height = height;
  const glm::vec4 clip = lod::projection_matrix(v) * lod::view_matrix(v) * glm::vec4(p, 1);
  const float nx = clip.x / clip.w, ny = clip.y / clip.w;
  return {int((nx * 0.5f + 0.5f) * float(width)), int((0.5f - ny * 0.5f) * float(height))};
}

inline bool is_background(const uint8_t* px) {
  for (int c = 0; c < 3; ++c)
    if (std::abs(int(px[c]) - int(std::lround(lod::viewer::kBackground[size_t(c)] * 255))) > 1) return false;
  return true;
}

}  // namespace lod::test
