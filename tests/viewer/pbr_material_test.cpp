// lod-viewer's metallic-roughness shading, on a unit sphere (scale 9, normals outward) with one
// material, written as glTF at test time with solid-colour textures, each texture kind present
// and absent. The sun comes from (0.45, 0.8, 0.35): the lower left of the sphere as the front
// camera sees it faces away from it (ambient only), the upper right faces it. Checks are
// relations between pixels of pictures that differ in one material input.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>

#include <stb_image_write.h>  // Debian's libstb.so holds the implementation

#include "textured_fixture.h"
#include "viewer/picture_checks.h"
#include "viewer/viewer_harness.h"

namespace {

namespace fs = std::filesystem;
using lod::test::Image;

const char* kRun = "[run]\nframes = 1\nthreads = 1\n[budget]\ntriangles = 1000000\n";

const std::string kCamera = lod::test::front_camera(400, 300);

const char* kModel = "[[model]]\nname = \"ball\"\nfile = \"ball/ball.gltf\"\nratios = [1.0]\n";

const char* kInstance = R"([[instances]]
model = "ball"
count = 1
placement = "grid"
box_min = [0.0, 0.0, 0.0]
box_max = [0.0, 0.0, 0.0]
scale = 9.0
)";

// An 8 x 8 image of one colour.
void write_solid_png(const fs::path& file, uint8_t r, uint8_t g, uint8_t b) {
  std::array<uint8_t, 8 * 8 * 3> px{};
  for (size_t i = 0; i < px.size(); i += 3) px[i] = r, px[i + 1] = g, px[i + 2] = b;
  ASSERT_NE(stbi_write_png(file.string().c_str(), 8, 8, 3, px.data(), 8 * 3), 0) << file;
}

struct Solid {
  uint8_t r = 0, g = 0, b = 0;
};

// The material's textures by slot: each given one is a solid image.
struct Textures {
  const Solid* metallic_roughness = nullptr;
  const Solid* occlusion = nullptr;
  const Solid* emissive = nullptr;
};

// The unit sphere (normals outward) with one material, as glTF.
void write_ball(const fs::path& file, const lod::GltfMaterialView& material) {
  lod::MeshData m = lod::test::two_material_sphere(24, 48);
  lod::test::turn_faces_outward(m);  // glTF's front faces, as single-sided materials are culled
  const std::vector<float> normals = m.positions;  // a unit sphere's normals are its positions
  lod::GltfMeshView view;
  view.name = file.stem().string();
  view.positions = m.positions.data();
  view.vertex_count = m.vertex_count();
  view.normals = normals.data();
  view.uvs = m.uvs.data();
  view.indices = m.indices.data();
  view.index_count = m.indices.size();

  view.materials = {material};
  view.submeshes = {{0, m.indices.size(), 0}};
  const lod::Status saved = lod::save_gltf(file, view);
  EXPECT_TRUE(saved.ok) << saved.message;
}

// Renders the sphere with `material` (its image paths filled from `textures`).
Image render(const std::string& tag, lod::GltfMaterialView material, const Textures& textures,
             const std::string& args = "") {
  const auto scene = lod::test::write_viewer_scene("pbr-" + tag, kRun, kCamera, kInstance, kModel);
  const fs::path dir = scene.dir / "ball";
  fs::create_directories(dir);
  auto image = [&](const Solid* s, const char* name, fs::path& slot) {
    if (!s) return;
    write_solid_png(dir / name, s->r, s->g, s->b);
    slot = dir / name;
  };
  image(textures.metallic_roughness, "mr.png", material.metallic_roughness_image);
  image(textures.occlusion, "occlusion.png", material.occlusion_image);
  image(textures.emissive, "emissive.png", material.emissive_image);

  write_ball(dir / "ball.gltf", material);

  const fs::path png = scene.dir / "ball.png";
  const auto r = lod::test::run_viewer(scene, "--screenshot '" + png.string() + "' --width 400 --height 300 " + args);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("lod-viewer: texture"), std::string::npos) << "a texture was not read: " << r.output;
  Image img;
  EXPECT_TRUE(lod::test::load_png(png, img)) << png;
  return img;
}

// Mean brightness (channel mean) of the 5 x 5 pixels around where the sphere's surface point
// with outward normal `n` lands.
float brightness_at(const Image& img, glm::vec3 n) {
  const auto p = lod::test::project(9.f * glm::normalize(n), img.width, img.height);
  float sum = 0;
  for (int dy = -2; dy <= 2; ++dy)
    for (int dx = -2; dx <= 2; ++dx) {
      const uint8_t* px = img.at(std::clamp(p[0] + dx, 0, img.width - 1), std::clamp(p[1] + dy, 0, img.height - 1));
      sum += (float(px[0]) + float(px[1]) + float(px[2])) / 3;
    }
  return sum / 25;
}

const glm::vec3 kShadowSide = {-0.4f, -0.45f, 0.8f};  // faces away from the sun (n . l = -0.27): ambient only
const glm::vec3 kSunSide = {0.45f, 0.5f, 0.75f};     // faces the sun (n . l = 0.87)

// A dielectric grey: the reference every test changes one input of.
lod::GltfMaterialView grey() {
  lod::GltfMaterialView g;
  g.name = "grey";
  g.base_color[0] = g.base_color[1] = g.base_color[2] = 0.5f;
  g.metallic = 0;
  g.roughness = 1;
  return g;
}

bool have_images(const std::initializer_list<const Image*> images) {
  for (const Image* i : images)
    if (i->rgb.empty()) return false;
  return true;
}

// Emission is added to the lit colour: an emissive factor with a white emissive texture makes
// the dark side bright; the same factor with a black texture emits nothing (the texture
// multiplies the factor), and the factor with no texture emits by itself.
TEST(ViewerPbr, EmissiveTextureAndFactorLightTheShadowSide) {
  LOD_REQUIRE_XVFB();
  const Solid white{255, 255, 255}, black{0, 0, 0};
  lod::GltfMaterialView glow = grey();
  glow.emissive[0] = glow.emissive[1] = glow.emissive[2] = 1;
  lod::GltfMaterialView half = grey();
  half.emissive[0] = half.emissive[1] = half.emissive[2] = 0.25f;
  const Image plain = render("emissive-none", grey(), {});
  const Image lit = render("emissive-white", glow, {.emissive = &white});
  const Image dark = render("emissive-black", glow, {.emissive = &black});
  const Image factor = render("emissive-factor", half, {});
  ASSERT_TRUE(have_images({&plain, &lit, &dark, &factor}));
  const float p = brightness_at(plain, kShadowSide), l = brightness_at(lit, kShadowSide);
  const float d = brightness_at(dark, kShadowSide), f = brightness_at(factor, kShadowSide);
  std::printf("shadow side: no emission %.1f, white emissive texture %.1f, black texture %.1f, factor 0.25 %.1f\n", p, l,
              d, f);
  EXPECT_LT(p, 160) << "the side away from the sun is dim without emission";
  EXPECT_GE(l, 250) << "a white emissive texture with factor 1 saturates it";
  EXPECT_NEAR(d, p, 2) << "a black emissive texture cancels the factor";
  EXPECT_GT(f, p + 20) << "the factor alone emits";
  EXPECT_LT(f, l - 20);
}

// Occlusion darkens the ambient light only: a black occlusion texture at strength 1 leaves the
// shadow side (ambient only) black while the sun side keeps its direct light; strength 0.5 is
// in between; a white occlusion texture changes nothing.
TEST(ViewerPbr, OcclusionDarkensTheAmbientPartByItsStrength) {
  LOD_REQUIRE_XVFB();
  const Solid white{255, 255, 255}, black{0, 0, 0};
  lod::GltfMaterialView full = grey(), half = grey();
  full.occlusion_strength = 1;
  half.occlusion_strength = 0.5f;
  const Image plain = render("occlusion-none", grey(), {});
  const Image occluded = render("occlusion-black", full, {.occlusion = &black});
  const Image partly = render("occlusion-half", half, {.occlusion = &black});
  const Image open = render("occlusion-white", full, {.occlusion = &white});
  ASSERT_TRUE(have_images({&plain, &occluded, &partly, &open}));
  const float p = brightness_at(plain, kShadowSide), o = brightness_at(occluded, kShadowSide);
  const float h = brightness_at(partly, kShadowSide), w = brightness_at(open, kShadowSide);
  const float p_sun = brightness_at(plain, kSunSide), o_sun = brightness_at(occluded, kSunSide);
  std::printf("shadow side: no occlusion %.1f, black strength 1 %.1f, strength 0.5 %.1f, white %.1f; sun side %.1f -> %.1f\n",
              p, o, h, w, p_sun, o_sun);
  EXPECT_GT(p, 40) << "the ambient light reaches the shadow side";
  EXPECT_LE(o, 3) << "fully occluded, the shadow side gets no light";
  EXPECT_GT(h, o + 20);
  EXPECT_LT(h, p - 10);
  EXPECT_NEAR(w, p, 2) << "a white occlusion texture occludes nothing";
  EXPECT_GT(o_sun, 100) << "the sun's direct light is not occluded";
  EXPECT_LT(o_sun, p_sun) << "the sun side loses its ambient part";
}

// Brightest pixel and the count of near-white ones on the sphere.
struct Highlight {
  int max = 0, white = 0;
};
Highlight highlight(const Image& img) {
  Highlight h;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* px = img.at(x, y);
      const int v = std::min({px[0], px[1], px[2]});
      h.max = std::max(h.max, v);
      h.white += v >= 240;
    }
  return h;
}

// The metallic-roughness texture scales the factors (B metallic, G roughness): with factors
// 1 / 1, a texture of B = 1, G = 0.15 makes a smooth metal (a small white-hot highlight, no
// diffuse light: the sun side is darker than the dielectric's), B = 0 a rough dielectric
// (lit like the grey reference), and without a texture the factors give a rough metal (no
// highlight either).
TEST(ViewerPbr, MetallicRoughnessTextureScalesTheFactors) {
  LOD_REQUIRE_XVFB();
  const Solid smooth_metal{0, 38, 255}, rough_dielectric{0, 255, 0};
  lod::GltfMaterialView metal = grey();
  metal.base_color[0] = metal.base_color[1] = metal.base_color[2] = 0.6f;
  metal.metallic = 1;
  metal.roughness = 1;
  lod::GltfMaterialView dielectric = metal;
  dielectric.metallic = 0;
  const Image smooth = render("mr-smooth-metal", metal, {.metallic_roughness = &smooth_metal});
  const Image textured_dielectric = render("mr-dielectric", metal, {.metallic_roughness = &rough_dielectric});
  const Image factors = render("mr-factors", metal, {});
  const Image reference = render("mr-reference", dielectric, {});
  ASSERT_TRUE(have_images({&smooth, &textured_dielectric, &factors, &reference}));
  const Highlight hs = highlight(smooth), hd = highlight(textured_dielectric), hf = highlight(factors);
  const float s_shadow = brightness_at(smooth, kShadowSide), d_sun = brightness_at(textured_dielectric, kSunSide);
  const float r_sun = brightness_at(reference, kSunSide), f_sun = brightness_at(factors, kSunSide);
  const float s_sun = brightness_at(smooth, kSunSide);
  std::printf("smooth metal: max %d, %d near-white, sun side %.1f, shadow side %.1f; rough metal (factors): max %d, %d "
              "near-white, sun side %.1f; textured dielectric: max %d, sun side %.1f; dielectric factors: sun side %.1f\n",
              hs.max, hs.white, s_sun, s_shadow, hf.max, hf.white, f_sun, hd.max, d_sun, r_sun);
  EXPECT_GE(hs.max, 250) << "the smooth metal mirrors the sun";
  EXPECT_GE(hs.white, 3);
  EXPECT_LT(hs.white, 2000) << "in a small highlight";
  EXPECT_EQ(hd.white, 0) << "a rough dielectric has no such highlight";
  EXPECT_EQ(hf.white, 0) << "nor has the rough metal of the factors alone";
  EXPECT_LT(s_sun, d_sun - 30) << "off its highlight, a metal gets no diffuse light";
  EXPECT_NEAR(d_sun, r_sun, 3) << "B = 0 turns the metallic factor 1 into a dielectric";
  EXPECT_GT(std::abs(f_sun - s_sun), 5) << "the texture's roughness changes the response";
}

// Colour by level (C, --color-by-level) still colours the sphere by its level, whatever its
// material: the emissive sphere's shadow side is level 0's red, not white.
TEST(ViewerPbr, ColourByLevelIgnoresTheMaterial) {
  LOD_REQUIRE_XVFB();
  const Solid white{255, 255, 255};
  lod::GltfMaterialView glow = grey();
  glow.emissive[0] = glow.emissive[1] = glow.emissive[2] = 1;
  const Image img = render("levels", glow, {.emissive = &white}, "--color-by-level");
  ASSERT_TRUE(have_images({&img}));
  const auto p = lod::test::project(9.f * glm::normalize(kShadowSide), img.width, img.height);
  const uint8_t* px = img.at(p[0], p[1]);
  const auto& red = lod::viewer::level_colour(0);
  EXPECT_GT(px[0], 60) << "lit in level 0's colour";
  EXPECT_NEAR(float(px[1]) / float(px[0]), red[1] / red[0], 0.05) << "level 0's hue";
  EXPECT_NEAR(float(px[2]) / float(px[0]), red[2] / red[0], 0.05) << "level 0's hue";
}

// BLEND runs are drawn after the opaque ones: a half-transparent sphere in front of an opaque
// red one, listed (and batched) first, still shows the red one through it; an opaque blue
// sphere in its place hides it.
TEST(ViewerPbr, BlendedMaterialsAreDrawnOverTheOpaqueOnesBehind) {
  LOD_REQUIRE_XVFB();
  const char* models = "[[model]]\nname = \"glass\"\nfile = \"balls/glass.gltf\"\nratios = [1.0]\n\n"
                       "[[model]]\nname = \"red\"\nfile = \"balls/red.gltf\"\nratios = [1.0]\n";
  const char* instances = R"([[instances]]
model = "glass"
count = 1
placement = "grid"
box_min = [0.0, 0.0, 10.0]
box_max = [0.0, 0.0, 10.0]
scale = 4.0
[[instances]]
model = "red"
count = 1
placement = "grid"
box_min = [0.0, 0.0, -10.0]
box_max = [0.0, 0.0, -10.0]
scale = 9.0
)";
  auto centre = [&](const std::string& tag, float alpha, lod::AlphaMode mode) {
    const auto scene = lod::test::write_viewer_scene("pbr-" + tag, kRun, kCamera, instances, models);
    fs::create_directories(scene.dir / "balls");
    lod::GltfMaterialView glass = grey(), red = grey();
    glass.base_color[0] = glass.base_color[1] = 0.05f, glass.base_color[2] = 0.9f, glass.base_color[3] = alpha;
    glass.alpha_mode = mode;
    red.base_color[0] = 0.9f, red.base_color[1] = red.base_color[2] = 0.05f;
    write_ball(scene.dir / "balls" / "glass.gltf", glass);
    write_ball(scene.dir / "balls" / "red.gltf", red);
    const fs::path png = scene.dir / "balls.png";
    const auto r = lod::test::run_viewer(scene, "--screenshot '" + png.string() + "' --width 400 --height 300");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    Image img;
    EXPECT_TRUE(lod::test::load_png(png, img)) << png;
    std::array<int, 3> c{};
    if (img.rgb.empty()) return c;
    const uint8_t* px = img.at(img.width / 2, img.height / 2);
    for (int k = 0; k < 3; ++k) c[size_t(k)] = px[k];
    return c;
  };
  const auto blended = centre("blend", 0.4f, lod::AlphaMode::blend);
  const auto opaque = centre("blend-opaque", 1.f, lod::AlphaMode::opaque);
  std::printf("centre pixel: blended glass %d %d %d, opaque glass %d %d %d\n", blended[0], blended[1], blended[2], opaque[0],
              opaque[1], opaque[2]);
  EXPECT_GT(blended[0], 80) << "the red sphere shows through the blended one";
  EXPECT_GT(blended[2], 60) << "the blended sphere is drawn";
  EXPECT_LT(opaque[0], blended[0] - 30) << "an opaque sphere hides the red one";
}

}  // namespace
