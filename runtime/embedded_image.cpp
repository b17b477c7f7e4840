// Embedded images: signatures and the "embedded:<k>" URI form. See embedded_image.h.
#include "runtime/embedded_image.h"

#include <cstring>

namespace lod {

namespace {
constexpr char kScheme[] = "embedded:";
constexpr size_t kSchemeBytes = sizeof(kScheme) - 1;
}  // namespace

ImageType image_type_of(std::span<const uint8_t> bytes) {
  static const uint8_t png[8] = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
  if (bytes.size() >= 8 && std::memcmp(bytes.data(), png, 8) == 0) return ImageType::png;
  if (bytes.size() >= 3 && bytes[0] == 0xff && bytes[1] == 0xd8 && bytes[2] == 0xff) return ImageType::jpeg;
  return ImageType::unknown;
}

const char* mime_type(ImageType type) {
  return type == ImageType::png ? "image/png" : type == ImageType::jpeg ? "image/jpeg" : "";
}

const char* file_extension(ImageType type) {
  return type == ImageType::png ? ".png" : type == ImageType::jpeg ? ".jpg" : "";
}

std::string embedded_image_uri(uint32_t k) { return kScheme + std::to_string(k); }

bool is_embedded_image_uri(const std::string& uri, uint32_t* k) {
  if (uri.compare(0, kSchemeBytes, kScheme) != 0) return false;
  uint64_t value = 0;
  bool digits =
      uri.size() > kSchemeBytes && uri.size() <= kSchemeBytes + 5;  // kMaxEmbeddedImages has 4 digits
  for (size_t i = kSchemeBytes; digits && i < uri.size(); ++i) {
    digits = uri[i] >= '0' && uri[i] <= '9';
    value = value * 10 + uint64_t(uri[i] - '0');
  }
  if (k) *k = digits && value < kMaxEmbeddedImages ? uint32_t(value) : UINT32_MAX;
  return true;
}

}  // namespace lod
