// One entry for every elevation file, picked by extension: ".txt", ".xyz" and ".gz"
// -> "x y z" text (height_field_io.h), ".png" -> stb (height_field_png.h), anything else ->
// GDAL (height_field_raster.h: GeoTIFF, SRTM .hgt, ESRI ASCII .asc, ...). Case-insensitive.
#pragma once
#include <filesystem>

#include "preprocess/height_field_io.h"
#include "runtime/height_field.h"
#include "runtime/status.h"

namespace lod {

enum class HeightFieldFormat : uint8_t { text, png, raster };

HeightFieldFormat height_field_format_of(const std::filesystem::path& path);

Status read_height_field(const std::filesystem::path& path, HeightField& out, const HeightFieldOptions& options = {});

}  // namespace lod
