// Images carried inside a baked chain: the PNG or JPEG bytes of a texture that the source
// held in itself (a GLB buffer view or a data: URI), kept undecoded so the .lod is
// self-contained. A material slot names one by the URI "embedded:<k>" (k indexes
// LodChain::images); a relative URI cannot start with a "name:" segment (RFC 3986 4.2), so the
// form never collides with a file's URI.
#pragma once
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace lod {

enum class ImageType : uint8_t { unknown = 0, png = 1, jpeg = 2 };

inline constexpr size_t kMaxEmbeddedImageBytes = size_t(256) << 20;  // one image (the exporters' bound too)
inline constexpr uint64_t kMaxEmbeddedBytes = uint64_t(1) << 30;     // all of a chain's images together
inline constexpr uint32_t kMaxEmbeddedImages = 4096;

struct EmbeddedImage {
  ImageType type = ImageType::unknown;
  std::vector<uint8_t> bytes;  // the file as it was embedded, signature first
};

// PNG by its 8-byte signature, JPEG by its SOI marker (FF D8 FF); anything else is unknown.
ImageType image_type_of(std::span<const uint8_t> bytes);
const char* mime_type(ImageType type);       // "image/png", "image/jpeg", "" for unknown
const char* file_extension(ImageType type);  // ".png", ".jpg", "" for unknown

std::string embedded_image_uri(uint32_t k);
// True when `uri` has the "embedded:" scheme; `k` is then its index, or UINT32_MAX when the
// rest is not a decimal number below kMaxEmbeddedImages.
bool is_embedded_image_uri(const std::string& uri, uint32_t* k = nullptr);

}  // namespace lod
