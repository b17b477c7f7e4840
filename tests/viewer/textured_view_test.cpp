// lod-viewer --screenshot of a textured, two-material glTF sphere (tests/textured_fixture.h):
// with materials (the default) its upper half shows both colours of the checker texture and
// its lower half the second material's red factor; with --color-by-level none of them; a
// normal texture shades its own material only.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <string>

#include "textured_fixture.h"
#include "viewer/picture_checks.h"
#include "viewer/viewer_harness.h"

namespace {

using lod::test::Image;

const char* kRun = "[run]\nframes = 1\nthreads = 1\n[budget]\ntriangles = 1000000\n";

const std::string kCamera = lod::test::front_camera(400, 300);

const char* kModel = R"([[model]]
name = "textured"
file = "textured/globe.gltf"
ratios = [1.0, 0.5]
)";

const std::string kInstance = lod::test::one_object_at_origin("textured", 9);

float srgb(float linear) { return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1 / 2.4f) - 0.055f; }

// The fixture's checker colours (0..255, sRGB as the image stores them) and the second
// material's base colour factor (linear, as glTF defines it; materials are lit in linear light
// and written sRGB-encoded, so the picture shows it encoded).
constexpr std::array<float, 3> kCheckerLight = {230, 200, 60};
constexpr std::array<float, 3> kCheckerDark = {40, 90, 160};
const std::array<float, 3> kBaseFactor = {srgb(0.8f), srgb(0.2f), srgb(0.1f)};

// Diffuse shading scales every channel alike: compare hues after dividing by the largest
// channel. Dim pixels (largest channel < 60) are left out, their rounding blurs the hue. The
// materials' specular part (white: 4 % of the sky on a dielectric) pales dark colours, so the
// checks that a colour is there allow `tolerance` 0.15; those that it is not keep 0.06.
bool same_hue(const uint8_t* px, std::array<float, 3> c, float tolerance) {
  const float pm = float(std::max({px[0], px[1], px[2]}));
  const float cm = std::max({c[0], c[1], c[2]});
  if (pm < 60) return false;
  for (int k = 0; k < 3; ++k)
    if (std::abs(float(px[k]) / pm - c[size_t(k)] / cm) > tolerance) return false;
  return true;
}
constexpr float kPresent = 0.15f, kAbsent = 0.06f;

struct HueCounts {
  int light_above = 0, dark_above = 0, base_below = 0, any_checker = 0, any_base = 0;
};

HueCounts count_hues(const Image& img, float tolerance) {
  HueCounts n;
  const int centre_row = lod::test::project({0, 0, 0}, img.width, img.height)[1];
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* px = img.at(x, y);
      const bool light = same_hue(px, kCheckerLight, tolerance), dark = same_hue(px, kCheckerDark, tolerance);
      const bool base = same_hue(px, kBaseFactor, tolerance);
      n.light_above += light && y < centre_row;
      n.dark_above += dark && y < centre_row;
      n.base_below += base && y > centre_row;
      n.any_checker += light || dark;
      n.any_base += base;
    }
  return n;
}

// The lit globe's three colours where they belong: both checker colours on the textured cap
// above the equator, the second material's factor below it; `where` names the picture.
void expect_checker_and_factor(const HueCounts& m, const std::string& where) {
  EXPECT_GE(m.light_above, 300) << "light checker squares " << where;
  EXPECT_GE(m.dark_above, 300) << "dark checker squares " << where;
  EXPECT_GE(m.base_below, 300) << "the untextured material's factor below the equator " << where;
}

// The two-material globe (24 x 48, faces outward) in the scene's textured/ folder; false when
// it could not be written.
bool write_globe(const lod::test::ViewerScene& scene, bool every_texture = false) {
  return !lod::test::write_two_material_gltf(scene.dir / "textured", "globe", 24, 48, every_texture,
                                             lod::test::SphereFaces::outward)
              .empty();
}

TEST(ViewerTextured, MaterialsShowTheTextureAndFactorColourByLevelDoesNot) {
  LOD_REQUIRE_XVFB();
  const auto scene = lod::test::write_viewer_scene("textured", kRun, kCamera, kInstance, kModel);
  ASSERT_TRUE(write_globe(scene));
  const auto lit = scene.dir / "materials.png";
  const auto levels = scene.dir / "levels.png";
  auto r = lod::test::run_viewer(scene, "--screenshot '" + lit.string() + "' --width 400 --height 300");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("lod-viewer: texture"), std::string::npos) << "the texture was not read: " << r.output;
  r = lod::test::run_viewer(scene, "--screenshot '" + levels.string() + "' --color-by-level --width 400 --height 300");
  ASSERT_EQ(r.exit_code, 0) << r.output;

  Image img;
  ASSERT_TRUE(lod::test::load_png(lit, img));
  expect_checker_and_factor(count_hues(img, kPresent), "on the textured cap");

  Image by_level;
  ASSERT_TRUE(lod::test::load_png(levels, by_level));
  const HueCounts c = count_hues(by_level, kAbsent);
  EXPECT_LE(c.any_checker, 10) << "colour-by-level must not show the texture";
  EXPECT_LE(c.any_base, 10) << "colour-by-level must not show the material factor";
}

// The globe written by lodkit's GLB exporter with the checker inside it (dir/globe.glb; no
// checker.png left beside it, so the picture's texture can only come from the embedded image).
void write_embedded_globe(const std::filesystem::path& dir, int rings, int segments) {
  std::filesystem::create_directories(dir);
  lod::MeshData m = lod::test::two_material_sphere(rings, segments);
  lod::test::turn_faces_outward(m);
  lod::test::write_bytes(dir / "checker.png", lod::test::checker_png(64, 8));
  lod::GltfMeshView view;
  view.name = "globe";
  view.positions = m.positions.data();
  view.vertex_count = m.vertex_count();
  view.uvs = m.uvs.data();
  view.indices = m.indices.data();
  view.index_count = m.indices.size();
  for (const lod::MeshMaterial& src : m.materials) {
    lod::GltfMaterialView g;
    g.name = src.name;
    std::copy(src.base_color, src.base_color + 4, g.base_color);
    g.metallic = src.metallic;
    g.roughness = src.roughness;
    g.double_sided = src.double_sided;
    view.materials.push_back(g);
  }
  view.materials[0].base_color_image = dir / "checker.png";
  for (const lod::Submesh& sm : m.submeshes)
    view.submeshes.push_back({3 * size_t(sm.first_triangle), 3 * size_t(sm.triangle_count), sm.material});
  ASSERT_TRUE(lod::save_gltf(dir / "globe.glb", view).ok);
  std::filesystem::remove(dir / "checker.png");
}

// The globe as a GLB whose checker PNG lives in the GLB's buffer (lodkit's exporter embeds it),
// the PNG file then deleted: the bake keeps the image in the asset (IMGS) and the viewer decodes
// it from memory, so the cap still shows both checker colours.
TEST(ViewerTextured, ATextureEmbeddedInTheGlbIsDecodedFromTheAsset) {
  LOD_REQUIRE_XVFB();
  const char* model = "[[model]]\nname = \"textured\"\nfile = \"textured/globe.glb\"\nratios = [1.0, 0.5]\n";
  const auto scene = lod::test::write_viewer_scene("textured-glb", kRun, kCamera, kInstance, model);
  write_embedded_globe(scene.dir / "textured", 24, 48);
  const auto lit = scene.dir / "embedded.png";
  const auto r = lod::test::run_viewer(scene, "--screenshot '" + lit.string() + "' --width 400 --height 300");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("lod-viewer: texture"), std::string::npos) << "every texture was decoded: " << r.output;
  EXPECT_EQ(r.output.find("drawn without it"), std::string::npos) << r.output;
  Image img;
  ASSERT_TRUE(lod::test::load_png(lit, img));
  const HueCounts c = count_hues(img, kPresent);
  std::printf("embedded checker: %d light and %d dark pixels above the equator, %d base below\n", c.light_above,
              c.dark_above, c.base_below);
  expect_checker_and_factor(c, "from the embedded image");
}

// The same globe drawn view-dependently: the front carries uvs and its triangles come grouped
// by material, so the picture shows the texture and the factor as the levels do.
TEST(ViewerTextured, ViewDependentGlobeShowsTheTextureAndFactorToo) {
  LOD_REQUIRE_XVFB();
  const std::string model = std::string(kModel) + "view_dependent = true\n";
  const auto scene = lod::test::write_viewer_scene("textured-vd", kRun, kCamera, kInstance, model.c_str());
  ASSERT_TRUE(write_globe(scene));
  const auto shot = lod::test::take_screenshot(scene, "vd", "--frames 3 --width 400 --height 300");
  ASSERT_EQ(shot.run.exit_code, 0) << shot.run.output;
  EXPECT_EQ(shot.run.output.find("lod-viewer: texture"), std::string::npos) << "the texture was not read: " << shot.run.output;
  ASSERT_TRUE(shot.stats_read);
  ASSERT_FALSE(shot.stats.rows.empty());
  EXPECT_EQ(shot.stats.last("vd_objects"), 1) << "drawn from its active front";
  ASSERT_TRUE(shot.image_read);
  expect_checker_and_factor(count_hues(shot.image, kPresent), "on the view-dependent cap");
}

// The same globe as an HLOD model: its nodes carry uvs and material runs, so the
// picture shows the texture and the factor as the levels do; colour-by-depth shows neither.
TEST(ViewerTextured, HlodGlobeShowsTheTextureAndFactorColourByDepthDoesNot) {
  LOD_REQUIRE_XVFB();
  const char* model = R"([[model]]
name = "textured"
file = "textured/globe.gltf"
hlod = true
min_verts = 300
)";
  const char* run = "[run]\nframes = 3\nthreads = 1\n[budget]\ntriangles = 1000000\n[lod]\npixel_error = 1.0\n";
  const auto scene = lod::test::write_viewer_scene("textured-hlod", run, kCamera, kInstance, model);
  ASSERT_FALSE(lod::test::write_two_material_gltf(scene.dir / "textured", "globe", 48, 96).empty());
  const auto depth = scene.dir / "depth.png";
  const auto shot = lod::test::take_screenshot(scene, "hlod", "--frames 3 --width 400 --height 300");
  ASSERT_EQ(shot.run.exit_code, 0) << shot.run.output;
  EXPECT_EQ(shot.run.output.find("lod-viewer: texture"), std::string::npos) << "the texture was not read: " << shot.run.output;
  ASSERT_TRUE(shot.stats_read);
  ASSERT_FALSE(shot.stats.rows.empty());
  EXPECT_GT(shot.stats.last("hlod_draws"), 0) << "drawn through its HLOD cut";
  EXPECT_EQ(shot.stats.last("hlod_missing"), 0);
  const auto r =
      lod::test::run_viewer(scene, "--screenshot '" + depth.string() + "' --frames 3 --color-by-level --width 400 --height 300");
  ASSERT_EQ(r.exit_code, 0) << r.output;

  ASSERT_TRUE(shot.image_read);
  expect_checker_and_factor(count_hues(shot.image, kPresent), "on the HLOD's textured cap");
  Image by_depth;
  ASSERT_TRUE(lod::test::load_png(depth, by_depth));
  const HueCounts c = count_hues(by_depth, kAbsent);
  EXPECT_LE(c.any_checker, 10) << "colour-by-depth must not show the texture";
  EXPECT_LE(c.any_base, 10) << "colour-by-depth must not show the material factor";
}

// The embedded-texture GLB as an HLOD model: the .hlod carries the PNG, and the nodes are drawn
// with it, decoded from the tree's images as a .lod's are from its chain's.
TEST(ViewerTextured, HlodOfAGlbShowsTheTextureEmbeddedInIt) {
  LOD_REQUIRE_XVFB();
  const char* model = R"([[model]]
name = "textured"
file = "textured/globe.glb"
hlod = true
min_verts = 300
)";
  const char* run = "[run]\nframes = 3\nthreads = 1\n[budget]\ntriangles = 1000000\n[lod]\npixel_error = 1.0\n";
  const auto scene = lod::test::write_viewer_scene("textured-hlod-glb", run, kCamera, kInstance, model);
  write_embedded_globe(scene.dir / "textured", 48, 96);
  const auto shot = lod::test::take_screenshot(scene, "hlod", "--frames 3 --width 400 --height 300");
  ASSERT_EQ(shot.run.exit_code, 0) << shot.run.output;
  EXPECT_EQ(shot.run.output.find("lod-viewer: texture"), std::string::npos) << "every texture was decoded: " << shot.run.output;
  EXPECT_EQ(shot.run.output.find("left out"), std::string::npos) << shot.run.output;
  ASSERT_TRUE(shot.stats_read);
  ASSERT_FALSE(shot.stats.rows.empty());
  EXPECT_GT(shot.stats.last("hlod_draws"), 0) << "drawn through its HLOD cut";
  ASSERT_TRUE(shot.image_read);
  const HueCounts c = count_hues(shot.image, kPresent);
  std::printf("HLOD embedded checker: %d light and %d dark pixels above the equator, %d base below\n", c.light_above,
              c.dark_above, c.base_below);
  expect_checker_and_factor(c, "from the .hlod's embedded image");
}

// The coloured sphere (north red shading to yellow, south blue) as one untextured surface,
// faces outward: COLOR_0 only, so glTF's default material (white) times the vertex colours.
std::filesystem::path write_coloured_globe(const std::filesystem::path& dir) {
  lod::MeshData m = lod::test::coloured_sphere(48, 96);
  lod::test::turn_faces_outward(m);
  std::filesystem::create_directories(dir);
  lod::GltfMeshView view;
  view.name = "painted";
  view.positions = m.positions.data();
  view.vertex_count = m.vertex_count();
  view.colors = m.colors.data();
  view.indices = m.indices.data();
  view.index_count = m.indices.size();
  const auto file = dir / "painted.gltf";
  return lod::save_gltf(file, view).ok ? file : std::filesystem::path();
}

// Pixels of the sphere's two vertex colours, above and below the equator: warm (red to orange:
// red full, some green, no blue) and pure blue (no red, no green).
struct Painted {
  int warm_above = 0, warm_below = 0, blue_above = 0, blue_below = 0;
};
Painted count_painted(const Image& img) {
  const int centre_row = lod::test::project({0, 0, 0}, img.width, img.height)[1];
  Painted n;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* px = img.at(x, y);
      const float pm = float(std::max({px[0], px[1], px[2]}));
      if (pm < 60) continue;
      const float r = px[0] / pm, g = px[1] / pm, b = px[2] / pm;
      const bool warm = r > 0.95f && g > 0.2f && g < 0.95f && b < 0.08f, blue = b > 0.95f && r < 0.08f && g < 0.08f;
      (y < centre_row ? n.warm_above : n.warm_below) += warm;
      (y < centre_row ? n.blue_above : n.blue_below) += blue;
    }
  return n;
}

// An HLOD model with vertex colours: its nodes are drawn with COLOR_0 multiplied into
// the base colour, so the picture shows the red north and the blue south; colour-by-depth
// shows neither.
TEST(ViewerTextured, HlodNodesShowTheirVertexColoursColourByDepthDoesNot) {
  LOD_REQUIRE_XVFB();
  const char* model = R"([[model]]
name = "textured"
file = "textured/painted.gltf"
hlod = true
min_verts = 300
)";
  const char* run = "[run]\nframes = 3\nthreads = 1\n[budget]\ntriangles = 1000000\n[lod]\npixel_error = 1.0\n";
  const auto scene = lod::test::write_viewer_scene("coloured-hlod", run, kCamera, kInstance, model);
  ASSERT_FALSE(write_coloured_globe(scene.dir / "textured").empty());
  const auto lit = scene.dir / "hlod.png";
  const auto depth = scene.dir / "depth.png";
  const auto stats = scene.dir / "hlod.csv";
  auto r = lod::test::run_viewer(scene, "--screenshot '" + lit.string() + "' --frames 3 --width 400 --height 300 --stats '" +
                                            stats.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  lod::test::CsvTable t;
  ASSERT_TRUE(lod::test::load_csv(stats, t));
  ASSERT_FALSE(t.rows.empty());
  EXPECT_GT(t.get(t.rows.size() - 1, "hlod_draws"), 0) << "drawn through its HLOD cut";
  EXPECT_EQ(t.get(t.rows.size() - 1, "hlod_missing"), 0);
  r = lod::test::run_viewer(scene, "--screenshot '" + depth.string() + "' --frames 3 --color-by-level --width 400 --height 300");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  Image img, by_depth;
  ASSERT_TRUE(lod::test::load_png(lit, img));
  ASSERT_TRUE(lod::test::load_png(depth, by_depth));
  const Painted lit_counts = count_painted(img), depth_counts = count_painted(by_depth);
  std::printf("HLOD vertex colours: warm %d above / %d below, blue %d above / %d below; by depth: %d %d %d %d\n",
              lit_counts.warm_above, lit_counts.warm_below, lit_counts.blue_above, lit_counts.blue_below,
              depth_counts.warm_above, depth_counts.warm_below, depth_counts.blue_above, depth_counts.blue_below);
  EXPECT_GE(lit_counts.warm_above, 1000) << "the red-to-orange north from COLOR_0";
  EXPECT_GE(lit_counts.blue_below, 1000) << "the blue south from COLOR_0";
  EXPECT_LE(lit_counts.warm_below + lit_counts.blue_above, 50) << "each half its own colour (the seam holds)";
  EXPECT_LE(depth_counts.warm_above + depth_counts.blue_below, 50) << "colour-by-depth must not show the vertex colours";
}

TEST(ViewerTextured, UnreadableTextureIsNamedOnceAndTheModelStillDrawn) {
  LOD_REQUIRE_XVFB();
  const auto scene = lod::test::write_viewer_scene("textured-bad", kRun, kCamera, kInstance, kModel);
  ASSERT_TRUE(write_globe(scene));
  // Bake first (the texture is not read by the bake), then break the image.
  const auto png = scene.dir / "out.png";
  auto r = lod::test::run_viewer(scene, "--screenshot '" + png.string() + "' --width 400 --height 300");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  lod::test::write_text(scene.dir / "textured" / "globe-image0.png", "not a png");
  r = lod::test::run_viewer(scene, "--screenshot '" + png.string() + "' --width 400 --height 300");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const size_t at = r.output.find("globe-image0.png");
  ASSERT_NE(at, std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("globe-image0.png", at + 1), std::string::npos) << "logged more than once: " << r.output;

  Image img;
  ASSERT_TRUE(lod::test::load_png(png, img));
  EXPECT_LE(count_hues(img, kAbsent).any_checker, 10) << "no texture colours without the texture";
  EXPECT_GE(count_hues(img, kPresent).base_below, 300) << "the rest of the model is still drawn";
}

// A normal texture changes the lit shading of the material that has it and nothing else:
// the same globe drawn with its normal image and with that image broken (drawn without it,
// said once) differs on many cap pixels and on none below the equator.
TEST(ViewerTextured, TheNormalTextureShadesItsMaterialOnly) {
  LOD_REQUIRE_XVFB();
  const auto scene = lod::test::write_viewer_scene("textured-normal", kRun, kCamera, kInstance, kModel);
  ASSERT_TRUE(write_globe(scene, /*every_texture=*/true));
  const auto mapped = scene.dir / "mapped.png";
  const auto plain = scene.dir / "plain.png";
  auto r = lod::test::run_viewer(scene, "--screenshot '" + mapped.string() + "' --width 400 --height 300");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("lod-viewer: texture"), std::string::npos) << "a texture was not read: " << r.output;
  lod::test::write_text(scene.dir / "textured" / "globe-image2.png", "not a png");  // the normal texture
  r = lod::test::run_viewer(scene, "--screenshot '" + plain.string() + "' --width 400 --height 300");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("globe-image2.png"), std::string::npos) << r.output;

  Image a, b;
  ASSERT_TRUE(lod::test::load_png(mapped, a));
  ASSERT_TRUE(lod::test::load_png(plain, b));
  ASSERT_EQ(a.rgb.size(), b.rgb.size());
  const int centre_row = lod::test::project({0, 0, 0}, a.width, a.height)[1];
  int changed_above = 0, changed_below = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const uint8_t *p = a.at(x, y), *q = b.at(x, y);
      const int d = std::max({std::abs(p[0] - q[0]), std::abs(p[1] - q[1]), std::abs(p[2] - q[2])});
      if (d <= 8) continue;
      if (y < centre_row - 4) ++changed_above;
      if (y > centre_row + 4) ++changed_below;
    }
  EXPECT_GE(changed_above, 1000) << "the normal texture shades the cap";
  EXPECT_EQ(changed_below, 0) << "the material without one is drawn as before";
}

}  // namespace

namespace {

// Sky and ground (--backdrop on): the eye is level with the globe's centre, so the rows above
// the globe are sky, darkening towards the zenith, and the rows below the horizon are ground,
// whose two tile shades both appear; --backdrop off keeps the flat background.
TEST(ViewerBackdrop, SkyGradientAboveGroundTilesBelowFlatWhenOff) {
  LOD_REQUIRE_XVFB();
  const auto scene = lod::test::write_viewer_scene("backdrop", kRun, kCamera, kInstance, kModel);
  ASSERT_TRUE(write_globe(scene));
  const auto on = scene.dir / "backdrop.png";
  const auto off = scene.dir / "flat.png";
  auto r = lod::test::run_viewer(scene, "--screenshot '" + on.string() + "' --width 400 --height 300 --backdrop on");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = lod::test::run_viewer(scene, "--screenshot '" + off.string() + "' --width 400 --height 300");
  ASSERT_EQ(r.exit_code, 0) << r.output;

  Image img;
  ASSERT_TRUE(lod::test::load_png(on, img));
  const int w = img.width, h = img.height;
  const uint8_t* top = img.at(5, 0);
  const uint8_t* near_horizon = img.at(5, h / 2 - 10);
  EXPECT_FALSE(lod::test::is_background(top));
  EXPECT_GT(top[2], top[0] + 40) << "the zenith is blue";
  EXPECT_GT(int(near_horizon[0]), int(top[0]) + 30) << "the sky lightens towards the horizon";
  // Ground: below the globe, near the bottom; two tile shades among its pixels.
  std::set<int> shades;
  for (int x = 0; x < w; ++x) {
    const uint8_t* px = img.at(x, h - 3);
    EXPECT_LT(std::abs(int(px[0]) - int(px[1])), 20) << "ground is grey-green at x " << x;
    shades.insert(px[1] / 8);
  }
  EXPECT_GE(shades.size(), 2u) << "the ground shows its tiles";
  EXPECT_LT(int(img.at(5, h - 3)[2]), int(top[2])) << "ground is not sky";

  Image flat;
  ASSERT_TRUE(lod::test::load_png(off, flat));
  EXPECT_TRUE(lod::test::is_background(flat.at(5, 0)));
  EXPECT_TRUE(lod::test::is_background(flat.at(5, flat.height - 3)));
}

}  // namespace

namespace {

// The statistics overlay (--overlay) at 1280 x 720: the pixels it changes against the same
// frame without it stay under a tenth of the picture (its panels start collapsed).
TEST(ViewerOverlay, CoversLessThanATenthOfThePicture) {
  LOD_REQUIRE_XVFB();
  const auto scene = lod::test::write_viewer_scene("overlay", kRun, kCamera, kInstance, kModel);
  ASSERT_TRUE(write_globe(scene));
  const auto with = scene.dir / "overlay.png";
  const auto without = scene.dir / "plain.png";
  auto r = lod::test::run_viewer(scene, "--screenshot '" + with.string() + "' --overlay --frames 3 --width 1280 --height 720");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = lod::test::run_viewer(scene, "--screenshot '" + without.string() + "' --frames 3 --width 1280 --height 720");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  Image a, b;
  ASSERT_TRUE(lod::test::load_png(with, a));
  ASSERT_TRUE(lod::test::load_png(without, b));
  ASSERT_EQ(a.rgb.size(), b.rgb.size());
  size_t changed = 0;
  for (size_t p = 0; p < a.rgb.size(); p += 3)
    changed += a.rgb[p] != b.rgb[p] || a.rgb[p + 1] != b.rgb[p + 1] || a.rgb[p + 2] != b.rgb[p + 2];
  const double fraction = double(changed) / double(a.width * a.height);
  EXPECT_GT(fraction, 0.005) << "the overlay is drawn";
  EXPECT_LT(fraction, 0.10) << "the overlay covers " << fraction * 100 << " % of the picture";
}

}  // namespace
