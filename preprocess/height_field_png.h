// Height fields from 8- and 16-bit PNG heightmaps, decoded by stb_image.
//
// Grey (or grey + alpha) PNGs only: the sample value (0-255 or 0-65535) is the elevation,
// multiplied by vertical_scale; cells are 1 m unless the scene's cell_size says otherwise. An
// alpha of 0 marks no data, as does a value equal to options.no_data_value; both are filled
// from their neighbours (fill_missing_heights). Orientation as the GDAL reader's for a north-up
// image: the top row is the grid's last (rows run along increasing northing). Colour PNGs are
// refused (a heightmap is one channel). The declared size is checked against max_samples and
// the available memory before decoding; errors name the file and, for a broken PNG, stb's
// reason.
#pragma once
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "preprocess/height_field_io.h"
#include "runtime/height_field.h"
#include "runtime/status.h"

namespace lod {

// `name` labels messages. On error `out` is unchanged.
Status parse_height_field_png(std::span<const uint8_t> bytes, const std::string& name, HeightField& out,
                              const HeightFieldOptions& options = {});
Status read_height_field_png(const std::filesystem::path& path, HeightField& out,
                             const HeightFieldOptions& options = {});

}  // namespace lod
