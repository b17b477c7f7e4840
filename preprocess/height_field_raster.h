// Height fields from GDAL rasters: GeoTIFF, SRTM .hgt, ESRI ASCII grid (.asc) and
// every other raster format the installed GDAL reads. GDAL's headers stay in the .cpp.
//
// Band 1 is the elevation, read as 32-bit floats and multiplied by vertical_scale. No-data: the
// band's own no-data value (or options.no_data_value when set) and non-finite samples are filled
// from their neighbours (fill_missing_heights); a raster with only no-data is refused.
// Orientation: grid rows run along increasing northing, as in the text reader, so a north-up
// raster (GDAL's usual negative y step, top row first) is flipped and a south-up one is not;
// columns run along increasing easting. A raster without a geotransform is taken as an image
// (top row = north, 1 m cells).
// Coordinates: a projected CRS gives cell sizes from the geotransform in its linear unit
// converted to metres; a geographic CRS (degrees, e.g. .hgt) is converted by the text
// reader's equirectangular projection about the raster's mid latitude
// (geographic_cell_sizes()). Rotated or sheared geotransforms are refused.
// Sizes: width x height is checked against options.max_samples and the available memory
// before anything that size is allocated. Every error names the file (GDAL's own message is
// appended when GDAL failed).
#pragma once
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "preprocess/height_field_io.h"
#include "runtime/height_field.h"
#include "runtime/status.h"

namespace lod {

// On error `out` is unchanged.
Status read_height_field_raster(const std::filesystem::path& path, HeightField& out,
                                const HeightFieldOptions& options = {});

// The same from bytes in memory (GDAL's /vsimem/), for tests and fuzzing; `name` labels
// messages and its extension tells GDAL drivers that need one (".asc", ".hgt") the format.
Status parse_height_field_raster(std::span<const uint8_t> bytes, const std::string& name, HeightField& out,
                                 const HeightFieldOptions& options = {});

}  // namespace lod
