// PNG heightmaps: 8-bit fixtures written with stb_image_write, 16-bit ones with GDAL's PNG
// driver (stb_image_write has no 16-bit PNG); values, orientation, alpha as no-data, hostile PNGs.
#include "preprocess/height_field_png.h"

#include <gdal.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "preprocess/height_field_read.h"
#include "test_support.h"

#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#endif
#include <stb_image_write.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace lod {
namespace {

bool has(const Status& st, const std::string& what) { return st.message.find(what) != std::string::npos; }

std::vector<uint8_t> png8(int w, int h, int comp, const std::vector<uint8_t>& px) {
  std::vector<uint8_t> out;
  stbi_write_png_to_func(
      [](void* ctx, void* data, int size) {
        auto* v = static_cast<std::vector<uint8_t>*>(ctx);
        v->insert(v->end(), static_cast<uint8_t*>(data), static_cast<uint8_t*>(data) + size);
      },
      &out, w, h, comp, px.data(), w * comp);
  return out;
}

// Pixel (c, r), r = 0 the top row.
uint8_t pixel8(int c, int r) { return uint8_t(10 * c + r); }

TEST(HeightFieldPng, EightBitGreyValuesWithTheTopRowNorth) {
  const int w = 6, h = 4;
  std::vector<uint8_t> px(w * h);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) px[r * w + c] = pixel8(c, r);
  const auto dir = test::temp_dir("png");
  test::write_bytes(dir / "h.png", png8(w, h, 1, px));
  HeightFieldOptions o;
  o.vertical_scale = 0.5f;
  HeightField f;
  const Status st = read_height_field(dir / "h.png", f, o);
  ASSERT_TRUE(st.ok) << st.message;
  ASSERT_EQ(f.width, 6u);
  ASSERT_EQ(f.height, 4u);
  EXPECT_FLOAT_EQ(f.vertical_scale, 0.5f);
  EXPECT_FLOAT_EQ(f.cell_size_x, 1.f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) EXPECT_FLOAT_EQ(f.at(x, y), float(pixel8(x, h - 1 - y))) << x << "," << y;
}

TEST(HeightFieldPng, SixteenBitValuesAreExact) {
  const int w = 5, h = 3;
  std::vector<uint16_t> px(w * h);
  for (int i = 0; i < w * h; ++i) px[i] = uint16_t(1000 + 4111 * i);  // up to 58,554
  const auto dir = test::temp_dir("png16");
  GDALAllRegister();
  GDALDatasetH mem = GDALCreate(GDALGetDriverByName("MEM"), "", w, h, 1, GDT_UInt16, nullptr);
  ASSERT_EQ(GDALRasterIO(GDALGetRasterBand(mem, 1), GF_Write, 0, 0, w, h, px.data(), w, h, GDT_UInt16, 0, 0), CE_None);
  GDALDatasetH png = GDALCreateCopy(GDALGetDriverByName("PNG"), (dir / "h16.png").c_str(), mem, FALSE, nullptr, nullptr, nullptr);
  ASSERT_NE(png, nullptr);
  GDALClose(png);
  GDALClose(mem);
  std::filesystem::remove(dir / "h16.png.aux.xml");
  HeightField f;
  const Status st = read_height_field_png(dir / "h16.png", f);
  ASSERT_TRUE(st.ok) << st.message;
  ASSERT_EQ(f.width, 5u);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) EXPECT_EQ(f.at(x, y), float(px[(h - 1 - y) * w + x])) << x << "," << y;
}

TEST(HeightFieldPng, AlphaZeroAndTheNoDataValueAreFilled) {
  const int w = 3, h = 3;
  std::vector<uint8_t> px(w * h * 2);
  for (int i = 0; i < w * h; ++i) px[2 * i] = 40, px[2 * i + 1] = 255;
  px[2 * 4] = 200, px[2 * 4 + 1] = 0;  // centre: transparent
  px[0] = 99;                          // top-left: the no-data value
  HeightFieldOptions o;
  o.no_data_value = 99;
  HeightField f;
  const Status st = parse_height_field_png(png8(w, h, 2, px), "a.png", f, o);
  ASSERT_TRUE(st.ok) << st.message;
  for (float v : f.heights) EXPECT_FLOAT_EQ(v, 40.f);
  std::vector<uint8_t> clear(w * h * 2, 0);
  const Status none = parse_height_field_png(png8(w, h, 2, clear), "clear.png", f);
  ASSERT_FALSE(none.ok);
  EXPECT_TRUE(has(none, "clear.png: every sample is no-data")) << none.message;
}

TEST(HeightFieldPng, ColourIsRefused) {
  HeightField f;
  const Status st = parse_height_field_png(png8(2, 2, 3, std::vector<uint8_t>(12, 7)), "c.png", f);
  ASSERT_FALSE(st.ok);
  EXPECT_TRUE(has(st, "c.png: colour PNG (3 channels)")) << st.message;
}

void put32(std::vector<uint8_t>& b, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) b.push_back(uint8_t(v >> s));
}

TEST(HeightFieldPng, HugeDeclaredSizeTruncationAndGarbageAreRefused) {
  // Headers declaring side x side 16-bit grey pixels and no image data: 20,000 passes stb's own
  // header check and meets the sample limit; 1,000,000 stb refuses itself.
  auto header = [](uint32_t side) {
    std::vector<uint8_t> b = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    put32(b, 13);
    b.insert(b.end(), {'I', 'H', 'D', 'R'});
    put32(b, side), put32(b, side);
    b.insert(b.end(), {16, 0, 0, 0, 0});
    put32(b, 0);  // crc (stb does not check it)
    put32(b, 0);
    b.insert(b.end(), {'I', 'E', 'N', 'D'});
    put32(b, 0);
    return b;
  };
  HeightField f;
  const Status big = parse_height_field_png(header(20000), "huge.png", f);
  ASSERT_FALSE(big.ok);
  EXPECT_TRUE(has(big, "huge.png: declares a grid of 20000 x 20000, more than the limit")) << big.message;
  const Status bigger = parse_height_field_png(header(1000000), "huger.png", f);
  ASSERT_FALSE(bigger.ok);
  EXPECT_TRUE(has(bigger, "huger.png: not a readable PNG")) << bigger.message;

  std::vector<uint8_t> px(64 * 64);
  for (size_t i = 0; i < px.size(); ++i) px[i] = uint8_t(i * 7);
  const std::vector<uint8_t> whole = png8(64, 64, 1, px);
  for (size_t keep : {whole.size() - 20, whole.size() / 2, size_t(40), size_t(5)}) {
    const Status st = parse_height_field_png({whole.data(), keep}, "cut.png", f);
    ASSERT_FALSE(st.ok) << keep;
    EXPECT_TRUE(has(st, "cut.png: ")) << st.message;
  }
  EXPECT_EQ(f.width, 0u);
  const std::string noise = "GIF89a not a png";
  EXPECT_TRUE(has(parse_height_field_png({reinterpret_cast<const uint8_t*>(noise.data()), noise.size()}, "n.png", f),
                  "n.png: not a PNG"));
  // Fuzzer finding: an IDAT declaring 1.1 GB in a 76-byte file made stb allocate that much.
  std::vector<uint8_t> liar = whole;
  const size_t idat = 8 + 25;  // after the signature and IHDR
  ASSERT_EQ(std::string(liar.begin() + idat + 4, liar.begin() + idat + 8), "IDAT");
  liar[idat] = 0x44, liar[idat + 1] = 0x53, liar[idat + 2] = 0x33, liar[idat + 3] = 0x12;
  const Status lie = parse_height_field_png(liar, "liar.png", f);
  ASSERT_FALSE(lie.ok);
  EXPECT_TRUE(has(lie, "liar.png: PNG chunk 'IDAT' at byte 33 declares 1146303250 bytes")) << lie.message;
  const auto dir = test::temp_dir("png_absent");
  EXPECT_TRUE(has(read_height_field(dir / "absent.png", f), "absent.png: no such file"));
}

// Fuzzer finding: an empty IDAT before the first one with data made stb call memcpy with a null
// destination (UBSan). Empty IDATs anywhere decode to the same heights as without them.
TEST(HeightFieldPng, EmptyImageDataChunksAreHarmless) {
  const int w = 9, h = 5;
  std::vector<uint8_t> px(w * h);
  for (size_t i = 0; i < px.size(); ++i) px[i] = uint8_t(i * 11 + 3);
  const std::vector<uint8_t> whole = png8(w, h, 1, px);
  const size_t idat = 8 + 25;
  ASSERT_EQ(std::string(whole.begin() + idat + 4, whole.begin() + idat + 8), "IDAT");
  const size_t after_idat = idat + 12 + (size_t(whole[idat + 2]) << 8 | whole[idat + 3]);
  std::vector<uint8_t> empty;
  put32(empty, 0);
  empty.insert(empty.end(), {'I', 'D', 'A', 'T'});
  put32(empty, 0x35af061e);  // the CRC of an empty IDAT
  std::vector<uint8_t> padded(whole.begin(), whole.begin() + idat);
  padded.insert(padded.end(), empty.begin(), empty.end());
  padded.insert(padded.end(), empty.begin(), empty.end());
  padded.insert(padded.end(), whole.begin() + idat, whole.begin() + after_idat);
  padded.insert(padded.end(), empty.begin(), empty.end());
  padded.insert(padded.end(), whole.begin() + after_idat, whole.end());
  HeightField plain, with_empty;
  ASSERT_TRUE(parse_height_field_png(whole, "plain.png", plain).ok);
  const Status st = parse_height_field_png(padded, "padded.png", with_empty);
  ASSERT_TRUE(st.ok) << st.message;
  ASSERT_EQ(with_empty.width, 9u);
  EXPECT_EQ(with_empty.heights, plain.heights);
  std::vector<uint8_t> only_empty(whole.begin(), whole.begin() + idat);
  only_empty.insert(only_empty.end(), empty.begin(), empty.end());
  only_empty.insert(only_empty.end(), whole.begin() + after_idat, whole.end());
  const Status none = parse_height_field_png(only_empty, "nodata.png", with_empty);
  ASSERT_FALSE(none.ok);
  EXPECT_TRUE(has(none, "nodata.png: PNG decoding failed")) << none.message;
}

}  // namespace
}  // namespace lod
