// Screenshots: the bound read framebuffer to a PNG (stb_image_write), flipped so that row 0
// is the top of the picture as image files expect (GL's row 0 is the bottom).
#pragma once
#include <cstdint>
#include <filesystem>
#include <vector>

#include "runtime/status.h"

namespace lod::viewer {

// RGB, top row first, `width * height * 3` bytes.
std::vector<uint8_t> read_pixels_top_down(int width, int height);
Status write_png(const std::filesystem::path& path, int width, int height, const std::vector<uint8_t>& rgb);

}  // namespace lod::viewer
