#include "viewer/screenshot.h"

#include <algorithm>
#include <cstring>

#include <epoxy/gl.h>
#include <stb_image_write.h>

namespace lod::viewer {

std::vector<uint8_t> read_pixels_top_down(int width, int height) {
  const size_t row = size_t(width) * 3;
  std::vector<uint8_t> pixels(row * size_t(height));
  glPixelStorei(GL_PACK_ALIGNMENT, 1);  // rows of width*3 bytes are not 4-aligned
  glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, pixels.data());
  std::vector<uint8_t> tmp(row);
  for (int y = 0; y < height / 2; ++y) {
    uint8_t* a = pixels.data() + size_t(y) * row;
    uint8_t* b = pixels.data() + size_t(height - 1 - y) * row;
    std::memcpy(tmp.data(), a, row);
    std::memcpy(a, b, row);
    std::memcpy(b, tmp.data(), row);
  }
  return pixels;
}

Status write_png(const std::filesystem::path& path, int width, int height, const std::vector<uint8_t>& rgb) {
  if (path.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(path.parent_path(), ec);
  }
  if (!stbi_write_png(path.c_str(), width, height, 3, rgb.data(), width * 3))
    return Status::error(path.string() + ": cannot write the PNG");
  return Status::success();
}

}  // namespace lod::viewer
