// Height field text input: plain "x y z" samples, one a line, on a regular grid (issue 15).
//
// Any sample order; blank lines and lines starting with '#' are skipped. The grid is detected:
// the distinct x and the distinct y values must each be evenly spaced (within 1 % of the step)
// and every grid point must appear exactly once. Refused, with the file and line named: fewer
// than 2 x 2 samples, a line that is not three numbers, a non-finite value, a value off the
// grid's step, a missing or repeated grid point, a grid larger than max_samples (checked before
// anything the size of the grid is allocated). No-data: a z equal to no_data_value is filled
// from its neighbours (fill_missing_heights); a grid with only no-data is refused.
// Geographic coordinates (degrees) become metres by an equirectangular projection about the
// mid latitude: cell_x = step_lon * R * cos(lat_mid) * pi / 180, cell_y = step_lat * R * pi / 180,
// R = 6,371,008.8 m (mean Earth radius), so distances along a parallel are off by
// cos(lat) / cos(lat_mid) - 1 away from the middle (under 2.5 % over the 11 degrees of the
// deal.II step-53 topography). Grid rows run along increasing y (latitude).
// Gzip'd input (".gz") is refused with a hint: scripts/fetch-topography.sh writes the
// decompressed text beside the .gz (lod_preprocess does not link zlib).
#pragma once
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <string_view>

#include "runtime/height_field.h"
#include "runtime/status.h"

namespace lod {

enum class GridCoordinates : uint8_t {
  metres,           // x y z, all metres
  degrees_lon_lat,  // longitude latitude elevation (metres)
  degrees_lat_lon,  // latitude longitude elevation (the deal.II step-53 topography)
};

struct HeightFieldTextOptions {
  GridCoordinates coordinates = GridCoordinates::metres;
  float vertical_scale = 1;
  double no_data_value = std::numeric_limits<double>::quiet_NaN();  // NaN: none
  size_t max_samples = size_t(1) << 28;                             // 1 GiB of floats
};

// `name` labels messages (the file name). On error `out` is unchanged.
Status parse_height_field_text(std::string_view text, const std::string& name, HeightField& out,
                               const HeightFieldTextOptions& options = {});
Status read_height_field_text(const std::filesystem::path& path, HeightField& out,
                              const HeightFieldTextOptions& options = {});

}  // namespace lod
