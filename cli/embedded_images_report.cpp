#include "cli/embedded_images_report.h"

#include <cstdio>

namespace lod::cli {

nlohmann::json images_json(std::span<const EmbeddedImage> images) {
  nlohmann::json out = nlohmann::json::array();
  for (size_t k = 0; k < images.size(); ++k)
    out.push_back({{"index", k},
                   {"uri", embedded_image_uri(uint32_t(k))},
                   {"mime_type", mime_type(images[k].type)},
                   {"bytes", images[k].bytes.size()}});
  return out;
}

void print_images(std::span<const EmbeddedImage> images) {
  uint64_t total = 0;
  for (const EmbeddedImage& img : images) total += img.bytes.size();
  std::printf("embedded images: %zu (%llu bytes, kept from the source file, PNG/JPEG undecoded)\n", images.size(),
              (unsigned long long)total);
  for (size_t k = 0; k < images.size(); ++k)
    std::printf("  %s: %s, %zu bytes\n", embedded_image_uri(uint32_t(k)).c_str(), mime_type(images[k].type),
                images[k].bytes.size());
}

}  // namespace lod::cli
