// The declared size of a text grid (ESRI ASCII "ncols"/"nrows", GRASS ASCII "cols:"/"rows:"),
// checked before GDAL opens the file: GDAL's driver allocates 8 bytes per declared row while
// opening, so a 200-byte file declaring 10^8 rows would cost 800 MB before any of our checks.
#pragma once
#include <cstdint>
#include <span>
#include <string>

#include "preprocess/height_field_io.h"
#include "runtime/status.h"

namespace lod {

// `head`: the file's first bytes (kAsciiGridHeadBytes or all of it); `file_bytes`: its size.
// Files that do not open with a text-grid keyword pass. A grid passes when its declared
// columns x rows meet check_height_field_size and fit the file (a sample takes >= 2 bytes).
inline constexpr size_t kAsciiGridHeadBytes = 64 << 10;
Status check_ascii_grid_header(std::span<const uint8_t> head, uint64_t file_bytes, const std::string& name,
                               const HeightFieldOptions& options, uint64_t bytes_per_sample);

}  // namespace lod
