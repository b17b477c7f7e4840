// GDAL rasters as height fields: fixtures written here with GDAL's own API (GeoTIFF) or by hand
// (SRTM .hgt, ESRI ASCII grid), then read back: values, orientation, cell sizes, no-data,
// hostile rasters.
#include "preprocess/height_field_raster.h"

#include <cpl_conv.h>
#include <gdal.h>
#include <gtest/gtest.h>
#include <ogr_srs_api.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "preprocess/height_field_read.h"
#include "test_support.h"

namespace lod {
namespace {

bool has(const Status& st, const std::string& what) { return st.message.find(what) != std::string::npos; }

// File value of column c, row r (row 0 = top of the raster).
float file_value(int c, int r) { return 100.f + 10.f * float(c) + float(r); }

struct TiffSpec {
  int width = 5, height = 3;
  double geo[6] = {500000, 30, 0, 1000000, 0, -20};
  int epsg = 32637;  // UTM 37N; 4326: WGS 84 degrees; 0: none
  bool geotransform = true;
  double no_data = std::nan("");
  std::function<float(int, int)> value = file_value;
};

void write_tiff(const std::filesystem::path& path, const TiffSpec& s) {
  GDALAllRegister();
  GDALDriverH drv = GDALGetDriverByName("GTiff");
  ASSERT_NE(drv, nullptr);
  GDALDatasetH ds = GDALCreate(drv, path.c_str(), s.width, s.height, 1, GDT_Float32, nullptr);
  ASSERT_NE(ds, nullptr);
  if (s.geotransform) GDALSetGeoTransform(ds, const_cast<double*>(s.geo));
  if (s.epsg) {
    OGRSpatialReferenceH srs = OSRNewSpatialReference(nullptr);
    OSRImportFromEPSG(srs, s.epsg);
    GDALSetSpatialRef(ds, srs);
    OSRDestroySpatialReference(srs);
  }
  GDALRasterBandH band = GDALGetRasterBand(ds, 1);
  if (!std::isnan(s.no_data)) GDALSetRasterNoDataValue(band, s.no_data);
  std::vector<float> v(size_t(s.width) * s.height);
  for (int r = 0; r < s.height; ++r)
    for (int c = 0; c < s.width; ++c) v[size_t(r) * s.width + c] = s.value(c, r);
  ASSERT_EQ(GDALRasterIO(band, GF_Write, 0, 0, s.width, s.height, v.data(), s.width, s.height, GDT_Float32, 0, 0),
            CE_None);
  GDALClose(ds);
}

TEST(HeightFieldRaster, GeoTiffProjectedNorthUpIsFlippedToRowsAlongNorthing) {
  const auto dir = test::temp_dir("raster_tiff");
  write_tiff(dir / "t.tif", {});
  HeightField f;
  const Status st = read_height_field_raster(dir / "t.tif", f);
  ASSERT_TRUE(st.ok) << st.message;
  EXPECT_EQ(f.width, 5u);
  EXPECT_EQ(f.height, 3u);  // not square: kept as is
  EXPECT_FLOAT_EQ(f.cell_size_x, 30.f);
  EXPECT_FLOAT_EQ(f.cell_size_y, 20.f);
  for (uint32_t y = 0; y < 3; ++y)
    for (uint32_t x = 0; x < 5; ++x) EXPECT_FLOAT_EQ(f.at(x, y), file_value(int(x), int(2 - y))) << x << "," << y;
}

TEST(HeightFieldRaster, GeoTiffSouthUpAndEastToWestKeepGridAxesAlongNorthingAndEasting) {
  const auto dir = test::temp_dir("raster_tiff");
  TiffSpec s;
  s.geo[1] = -30, s.geo[5] = 20;  // columns run west, rows run north
  write_tiff(dir / "t.tif", s);
  HeightField f;
  ASSERT_TRUE(read_height_field_raster(dir / "t.tif", f).ok);
  for (uint32_t y = 0; y < 3; ++y)
    for (uint32_t x = 0; x < 5; ++x) EXPECT_FLOAT_EQ(f.at(x, y), file_value(int(4 - x), int(y)));
}

TEST(HeightFieldRaster, GeographicDegreesBecomeMetresAboutTheMidLatitude) {
  const auto dir = test::temp_dir("raster_tiff");
  TiffSpec s;
  s.width = s.height = 4;
  s.epsg = 4326;
  const double geo[6] = {36.0, 0.01, 0, 50.04, 0, -0.01};  // 50.00 to 50.04 N
  std::copy(geo, geo + 6, s.geo);
  write_tiff(dir / "g.tif", s);
  HeightField f;
  const Status st = read_height_field_raster(dir / "g.tif", f);
  ASSERT_TRUE(st.ok) << st.message;
  const double R = 6371008.8, deg = 3.14159265358979323846 / 180;
  EXPECT_NEAR(f.cell_size_y, 0.01 * deg * R, 0.01);                             // 1,111.95 m
  EXPECT_NEAR(f.cell_size_x, 0.01 * deg * R * std::cos(50.02 * deg), 0.01);  // 714.5 m
}

TEST(HeightFieldRaster, WithoutGeoreferenceItIsAnImageOfMetreCells) {
  const auto dir = test::temp_dir("raster_tiff");
  TiffSpec s;
  s.geotransform = false;
  s.epsg = 0;
  write_tiff(dir / "i.tif", s);
  HeightField f;
  ASSERT_TRUE(read_height_field_raster(dir / "i.tif", f).ok);
  EXPECT_FLOAT_EQ(f.cell_size_x, 1.f);
  EXPECT_FLOAT_EQ(f.cell_size_y, 1.f);
  EXPECT_FLOAT_EQ(f.at(0, 0), file_value(0, 2));  // top row is north: the last grid row
}

TEST(HeightFieldRaster, BandNoDataAndNaNAreFilledFromNeighbours) {
  const auto dir = test::temp_dir("raster_tiff");
  TiffSpec s;
  s.no_data = -9999;
  s.value = [](int c, int r) {
    if (c == 2 && r == 1) return -9999.f;
    if (c == 0 && r == 0) return std::nanf("");
    return 50.f;
  };
  write_tiff(dir / "n.tif", s);
  HeightField f;
  const Status st = read_height_field_raster(dir / "n.tif", f);
  ASSERT_TRUE(st.ok) << st.message;
  for (float h : f.heights) EXPECT_FLOAT_EQ(h, 50.f);
}

TEST(HeightFieldRaster, AnOptionNoDataOverridesTheBands) {
  const auto dir = test::temp_dir("raster_tiff");
  TiffSpec s;
  s.value = [](int c, int r) { return c == 1 && r == 1 ? 7.f : 3.f; };
  write_tiff(dir / "o.tif", s);
  HeightFieldOptions o;
  o.no_data_value = 7;
  HeightField f;
  ASSERT_TRUE(read_height_field_raster(dir / "o.tif", f, o).ok);
  for (float h : f.heights) EXPECT_FLOAT_EQ(h, 3.f);
}

TEST(HeightFieldRaster, OnlyNoDataIsRefusedNamingTheFile) {
  const auto dir = test::temp_dir("raster_tiff");
  TiffSpec s;
  s.no_data = -1;
  s.value = [](int, int) { return -1.f; };
  write_tiff(dir / "empty.tif", s);
  HeightField f;
  const Status st = read_height_field_raster(dir / "empty.tif", f);
  ASSERT_FALSE(st.ok);
  EXPECT_TRUE(has(st, "empty.tif: every sample is no-data")) << st.message;
  EXPECT_EQ(f.width, 0u);
}

TEST(HeightFieldRaster, RotatedGeotransformIsRefused) {
  const auto dir = test::temp_dir("raster_tiff");
  TiffSpec s;
  s.geo[2] = 0.5;
  write_tiff(dir / "r.tif", s);
  HeightField f;
  const Status st = read_height_field_raster(dir / "r.tif", f);
  ASSERT_FALSE(st.ok);
  EXPECT_TRUE(has(st, "r.tif: rotated or sheared geotransform")) << st.message;
}

// SRTM3 tile N00E036: 1201 x 1201 big-endian int16, north row first, -32768 = void.
std::vector<uint8_t> hgt_tile(int16_t (*value)(int c, int r)) {
  std::vector<uint8_t> b(1201 * 1201 * 2);
  for (int r = 0; r < 1201; ++r)
    for (int c = 0; c < 1201; ++c) {
      const uint16_t v = uint16_t(value(c, r));
      b[2 * (size_t(r) * 1201 + c)] = uint8_t(v >> 8);
      b[2 * (size_t(r) * 1201 + c) + 1] = uint8_t(v & 0xff);
    }
  return b;
}

int16_t hgt_value(int c, int r) {
  if (c == 600 && r == 600) return -32768;
  return int16_t(c + 2 * r);
}

TEST(HeightFieldRaster, SrtmHgtTileIsGeographicBigEndianWithVoids) {
  const auto dir = test::temp_dir("raster_hgt");
  test::write_bytes(dir / "N00E036.hgt", hgt_tile(hgt_value));
  HeightField f;
  const Status st = read_height_field(dir / "N00E036.hgt", f);
  ASSERT_TRUE(st.ok) << st.message;
  ASSERT_EQ(f.width, 1201u);
  ASSERT_EQ(f.height, 1201u);
  // 3 arc-seconds at the equator: 92.66 m both ways (cos(0.5 deg) ~ 1).
  EXPECT_NEAR(f.cell_size_y, 92.66, 0.05);
  EXPECT_NEAR(f.cell_size_x, 92.66, 0.05);
  EXPECT_FLOAT_EQ(f.at(0, 0), float(hgt_value(0, 1200)));    // south-west corner
  EXPECT_FLOAT_EQ(f.at(1200, 1200), float(hgt_value(1200, 0)));  // north-east
  EXPECT_FLOAT_EQ(f.at(17, 1000), float(hgt_value(17, 200)));
  // The void takes the mean of its four neighbours: (c +- 1) + 2 r and c + 2 (r +- 1).
  EXPECT_FLOAT_EQ(f.at(600, 600), float(600 + 2 * 600));
}

const char* kAsc =
    "ncols 4\n"
    "nrows 3\n"
    "xllcorner 1000\n"
    "yllcorner 2000\n"
    "cellsize 25\n"
    "NODATA_value -9999\n"
    "1 2 3 4\n"
    "5 -9999 7 8\n"
    "9 10 11 12\n";

TEST(HeightFieldRaster, EsriAsciiGridFromFileAndFromMemory) {
  const auto dir = test::temp_dir("raster_asc");
  test::write_text(dir / "g.asc", kAsc);
  HeightField a, b;
  const Status sa = read_height_field(dir / "g.asc", a);
  ASSERT_TRUE(sa.ok) << sa.message;
  const std::string text = kAsc;
  const Status sb = parse_height_field_raster({reinterpret_cast<const uint8_t*>(text.data()), text.size()}, "m.asc", b);
  ASSERT_TRUE(sb.ok) << sb.message;
  for (const HeightField* f : {&a, &b}) {
    ASSERT_EQ(f->width, 4u);
    ASSERT_EQ(f->height, 3u);
    EXPECT_FLOAT_EQ(f->cell_size_x, 25.f);
    EXPECT_FLOAT_EQ(f->at(0, 0), 9.f);  // the last text row is the south edge
    EXPECT_FLOAT_EQ(f->at(3, 2), 4.f);
    EXPECT_FLOAT_EQ(f->at(1, 1), (5.f + 7.f + 2.f + 10.f) / 4.f);  // no-data filled
  }
}

// Fuzzer finding: two near-FLT_MAX samples around a hole summed to infinity in the fill.
// Elevations beyond +-1e9 are no data themselves (undeclared float no-data such as -3.4e38).
TEST(HeightFieldRaster, AbsurdElevationsAreNoDataAndTheFillStaysFinite) {
  const std::string asc =
      "ncols 4\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -9999\n"
      "3e38 -9999 3e38 4\n5 6 -3.4e38 8\n9 10 11 12\n";
  HeightField f;
  const Status st = parse_height_field_raster({reinterpret_cast<const uint8_t*>(asc.data()), asc.size()}, "x.asc", f);
  ASSERT_TRUE(st.ok) << st.message;
  for (float h : f.heights) {
    EXPECT_TRUE(std::isfinite(h));
    EXPECT_GE(h, 4.f);
    EXPECT_LE(h, 12.f);
  }
}

TEST(HeightFieldRaster, HugeDeclaredSizeIsRefusedBeforeAllocating) {
  const auto dir = test::temp_dir("raster_huge");
  GDALAllRegister();
  char* opts[] = {const_cast<char*>("SPARSE_OK=TRUE"), const_cast<char*>("TILED=YES"), nullptr};
  GDALDatasetH ds = GDALCreate(GDALGetDriverByName("GTiff"), (dir / "huge.tif").c_str(), 200000, 200000, 1, GDT_Byte, opts);
  ASSERT_NE(ds, nullptr);
  GDALClose(ds);
  ASSERT_LT(std::filesystem::file_size(dir / "huge.tif"), 16u << 20);  // declared, not stored (tile index only)
  HeightField f;
  const Status limit = read_height_field_raster(dir / "huge.tif", f);
  ASSERT_FALSE(limit.ok);
  EXPECT_TRUE(has(limit, "huge.tif: declares a grid of 200000 x 200000, more than the limit")) << limit.message;
  HeightFieldOptions unlimited;
  unlimited.max_samples = SIZE_MAX;  // then the memory check: 4e10 samples do not fit
  const Status memory = read_height_field_raster(dir / "huge.tif", f, unlimited);
  ASSERT_FALSE(memory.ok);
  EXPECT_TRUE(has(memory, "huge.tif: a grid of 200000 x 200000 needs")) << memory.message;
  EXPECT_TRUE(has(memory, "of memory is available")) << memory.message;
  const std::string asc = "ncols 1000000000\nnrows 1000000000\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n";
  const Status text = parse_height_field_raster({reinterpret_cast<const uint8_t*>(asc.data()), asc.size()}, "big.asc", f);
  ASSERT_FALSE(text.ok);
  EXPECT_TRUE(has(text, "big.asc: ")) << text.message;
  EXPECT_EQ(f.width, 0u);
}

// Fuzzer finding: a 190-byte ESRI grid declaring 8,888,888 rows made GDAL allocate 71 MB while
// opening it (8 bytes per row). Text grids are sized against their file before GDAL sees them.
TEST(HeightFieldRaster, TextGridDeclaringMoreSamplesThanItsBytesIsRefusedBeforeGdal) {
  HeightFieldOptions unlimited;
  unlimited.max_samples = SIZE_MAX;
  auto parse = [&](const std::string& text, const std::string& name) {
    HeightField f;
    const Status st = parse_height_field_raster({reinterpret_cast<const uint8_t*>(text.data()), text.size()}, name, f,
                                                unlimited);
    EXPECT_EQ(f.width, st.ok ? f.width : 0u);
    return st;
  };
  const std::string esri = "ncols 2\nNROWS 8888888\xce" "88tRNS\nxllcorner 0\nyllcorner 0\ncellsize 25\n1 2\n3 4\n";
  const Status e = parse(esri, "rows.asc");
  ASSERT_FALSE(e.ok);
  EXPECT_TRUE(has(e, "rows.asc: text grid declares 2 x 8888888 samples, but the file has only")) << e.message;
  const std::string grass = "north: 3\nsouth: 0\neast: 3\nwest: 0\nrows: 900000\ncols: 3\n1 2 3\n4 5 6\n";
  const Status g = parse(grass, "grass.asc");
  ASSERT_FALSE(g.ok);
  EXPECT_TRUE(has(g, "grass.asc: text grid declares 3 x 900000 samples")) << g.message;
  const auto dir = test::temp_dir("raster_rows");
  test::write_text(dir / "rows.asc", esri);
  HeightField f;
  const Status from_file = read_height_field_raster(dir / "rows.asc", f, unlimited);
  ASSERT_FALSE(from_file.ok);
  EXPECT_TRUE(has(from_file, "rows.asc: text grid declares 2 x 8888888 samples")) << from_file.message;
  // Exactly as many samples as the text holds passes on to GDAL and reads.
  EXPECT_TRUE(parse("ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n3 4", "fits.asc").ok);
}

TEST(HeightFieldRaster, TruncatedAndGarbageFilesAreRefusedNamingThem) {
  const auto dir = test::temp_dir("raster_cut");
  TiffSpec s;
  s.width = s.height = 256;
  s.epsg = 0;
  write_tiff(dir / "whole.tif", s);
  std::vector<uint8_t> bytes = test::read_bytes(dir / "whole.tif");
  for (size_t keep : {bytes.size() / 2, size_t(600), size_t(9)}) {
    test::write_bytes(dir / "cut.tif", std::vector<uint8_t>(bytes.begin(), bytes.begin() + ptrdiff_t(keep)));
    HeightField f;
    const Status st = read_height_field_raster(dir / "cut.tif", f);
    ASSERT_FALSE(st.ok) << keep;
    EXPECT_TRUE(has(st, "cut.tif: ")) << st.message;
    EXPECT_EQ(f.width, 0u);
  }
  test::write_text(dir / "noise.dem", "this is not a raster\n");
  HeightField f;
  const Status st = read_height_field(dir / "noise.dem", f);
  ASSERT_FALSE(st.ok);
  EXPECT_TRUE(has(st, "noise.dem: not a raster GDAL can read")) << st.message;
  EXPECT_TRUE(has(read_height_field(dir / "absent.tif", f), "absent.tif: no such file"));
}

TEST(HeightFieldRaster, DriverListKeepsOtherFormatsOut) {
  const auto dir = test::temp_dir("raster_drivers");
  write_tiff(dir / "t.tif", {});
  HeightFieldOptions only_ascii;
  only_ascii.gdal_drivers = {"AAIGrid"};
  HeightField f;
  const Status st = read_height_field_raster(dir / "t.tif", f, only_ascii);
  ASSERT_FALSE(st.ok);
  EXPECT_TRUE(has(st, "t.tif: not a raster GDAL can read")) << st.message;
  only_ascii.gdal_drivers.push_back("GTiff");
  EXPECT_TRUE(read_height_field_raster(dir / "t.tif", f, only_ascii).ok);
}

TEST(HeightFieldRead, PicksTheReaderByExtension) {
  EXPECT_EQ(height_field_format_of("a/topography.txt"), HeightFieldFormat::text);
  EXPECT_EQ(height_field_format_of("a/t.XYZ"), HeightFieldFormat::text);
  EXPECT_EQ(height_field_format_of("a/t.txt.gz"), HeightFieldFormat::text);
  EXPECT_EQ(height_field_format_of("h.PNG"), HeightFieldFormat::png);
  EXPECT_EQ(height_field_format_of("N00E036.hgt"), HeightFieldFormat::raster);
  EXPECT_EQ(height_field_format_of("dem.tif"), HeightFieldFormat::raster);
}

}  // namespace
}  // namespace lod
