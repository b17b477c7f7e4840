// PNG heightmap -> HeightField through stb_image (compiled here, static: no symbol clashes).
#include "preprocess/height_field_png.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstring>
#include <iterator>
#include <memory>
#include <vector>

#include "runtime/regular_file.h"

#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#define STBI_NO_STDIO
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#endif
#include <stb_image.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace lod {
namespace detail {

struct StbFree {
  void operator()(void* p) const { stbi_image_free(p); }
};

// Bytes per sample while decoding: stb's grey + alpha at 16 bits, the floats, the fill's flags.
inline constexpr uint64_t kPngBytesPerSample = 4 + sizeof(float) + 3;

// Copies channel 0 of each pixel to the grid, top row last; alpha 0 (when present) -> no data.
template <typename T>
void take_pixels(const T* px, int channels, HeightField& f, std::vector<uint8_t>& missing) {
  for (uint32_t y = 0; y < f.height; ++y) {
    const T* row = px + size_t(f.height - 1 - y) * f.width * size_t(channels);
    for (uint32_t x = 0; x < f.width; ++x) {
      const size_t i = size_t(y) * f.width + x;
      f.heights[i] = float(row[size_t(x) * channels]);
      if (channels == 2 && row[size_t(x) * channels + 1] == 0) missing[i] = 1;
    }
  }
}

uint32_t big_endian32(const uint8_t* p) {
  return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | uint32_t(p[3]);
}

// Every chunk's declared length must fit in the bytes that follow it: stb grows its IDAT buffer
// to a declared length before reading it, so a lying header would cost that much memory.
Status check_png_chunks(std::span<const uint8_t> b, const std::string& name) {
  static constexpr uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (b.size() < 8 || !std::equal(kSignature, kSignature + 8, b.begin()))
    return Status::error(name + ": not a PNG (no PNG signature)");
  size_t at = 8;
  while (at < b.size()) {
    if (b.size() - at < 12) return Status::error(name + ": truncated PNG chunk at byte " + std::to_string(at));
    const uint32_t length = big_endian32(&b[at]);
    const std::string type(reinterpret_cast<const char*>(&b[at + 4]), 4);
    if (length > b.size() - at - 12)
      return Status::error(name + ": PNG chunk '" + type + "' at byte " + std::to_string(at) + " declares " +
                           std::to_string(length) + " bytes, only " + std::to_string(b.size() - at - 12) + " follow");
    at += size_t(length) + 12;
    if (type == "IEND") return Status::success();
  }
  return Status::error(name + ": truncated PNG (no IEND chunk)");
}

// stb copies IDAT data into a buffer it allocates at the first non-empty chunk; an empty IDAT
// before that hands memcpy a null pointer (undefined behaviour). Empty IDATs carry nothing, so
// they are dropped. Returns no bytes when there is none to drop. Chunks are checked already.
std::vector<uint8_t> without_empty_idat(std::span<const uint8_t> b) {
  std::vector<uint8_t> kept;
  size_t at = 8, copied = 0;
  while (at + 12 <= b.size()) {
    const uint32_t length = big_endian32(&b[at]);
    const bool empty_idat = length == 0 && std::equal(&b[at + 4], &b[at + 8], "IDAT");
    if (empty_idat) {
      if (kept.empty()) kept.reserve(b.size());
      kept.insert(kept.end(), b.begin() + ptrdiff_t(copied), b.begin() + ptrdiff_t(at));
      copied = at + 12;
    }
    at += size_t(length) + 12;
  }
  if (copied == 0) return {};
  kept.insert(kept.end(), b.begin() + ptrdiff_t(copied), b.end());
  return kept;
}

}  // namespace detail

Status parse_height_field_png(std::span<const uint8_t> bytes, const std::string& name, HeightField& out,
                              const HeightFieldOptions& o) {
  if (bytes.size() > size_t(INT_MAX)) return Status::error(name + ": PNG over 2 GiB");
  if (Status st = detail::check_png_chunks(bytes, name); !st) return st;
  const std::vector<uint8_t> trimmed = detail::without_empty_idat(bytes);
  if (!trimmed.empty()) bytes = trimmed;
  const auto* data = reinterpret_cast<const stbi_uc*>(bytes.data());
  const int len = int(bytes.size());
  int w = 0, h = 0, comp = 0;
  if (!stbi_info_from_memory(data, len, &w, &h, &comp))
    return Status::error(name + ": not a readable PNG (" + std::string(stbi_failure_reason()) + ")");
  if (comp != 1 && comp != 2)
    return Status::error(name + ": colour PNG (" + std::to_string(comp) +
                         " channels); a heightmap is grey, 8 or 16 bits, optionally with alpha");
  if (Status st = check_height_field_size(name, uint64_t(w), uint64_t(h), o, detail::kPngBytesPerSample); !st)
    return st;
  const bool wide = stbi_is_16_bit_from_memory(data, len) != 0;
  int dw = 0, dh = 0, dc = 0;
  std::unique_ptr<void, detail::StbFree> pixels(
      wide ? static_cast<void*>(stbi_load_16_from_memory(data, len, &dw, &dh, &dc, comp))
           : static_cast<void*>(stbi_load_from_memory(data, len, &dw, &dh, &dc, comp)));
  if (!pixels) return Status::error(name + ": PNG decoding failed (" + std::string(stbi_failure_reason()) + ")");
  if (dw != w || dh != h) return Status::error(name + ": PNG size changed between header and decoding");
  HeightField f;
  f.width = uint32_t(w), f.height = uint32_t(h);
  f.vertical_scale = o.vertical_scale;
  f.heights.resize(f.sample_count());
  std::vector<uint8_t> missing(f.sample_count(), 0);
  if (wide)
    detail::take_pixels(static_cast<const uint16_t*>(pixels.get()), comp, f, missing);
  else
    detail::take_pixels(static_cast<const uint8_t*>(pixels.get()), comp, f, missing);
  pixels.reset();
  size_t holes = 0;
  for (size_t i = 0; i < missing.size(); ++i) {
    missing[i] |= !std::isnan(o.no_data_value) && f.heights[i] == float(o.no_data_value);
    holes += missing[i];
  }
  if (holes > 0 && fill_missing_heights(f, missing) == 0) return Status::error(name + ": every sample is no-data");
  out = std::move(f);
  return Status::success();
}

Status read_height_field_png(const std::filesystem::path& path, HeightField& out, const HeightFieldOptions& o) {
  const std::string name = path.string();
  // A regular file only; its signature is checked before it is read whole.
  RegularFile f;
  if (Status s = open_regular_file(path, kInputFileLimit, f); !s) return s;
  std::vector<uint8_t> bytes;
  if (Status s = f.read_head(8, bytes); !s) return s;
  static const uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
  if (bytes.size() == 8 && std::memcmp(bytes.data(), kSignature, 8) != 0)
    return Status::error(name + ": not a PNG file (its first 8 bytes are not the PNG signature)");
  if (Status s = f.read_all(bytes); !s) return s;
  return parse_height_field_png(bytes, name, out, o);
}

}  // namespace lod
