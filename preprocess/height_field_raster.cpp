// GDAL raster -> HeightField: open, check the declared size, georeference, read band 1, orient,
// fill no-data.
#include "preprocess/height_field_raster.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_vsi.h>
#include <gdal.h>
#include <ogr_srs_api.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <utility>
#include <vector>

#include "preprocess/ascii_grid_header.h"
#include "runtime/regular_file.h"

namespace lod {
namespace detail {

void gdal_register_once() {
  static std::once_flag once;
  std::call_once(once, [] { GDALAllRegister(); });
}

// GDAL reports through a per-thread handler: keep its messages off stderr, for our errors.
struct QuietGdal {
  QuietGdal() {
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErrorReset();
  }
  ~QuietGdal() { CPLPopErrorHandler(); }
  QuietGdal(const QuietGdal&) = delete;
  QuietGdal& operator=(const QuietGdal&) = delete;
};

std::string gdal_says() {
  const char* m = CPLGetLastErrorMsg();
  return m && *m ? std::string(" (GDAL: ") + m + ")" : std::string();
}

struct Dataset {
  GDALDatasetH handle = nullptr;
  ~Dataset() {
    if (handle) GDALClose(handle);
  }
};

// How raster pixels become grid samples.
struct Georef {
  float cell_x = 1, cell_y = 1;
  bool flip_rows = true;  // top row first, north up: the grid's last row
  bool flip_cols = false;
};

constexpr double kPi = 3.14159265358979323846;

Status geographic_cells(OGRSpatialReferenceH srs, const double gt[6], int rows, const std::string& name, Georef& g) {
  const double to_degrees = OSRGetAngularUnits(srs, nullptr) * 180.0 / kPi;  // units are radians per unit
  const double lat_a = gt[3] * to_degrees, lat_b = (gt[3] + gt[5] * rows) * to_degrees;
  if (!(std::abs(lat_a) <= 90.0 + 1e-6 && std::abs(lat_b) <= 90.0 + 1e-6))
    return Status::error(name + ": geographic raster reaches latitude " + std::to_string(std::abs(lat_a) > 90 ? lat_a : lat_b) +
                         ", outside [-90, 90] degrees");
  geographic_cell_sizes(gt[1] * to_degrees, gt[5] * to_degrees, 0.5 * (lat_a + lat_b), g.cell_x, g.cell_y);
  return Status::success();
}

Status georef_of(GDALDatasetH ds, int rows, const std::string& name, Georef& g) {
  double gt[6];
  if (GDALGetGeoTransform(ds, gt) != CE_None) return Status::success();  // an image: 1 m cells, top row north
  if (gt[2] != 0 || gt[4] != 0)
    return Status::error(name + ": rotated or sheared geotransform (terms " + std::to_string(gt[2]) + ", " +
                         std::to_string(gt[4]) + "); warp it north-up first (gdalwarp)");
  if (!(std::isfinite(gt[1]) && std::isfinite(gt[5]) && gt[1] != 0 && gt[5] != 0))
    return Status::error(name + ": geotransform has a zero or non-finite pixel size");
  g.flip_rows = gt[5] < 0;
  g.flip_cols = gt[1] < 0;
  OGRSpatialReferenceH srs = GDALGetSpatialRef(ds);
  if (srs && OSRIsGeographic(srs)) return geographic_cells(srs, gt, rows, name, g);
  const double metres = srs ? OSRGetLinearUnits(srs, nullptr) : 1.0;  // metres per unit
  g.cell_x = float(std::abs(gt[1]) * metres);
  g.cell_y = float(std::abs(gt[5]) * metres);
  if (!(g.cell_x > 0 && g.cell_y > 0 && std::isfinite(g.cell_x) && std::isfinite(g.cell_y)))
    return Status::error(name + ": pixel size is not a positive finite length in metres");
  return Status::success();
}

void orient(HeightField& f, const Georef& g) {
  const size_t w = f.width;
  if (g.flip_rows)
    for (uint32_t y = 0; y < f.height / 2; ++y)
      std::swap_ranges(f.heights.begin() + ptrdiff_t(y * w), f.heights.begin() + ptrdiff_t((y + 1) * w),
                       f.heights.begin() + ptrdiff_t((f.height - 1 - y) * w));
  if (g.flip_cols)
    for (uint32_t y = 0; y < f.height; ++y)
      std::reverse(f.heights.begin() + ptrdiff_t(y * w), f.heights.begin() + ptrdiff_t((y + 1) * w));
}

// Bytes per sample a read needs: the floats, the no-data flags and the fill's two copies of them.
inline constexpr uint64_t kBytesPerSample = sizeof(float) + 3;

Status read_dataset(GDALDatasetH ds, const std::string& name, HeightField& out, const HeightFieldOptions& o) {
  if (GDALGetRasterCount(ds) < 1) return Status::error(name + ": the raster has no bands");
  const int w = GDALGetRasterXSize(ds), h = GDALGetRasterYSize(ds);
  if (w < 0 || h < 0) return Status::error(name + ": negative raster size");
  if (Status st = check_height_field_size(name, uint64_t(w), uint64_t(h), o, kBytesPerSample); !st) return st;
  Georef g;
  if (Status st = georef_of(ds, h, name, g); !st) return st;
  GDALRasterBandH band = GDALGetRasterBand(ds, 1);
  int has_no_data = 0;
  const double band_no_data = GDALGetRasterNoDataValue(band, &has_no_data);
  HeightField f;
  f.width = uint32_t(w), f.height = uint32_t(h);
  f.cell_size_x = g.cell_x, f.cell_size_y = g.cell_y;
  f.vertical_scale = o.vertical_scale;
  f.heights.resize(f.sample_count());
  if (GDALRasterIO(band, GF_Read, 0, 0, w, h, f.heights.data(), w, h, GDT_Float32, 0, 0) != CE_None)
    return Status::error(name + ": reading the elevations failed" + gdal_says());
  orient(f, g);
  const double no_data = !std::isnan(o.no_data_value) ? o.no_data_value
                         : has_no_data                 ? band_no_data
                                                       : std::nan("");
  if (Status st = fill_no_data_samples(f, no_data, name); !st) return st;
  out = std::move(f);
  return Status::success();
}

Status open_and_read(const std::string& path, const std::string& name, HeightField& out, const HeightFieldOptions& o) {
  gdal_register_once();
  QuietGdal quiet;
  Dataset ds;
  std::vector<const char*> drivers;
  for (const std::string& d : o.gdal_drivers) {
    if (!GDALGetDriverByName(d.c_str()))
      return Status::error(name + ": the allowed GDAL drivers name '" + d + "', which this GDAL does not have");
    drivers.push_back(d.c_str());
  }
  drivers.push_back(nullptr);
  ds.handle = GDALOpenEx(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY, o.gdal_drivers.empty() ? nullptr : drivers.data(),
                         nullptr, nullptr);
  if (!ds.handle) return Status::error(name + ": not a raster GDAL can read" + gdal_says());
  return read_dataset(ds.handle, name, out, o);
}

}  // namespace detail

Status read_height_field_raster(const std::filesystem::path& path, HeightField& out, const HeightFieldOptions& o) {
  const std::string name = path.string();
  // A regular file only, its head checked against its size before GDAL opens it.
  RegularFile f;
  if (Status s = open_regular_file(path, kInputFileLimit, f); !s) return s;
  std::vector<uint8_t> head;
  if (Status s = f.read_head(kAsciiGridHeadBytes, head); !s) return s;
  if (Status st = check_ascii_grid_header(head, f.size, name, o, detail::kBytesPerSample); !st) return st;
  return detail::open_and_read(name, name, out, o);
}

Status parse_height_field_raster(std::span<const uint8_t> bytes, const std::string& name, HeightField& out,
                                 const HeightFieldOptions& o) {
  if (Status st = check_ascii_grid_header(bytes, bytes.size(), name, o, detail::kBytesPerSample); !st) return st;
  detail::gdal_register_once();
  static std::atomic<uint64_t> serial{0};
  // A folder per call keeps the file's own name, which some drivers read (.hgt: its tile).
  const std::string path = "/vsimem/lodkit_height_field_" + std::to_string(serial++) + "/" +
                           std::filesystem::path(name).filename().string();
  VSILFILE* file = VSIFileFromMemBuffer(path.c_str(), const_cast<GByte*>(bytes.data()), vsi_l_offset(bytes.size()), FALSE);
  if (!file) return Status::error(name + ": cannot hand the bytes to GDAL");
  VSIFCloseL(file);
  const Status st = detail::open_and_read(path, name, out, o);
  VSIUnlink(path.c_str());
  return st;
}

}  // namespace lod
