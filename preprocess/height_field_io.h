// Height field text input: plain "x y z" samples, one a line, on a regular grid.
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
#include <vector>

#include "runtime/height_field.h"
#include "runtime/status.h"

namespace lod {

enum class GridCoordinates : uint8_t {
  metres,           // x y z, all metres
  degrees_lon_lat,  // longitude latitude elevation (metres)
  degrees_lat_lon,  // latitude longitude elevation (the deal.II step-53 topography)
};

// Options of every height-field reader (text here, GDAL rasters in height_field_raster.h, PNG
// in height_field_png.h; height_field_read.h picks one by the file's extension).
struct HeightFieldOptions {
  GridCoordinates coordinates = GridCoordinates::metres;  // text only: rasters carry their own
  float vertical_scale = 1;
  double no_data_value = std::numeric_limits<double>::quiet_NaN();  // NaN: none (rasters: the band's own)
  size_t max_samples = size_t(1) << 28;                             // 1 GiB of floats
  // GDAL rasters: the drivers allowed to open the file (short names, e.g. "GTiff", "AAIGrid",
  // "SRTMHGT"); empty: every installed driver. Some GDAL drivers allocate for the declared size
  // while opening, before the size check here can run: a list keeps untrusted input to drivers
  // that do not (the fuzz target uses {"AAIGrid"}).
  std::vector<std::string> gdal_drivers;
};
using HeightFieldTextOptions = HeightFieldOptions;

// Checks a declared width x height before anything that size is allocated: at least 2 x 2, at
// most options.max_samples, and the memory a reader needs for it (bytes_per_sample each) under
// what the machine has available now. The error names the file and says which limit.
Status check_height_field_size(const std::string& name, uint64_t width, uint64_t height,
                               const HeightFieldOptions& options, uint64_t bytes_per_sample);

// Available memory in bytes (MemAvailable of /proc/meminfo; physical pages when absent).
uint64_t available_memory_bytes();

// Every sample equal to no_data (when not NaN), not finite or beyond +-1e9 (an undeclared float
// no-data such as -3.4e38; the text reader refuses those) is filled from its neighbours
// (fill_missing_heights); refused when every sample is no-data. `filled` counts them.
Status fill_no_data_samples(HeightField& field, double no_data, const std::string& name, size_t* filled = nullptr);

// Degrees to metres, as the text reader does: the equirectangular cell sizes of a grid with
// steps (step_lon, step_lat) degrees about latitude lat_mid.
void geographic_cell_sizes(double step_lon, double step_lat, double lat_mid, float& cell_x, float& cell_y);

// `name` labels messages (the file name). On error `out` is unchanged.
Status parse_height_field_text(std::string_view text, const std::string& name, HeightField& out,
                               const HeightFieldTextOptions& options = {});
Status read_height_field_text(const std::filesystem::path& path, HeightField& out,
                              const HeightFieldTextOptions& options = {});

}  // namespace lod
