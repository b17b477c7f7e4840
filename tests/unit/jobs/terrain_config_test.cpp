// [[terrain]] in the scene config, and the TerrainModel made from it (jobs/terrain_scene.h).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "jobs/scene_config.h"
#include "jobs/terrain_scene.h"
#include "synthetic_scene.h"
#include "test_support.h"

namespace lod {
namespace {

namespace fs = std::filesystem;

const std::string kObjects =
    "[[model]]\nname = \"ball\"\nfile = \"ball.off\"\n[[instances]]\nmodel = \"ball\"\ncount = 3\n";

// A folder holding a mesh and a 5 x 3 "x y z" height field in metres (10 m steps).
struct TerrainDir {
  fs::path dir = test::temp_dir("terrain-config");
  TerrainDir() {
    test::write_text(dir / "ball.off", test::sphere_off(3, 5));
    std::string grid;
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 5; ++x) grid += std::to_string(10 * x) + " " + std::to_string(10 * y) + " " + std::to_string(x + y) + "\n";
    test::write_text(dir / "hills.txt", grid);
  }
  Status load(const std::string& terrain, SceneConfig& out) const {
    test::write_text(dir / "scene.toml", kObjects + "[[terrain]]\n" + terrain);
    return load_scene_config(dir / "scene.toml", dir, out);
  }
};

void expect_refused(const std::string& terrain, const std::string& key, const std::string& why = "") {
  TerrainDir d;
  SceneConfig c;
  const Status s = d.load(terrain, c);
  ASSERT_FALSE(s.ok) << terrain;
  EXPECT_NE(s.message.find((d.dir / "scene.toml").string() + ": " + key + ":"), std::string::npos) << s.message;
  if (!why.empty()) EXPECT_NE(s.message.find(why), std::string::npos) << s.message;
  EXPECT_FALSE(c.terrain.has_value());
}

TEST(TerrainConfig, ParsesEveryKey) {
  TerrainDir d;
  SceneConfig c;
  const Status s = d.load(R"(file = "hills.txt"
coordinates = "metres"
cell_size = [2.0, 3.0]
vertical_scale = 4.0
no_data = -9999
placement = "corner"
position = [1, 2, 3]
samples = 9
pixel_error = 0.75
target = "triangles"
max_triangles = 5000
share = [0.1, 0.3, 0.6]
gdal_drivers = ["GTiff", "AAIGrid"]
)", c);
  ASSERT_TRUE(s.ok) << s.message;
  ASSERT_TRUE(c.terrain.has_value());
  const TerrainConfig& t = *c.terrain;
  EXPECT_EQ(t.file, d.dir / "hills.txt");
  EXPECT_EQ(t.cell_size[0], 2.f);
  EXPECT_EQ(t.cell_size[1], 3.f);
  EXPECT_EQ(t.vertical_scale, 4.f);
  EXPECT_EQ(t.no_data, -9999.0);
  EXPECT_FALSE(t.centered);
  EXPECT_EQ(t.position[2], 3.f);
  EXPECT_EQ(t.samples, 9u);
  EXPECT_EQ(t.pixel_error, 0.75f);
  EXPECT_EQ(t.target, RoamTarget::triangle_count);
  EXPECT_EQ(t.max_triangles, 5000u);
  EXPECT_EQ(t.min_share, 0.1f);
  EXPECT_EQ(t.initial_share, 0.3f);
  EXPECT_EQ(t.max_share, 0.6f);
  EXPECT_EQ(t.gdal_drivers, (std::vector<std::string>{"GTiff", "AAIGrid"}));
}

TEST(TerrainConfig, AbsentMeansNoTerrain) {
  TerrainDir d;
  test::write_text(d.dir / "plain.toml", kObjects);
  SceneConfig c;
  ASSERT_TRUE(load_scene_config(d.dir / "plain.toml", d.dir, c).ok);
  EXPECT_FALSE(c.terrain.has_value());
}

TEST(TerrainConfig, RefusesUnknownKey) { expect_refused("file = \"hills.txt\"\nheight = 3\n", "terrain[0].height", "unknown key"); }
TEST(TerrainConfig, RefusesMissingFile) { expect_refused("vertical_scale = 2\n", "terrain[0].file", "missing"); }
TEST(TerrainConfig, RefusesAFileThatIsNotThere) {
  expect_refused("file = \"nowhere.txt\"\n", "terrain[0].file", "not found");
}
TEST(TerrainConfig, RefusesTwoTerrains) {
  expect_refused("file = \"hills.txt\"\n[[terrain]]\nfile = \"hills.txt\"\n", "terrain[1]", "at most one");
}
TEST(TerrainConfig, RefusesSamplesNotTwoToTheNPlusOne) {
  expect_refused("file = \"hills.txt\"\nsamples = 100\n", "terrain[0].samples", "2^n + 1");
}
TEST(TerrainConfig, RefusesHugeSamples) { expect_refused("file = \"hills.txt\"\nsamples = 8193\n", "terrain[0].samples"); }
TEST(TerrainConfig, RefusesZeroCellSize) { expect_refused("file = \"hills.txt\"\ncell_size = 0\n", "terrain[0].cell_size"); }
TEST(TerrainConfig, RefusesNegativeVerticalScale) {
  expect_refused("file = \"hills.txt\"\nvertical_scale = -1\n", "terrain[0].vertical_scale");
}
TEST(TerrainConfig, RefusesUnknownCoordinates) {
  expect_refused("file = \"hills.txt\"\ncoordinates = \"utm\"\n", "terrain[0].coordinates");
}
TEST(TerrainConfig, RefusesUnknownPlacement) {
  expect_refused("file = \"hills.txt\"\nplacement = \"random\"\n", "terrain[0].placement");
}
TEST(TerrainConfig, RefusesSharesOutOfOrder) {
  expect_refused("file = \"hills.txt\"\nshare = [0.5, 0.2, 0.9]\n", "terrain[0].share", "min <= initial <= max");
}
TEST(TerrainConfig, RefusesUnknownTarget) { expect_refused("file = \"hills.txt\"\ntarget = \"speed\"\n", "terrain[0].target"); }
TEST(TerrainConfig, RefusesMalformedDriverLists) {
  expect_refused("file = \"hills.txt\"\ngdal_drivers = \"GTiff\"\n", "terrain[0].gdal_drivers", "expected an array");
  expect_refused("file = \"hills.txt\"\ngdal_drivers = []\n", "terrain[0].gdal_drivers", "is empty");
  expect_refused("file = \"hills.txt\"\ngdal_drivers = [\"GTiff\", 3]\n", "terrain[0].gdal_drivers[1]",
                 "expected a driver name");
  expect_refused("file = \"hills.txt\"\ngdal_drivers = [\"../GTiff\"]\n", "terrain[0].gdal_drivers[0]",
                 "is not a GDAL driver name");
}

TEST(TerrainConfig, TimeTargetTakesItsLimit) {
  TerrainDir d;
  SceneConfig c;
  ASSERT_TRUE(d.load("file = \"hills.txt\"\ntarget = \"time\"\nmax_ms = 0.25\n", c).ok);
  EXPECT_EQ(c.terrain->target, RoamTarget::time_limit);
  EXPECT_EQ(c.terrain->max_ms, 0.25f);
  TerrainModel m;
  ASSERT_TRUE(load_terrain_model(*c.terrain, 1.f, m).ok);
  EXPECT_EQ(m.target, RoamTarget::time_limit);
  EXPECT_EQ(m.max_ms, 0.25f);
}
TEST(TerrainConfig, RefusesATimeTargetWithoutALimit) {
  expect_refused("file = \"hills.txt\"\ntarget = \"time\"\n", "terrain[0].max_ms", "needs max_ms > 0");
}
TEST(TerrainConfig, RefusesANegativeTimeLimit) {
  expect_refused("file = \"hills.txt\"\nmax_ms = -1\n", "terrain[0].max_ms", "[0, 1000]");
}

TEST(TerrainModelLoad, ResamplesOntoTheRoamGridAndCentresIt) {
  TerrainDir d;
  SceneConfig c;
  ASSERT_TRUE(d.load("file = \"hills.txt\"\nposition = [100, 5, 200]\nvertical_scale = 2\n", c).ok);
  TerrainModel m;
  const Status s = load_terrain_model(*c.terrain, 1.5f, m);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(m.roam.size, 5u) << "smallest 2^n + 1 holding 5 x 3";
  EXPECT_EQ(m.pixel_error, 1.5f) << "tau from [lod] when the block has none";
  const glm::vec3 first = m.roam.positions.front(), last = m.roam.positions.back();
  EXPECT_FLOAT_EQ(first.x, 100.f - 20.f);  // 40 m wide, centred on x = 100
  EXPECT_FLOAT_EQ(first.z, 200.f - 10.f);  // 20 m deep
  EXPECT_FLOAT_EQ(last.x, 100.f + 20.f);
  EXPECT_FLOAT_EQ(first.y, 5.f);                  // height 0 at (0, 0)
  EXPECT_FLOAT_EQ(last.y, 5.f + 2.f * (4 + 2));  // the far corner's 6, scaled by 2
}

TEST(TerrainModelLoad, BadHeightFileIsNamed) {
  TerrainDir d;
  test::write_text(d.dir / "bad.txt", "0 0 1\n1 0 nan\n0 1 2\n1 1 3\n");
  SceneConfig c;
  ASSERT_TRUE(d.load("file = \"bad.txt\"\n", c).ok);
  TerrainModel m;
  const Status s = load_terrain_model(*c.terrain, 1, m);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("bad.txt"), std::string::npos) << s.message;
}

TEST(TerrainConfig, OnTerrainNeedsATerrainAndAStaticBlock) {
  TerrainDir d;
  SceneConfig c;
  test::write_text(d.dir / "scene.toml", kObjects + "on_terrain = true\n");
  Status s = load_scene_config(d.dir / "scene.toml", d.dir, c);
  ASSERT_FALSE(s.ok);
  EXPECT_NE(s.message.find("instances[0].on_terrain: the scene has no [[terrain]]"), std::string::npos) << s.message;
  test::write_text(d.dir / "scene.toml",
                   kObjects + "on_terrain = true\nmotion = \"wander\"\nspeed = 2\n[[terrain]]\nfile = \"hills.txt\"\n");
  s = load_scene_config(d.dir / "scene.toml", d.dir, c);
  ASSERT_FALSE(s.ok);
  EXPECT_NE(s.message.find("instances[0].on_terrain: needs a static block"), std::string::npos) << s.message;
}

TEST(TerrainPlacement, OnTerrainObjectsStandOnTheSurface) {
  TerrainDir d;
  SceneConfig c;
  // Two blocks: the first on the terrain, 1 m above it; the second as the box says.
  test::write_text(d.dir / "scene.toml",
                   "[[model]]\nname = \"ball\"\nfile = \"ball.off\"\n"
                   "[[instances]]\nmodel = \"ball\"\ncount = 20\nbox_min = [-20, 1, -10]\nbox_max = [20, 1, 10]\n"
                   "on_terrain = true\n"
                   "[[instances]]\nmodel = \"ball\"\ncount = 5\nbox_min = [-20, 3, -10]\nbox_max = [20, 3, 10]\n"
                   "[[terrain]]\nfile = \"hills.txt\"\nvertical_scale = 2\n");
  const Status s = load_scene_config(d.dir / "scene.toml", d.dir, c);
  ASSERT_TRUE(s.ok) << s.message;
  TerrainModel m;
  ASSERT_TRUE(load_terrain_model(*c.terrain, 1, m).ok);
  Scene scene = make_scene(c, {test::synthetic_chain("ball", {8, 4}, 0.01f, 1.f)});
  const std::vector<float> y0(scene.objects.y.begin(), scene.objects.y.end());
  const std::vector<float> cy0(scene.objects.cy.begin(), scene.objects.cy.end());
  EXPECT_EQ(place_on_terrain(scene, c, m), 20u);
  // The hills: height x + y (grid units) at 10 m steps, scaled by 2, centred on the origin.
  for (size_t i = 0; i < 25; ++i) {
    const float gx = (scene.objects.x[i] + 20) / 10, gy = (scene.objects.z[i] + 10) / 10;
    const float ground = 2 * (gx + gy);
    if (i < 20) {
      EXPECT_NEAR(scene.objects.y[i], 1 + ground, 1e-4) << i;
      EXPECT_NEAR(scene.objects.cy[i] - cy0[i], scene.objects.y[i] - y0[i], 1e-4) << "its sphere moved with it";
    } else {
      EXPECT_EQ(scene.objects.y[i], y0[i]) << "the second block stays where its box put it";
    }
  }
  EXPECT_FLOAT_EQ(terrain_height_at(m, -100, -100), 0.f) << "beyond the grid: the nearest edge";
}

TEST(TerrainModelLoad, ReadsAnEsriAsciiGridThroughGdal) {
  TerrainDir d;
  // 5 x 3 at 10 m, the same hills as hills.txt (the top text row is the north edge, y = 2).
  std::string asc = "ncols 5\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 10\n";
  for (int y = 2; y >= 0; --y) {
    for (int x = 0; x < 5; ++x) asc += std::to_string(x + y) + " ";
    asc += "\n";
  }
  test::write_text(d.dir / "hills.asc", asc);
  SceneConfig text, raster;
  ASSERT_TRUE(d.load("file = \"hills.txt\"\n", text).ok);
  ASSERT_TRUE(d.load("file = \"hills.asc\"\n", raster).ok);
  TerrainModel a, b;
  ASSERT_TRUE(load_terrain_model(*text.terrain, 1, a).ok);
  const Status s = load_terrain_model(*raster.terrain, 1, b);
  ASSERT_TRUE(s.ok) << s.message;
  ASSERT_EQ(a.roam.positions.size(), b.roam.positions.size());
  for (size_t i = 0; i < a.roam.positions.size(); ++i) {
    EXPECT_FLOAT_EQ(a.roam.positions[i].x, b.roam.positions[i].x);
    EXPECT_FLOAT_EQ(a.roam.positions[i].y, b.roam.positions[i].y) << i;
    EXPECT_FLOAT_EQ(a.roam.positions[i].z, b.roam.positions[i].z);
  }
}

// gdal_drivers reaches the reader: a list without the file's driver refuses it, naming the
// file; a name this GDAL lacks is said as such.
TEST(TerrainModelLoad, GdalDriverListDecidesWhoMayOpenTheRaster) {
  TerrainDir d;
  test::write_text(d.dir / "hills.asc", "ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 10\n1 2 3\n4 5 6\n");
  auto load = [&](const std::string& drivers) {
    SceneConfig c;
    const Status parsed = d.load("file = \"hills.asc\"\ngdal_drivers = " + drivers + "\n", c);
    EXPECT_TRUE(parsed.ok) << parsed.message;
    TerrainModel m;
    return parsed.ok ? load_terrain_model(*c.terrain, 1, m) : parsed;
  };
  EXPECT_TRUE(load("[\"GTiff\", \"AAIGrid\"]").ok);
  const Status other = load("[\"GTiff\"]");
  ASSERT_FALSE(other.ok);
  EXPECT_NE(other.message.find("hills.asc: not a raster GDAL can read"), std::string::npos) << other.message;
  const Status unknown = load("[\"AAIGrid\", \"NoSuchDriver\"]");
  ASSERT_FALSE(unknown.ok);
  EXPECT_NE(unknown.message.find("hills.asc: the allowed GDAL drivers name 'NoSuchDriver', which this GDAL does not have"),
            std::string::npos)
      << unknown.message;
}

}  // namespace
}  // namespace lod
