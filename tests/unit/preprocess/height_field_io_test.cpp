#include "preprocess/height_field_io.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>
#include <sstream>

#include "runtime/roam.h"
#include "runtime/terrain_mesh_check.h"
#include "test_support.h"

namespace lod {
namespace {

float ground(int x, int y) { return 100.f + 3.f * float(x) - 2.f * float(y) + 0.5f * float(x * y); }

// A w x h grid with steps dx, dy starting at (x0, y0), samples in a shuffled order.
std::string grid_text(int w, int h, double x0, double y0, double dx, double dy, uint32_t seed = 1) {
  std::vector<std::string> lines;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::ostringstream l;
      l.precision(10);
      l << x0 + x * dx << ' ' << y0 + y * dy << ' ' << ground(x, y) << '\n';
      lines.push_back(l.str());
    }
  std::shuffle(lines.begin(), lines.end(), std::mt19937(seed));
  std::string text = "# generated\n\n";
  for (const auto& l : lines) text += l;
  return text;
}

Status parse(const std::string& text, HeightField& f, HeightFieldTextOptions o = {}) {
  return parse_height_field_text(text, "t.xyz", f, o);
}

TEST(HeightFieldText, ReadsAShuffledRegularGrid) {
  const auto dir = test::temp_dir("height_field_io");
  test::write_text(dir / "g.xyz", grid_text(7, 5, -30.0, 12.5, 2.5, 4.0));
  HeightField f;
  const Status st = read_height_field_text(dir / "g.xyz", f);
  ASSERT_TRUE(st.ok) << st.message;
  EXPECT_EQ(f.width, 7u);
  EXPECT_EQ(f.height, 5u);
  EXPECT_FLOAT_EQ(f.cell_size_x, 2.5f);
  EXPECT_FLOAT_EQ(f.cell_size_y, 4.f);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x) EXPECT_FLOAT_EQ(f.at(x, y), ground(x, y));
}

TEST(HeightFieldText, RefusesANonRegularGrid) {
  std::string text = grid_text(4, 4, 0, 0, 1, 1);
  text += "0.5 0.25 7\n";  // off the step in x and y
  HeightField f;
  const Status st = parse(text, f);
  ASSERT_FALSE(st.ok);
  EXPECT_NE(st.message.find("t.xyz"), std::string::npos) << st.message;
  EXPECT_NE(st.message.find("regular grid"), std::string::npos) << st.message;
  EXPECT_EQ(f.width, 0u);  // unchanged on error
}

TEST(HeightFieldText, RefusesAMissingOrRepeatedPoint) {
  std::string text = grid_text(3, 3, 0, 0, 1, 1, 2);
  HeightField f;
  const Status missing = parse(text.substr(0, text.rfind('\n', text.size() - 2) + 1), f);
  ASSERT_FALSE(missing.ok);
  EXPECT_NE(missing.message.find("8 samples for a grid of 3 x 3"), std::string::npos) << missing.message;
  const Status twice = parse(grid_text(3, 3, 0, 0, 1, 1).substr(0) + "1 1 5\n", f);
  ASSERT_FALSE(twice.ok);
  EXPECT_NE(twice.message.find("regular grid"), std::string::npos) << twice.message;
}

TEST(HeightFieldText, RefusesAnElevationBeyondAFloat) {
  HeightField f;
  const Status st = parse("0 0 1\n1 0 2\n0 1 1e39\n1 1 4\n", f);
  ASSERT_FALSE(st.ok);
  EXPECT_NE(st.message.find("t.xyz: line 3: elevation"), std::string::npos) << st.message;
}

TEST(HeightFieldText, RefusesNaNWithItsLine) {
  HeightField f;
  const Status st = parse("0 0 1\n1 0 2\n0 1 nan\n1 1 4\n", f);
  ASSERT_FALSE(st.ok);
  EXPECT_NE(st.message.find("t.xyz: line 3: value is not finite"), std::string::npos) << st.message;
}

TEST(HeightFieldText, RefusesEmptyAndGarbledInput) {
  HeightField f;
  Status st = parse("", f);
  ASSERT_FALSE(st.ok);
  EXPECT_NE(st.message.find("no samples"), std::string::npos) << st.message;
  st = parse("# only a comment\n\n", f);
  EXPECT_FALSE(st.ok);
  st = parse("0 0 1\n1 0\n", f);
  ASSERT_FALSE(st.ok);
  EXPECT_NE(st.message.find("line 2: expected three numbers"), std::string::npos) << st.message;
  st = parse("0 0 1 9\n", f);
  EXPECT_FALSE(st.ok);
  st = parse("0 0 1\n0 1 1\n0 2 1\n", f);  // one column: not 2-D
  ASSERT_FALSE(st.ok);
  EXPECT_NE(st.message.find("one x value"), std::string::npos) << st.message;
}

TEST(HeightFieldText, RefusesAHugeGridBeforeAllocating) {
  HeightField f;
  // Four samples whose spacing implies a 2e9-point grid.
  const Status st = parse("0 0 1\n0.01 0 1\n10000000 0 1\n0 1 1\n", f);
  ASSERT_FALSE(st.ok);
  EXPECT_NE(st.message.find("more than the limit"), std::string::npos) << st.message;
  HeightFieldTextOptions small;
  small.max_samples = 10;
  EXPECT_FALSE(parse(grid_text(4, 4, 0, 0, 1, 1), f, small).ok);
  EXPECT_TRUE(parse(grid_text(2, 5, 0, 0, 1, 1), f, small).ok);
}

TEST(HeightFieldText, FillsNoDataFromNeighbours) {
  std::string text;
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 5; ++x)
      text += std::to_string(x) + " " + std::to_string(y) + " " +
              ((x >= 1 && x <= 3 && y >= 1 && y <= 3) ? "-32768" : "10") + "\n";
  HeightFieldTextOptions o;
  o.no_data_value = -32768;
  HeightField f;
  const Status st = parse(text, f, o);
  ASSERT_TRUE(st.ok) << st.message;
  for (float h : f.heights) EXPECT_FLOAT_EQ(h, 10.f);  // the hole takes its rim's height
  std::string all;
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 2; ++x) all += std::to_string(x) + " " + std::to_string(y) + " -32768\n";
  const Status none = parse(all, f, o);
  ASSERT_FALSE(none.ok);
  EXPECT_NE(none.message.find("every sample is no-data"), std::string::npos);
}

TEST(HeightFieldText, ConvertsDegreesToMetresAboutTheMidLatitude) {
  HeightFieldTextOptions o;
  o.coordinates = GridCoordinates::degrees_lat_lon;
  HeightField f;
  // lat 59.9 .. 60.1 (mid 60), lon 10 .. 10.3, steps 0.1
  std::string text;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j)
      text += std::to_string(59.9 + 0.1 * i) + " " + std::to_string(10.0 + 0.1 * j) + " 5\n";
  const Status st = parse(text, f, o);
  ASSERT_TRUE(st.ok) << st.message;
  EXPECT_EQ(f.width, 4u);                            // longitude
  EXPECT_EQ(f.height, 3u);                           // latitude
  EXPECT_NEAR(f.cell_size_y, 11119.5f, 1.f);         // 0.1 degree of latitude
  EXPECT_NEAR(f.cell_size_x, 11119.5f * 0.5f, 1.f);  // times cos 60
}

TEST(HeightFieldText, RefusesLatitudesBeyondThePoles) {
  HeightFieldTextOptions o;
  o.coordinates = GridCoordinates::degrees_lon_lat;
  HeightField f;
  const Status st = parse("0 89 1\n1 89 1\n0 91 1\n1 91 1\n", f, o);
  ASSERT_FALSE(st.ok);
  EXPECT_NE(st.message.find("line 3: latitude outside"), std::string::npos) << st.message;
  EXPECT_TRUE(parse("0 88 1\n1 88 1\n0 89 1\n1 89 1\n", f, o).ok);
}

TEST(HeightFieldText, RefusesGzipWithAHint) {
  HeightField f;
  const Status st = read_height_field_text("nowhere/topography.txt.gz", f);
  ASSERT_FALSE(st.ok);
  EXPECT_NE(st.message.find("topography.txt.gz"), std::string::npos);
  EXPECT_NE(st.message.find("gzip"), std::string::npos);
  EXPECT_FALSE(read_height_field_text("nowhere/absent.xyz", f).ok);
}

// The deal.II step-53 SRTM topography (scripts/fetch-topography.sh), when fetched.
TEST(HeightFieldText, ReadsTheRealTopography) {
  const char* env = std::getenv("LOD_TOPOGRAPHY");
  const std::filesystem::path path =
      env ? std::filesystem::path(env)
          : std::filesystem::path(LOD_SOURCE_DIR) / "build" / "data" / "topography.txt";
  if (!std::filesystem::exists(path))
    GTEST_SKIP() << path << " absent: run scripts/fetch-topography.sh (or set LOD_TOPOGRAPHY)";
  HeightFieldTextOptions o;
  o.coordinates = GridCoordinates::degrees_lat_lon;
  HeightField f;
  const Status st = read_height_field_text(path, f, o);
  ASSERT_TRUE(st.ok) << st.message;
  EXPECT_EQ(f.sample_count(), 83600u);
  EXPECT_EQ(f.width, 220u);   // longitude 25 .. 35.95
  EXPECT_EQ(f.height, 380u);  // latitude -11.97 .. 6.98
  EXPECT_NEAR(f.cell_size_y, 5559.5f, 1.f);
  EXPECT_GT(f.cell_size_x, 5550.f);  // cos(mid latitude -2.5) ~ 0.999
  const auto [lo, hi] = std::minmax_element(f.heights.begin(), f.heights.end());
  EXPECT_LT(*lo, 1000.f);  // Lake Tanganyika / Malawi shores
  EXPECT_GT(*hi, 4000.f);  // Kilimanjaro, Rwenzori
  // Resampled to a ROAM grid, a low flight at a pixel error then at a triangle count: every
  // frame crack-free, the count within one diamond of its target.
  const RoamTerrain t = build_roam_terrain(resample_square(f, 257));
  RoamState s;
  roam_reset(s, t);
  RoamParams p;
  p.pixel_error = 1;
  std::vector<uint32_t> idx;
  for (int frame = 0; frame < 60; ++frame) {
    if (frame == 30) p.target = RoamTarget::triangle_count, p.triangle_count = 4000;
    View v;
    v.eye = t.positions[t.root] + glm::vec3(2000.f * float(frame), 3000, 1500.f * float(frame));
    v.target = v.eye + glm::vec3(1, -0.3f, 1);
    v.far_plane = 3e6f;
    v.near_plane = 10;
    const RoamFrameStats fs = roam_update(s, t, v, p);
    roam_triangles(idx, s, t);
    const TerrainMeshCheck c = check_terrain_mesh(idx, t.size);
    ASSERT_TRUE(c.ok()) << "frame " << frame << ": " << c.first_problem;
    EXPECT_GT(c.triangles, 1000u);
    if (frame < 30) continue;
    EXPECT_LE(fs.triangles, 4000u);
    EXPECT_GE(fs.triangles, 3998u);
  }
}

}  // namespace
}  // namespace lod
