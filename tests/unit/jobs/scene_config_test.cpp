// SceneConfig: a good config parses into every field; each absurd value is refused with
// "file: key: why".
#include "jobs/scene_config.h"
#include "jobs/service.h"

#include <gtest/gtest.h>

#include "test_support.h"

namespace lod {
namespace {

namespace fs = std::filesystem;

// A folder with a config next to a tiny mesh, and a separate data directory.
struct ConfigDir {
  fs::path dir = test::temp_dir("scene-config");
  fs::path data = test::temp_dir("scene-config-data");
  ConfigDir() {
    test::write_text(dir / "ball.off", test::sphere_off(4, 6));
    test::write_text(data / "datamesh.off", test::sphere_off(3, 5));
  }
  fs::path write(const std::string& text, const std::string& name = "scene.toml") const {
    test::write_text(dir / name, text);
    return dir / name;
  }
};

// The smallest valid scene; tests append to or replace pieces of it.
const std::string kModel = "[[model]]\nname = \"ball\"\nfile = \"ball.off\"\n";
const std::string kInstances = "[[instances]]\nmodel = \"ball\"\ncount = 10\n";

Status load(const ConfigDir& d, const std::string& text, SceneConfig& out) {
  return load_scene_config(d.write(text), d.data, out);
}

// Refused, and the message names the file and the key.
void expect_refused(const std::string& text, const std::string& key, const std::string& why_part = "") {
  ConfigDir d;
  SceneConfig c;
  c.frames = 4242;
  const Status s = load(d, text, c);
  ASSERT_FALSE(s.ok) << "accepted:\n" << text;
  EXPECT_NE(s.message.find((d.dir / "scene.toml").string() + ": " + key + ":"), std::string::npos)
      << "message: " << s.message << "\nwanted key: " << key;
  if (!why_part.empty()) {
    EXPECT_NE(s.message.find(why_part), std::string::npos) << s.message;
  }
  EXPECT_EQ(c.frames, 4242u) << "out must be untouched on failure";
}

TEST(SceneConfig, ParsesEveryKeyOfAGoodConfig) {
  ConfigDir d;
  const std::string text = R"(
[run]
frames = 120
threads = 2
rate_hz = 30.5

[budget]
triangles = 123456
count = "levels"
reserve_blends = false

[lod]
pixel_error = 2.5
hysteresis = 0.5

[camera]
fov_deg = 70
width = 800
height = 600
path = "keyframes"
center = [1, 2, 3]
radius = 250
height_above = 12.5
period_frames = 90
near = 0.25
far = 3000

[[camera.keyframe]]
frame = 60
position = [10, 5, 0]
look_at = [0, 0, 0]

[[camera.keyframe]]
frame = 0
position = [0, 5, 10]
look_at = [0, 1, 0]

[[model]]
name = "ball"
file = "ball.off"
ratios = [1.0, 0.5, 0.25]
method = "extreme"
extreme_threshold = 5000
view_dependent = true
vd_parts = 4

[[model]]
name = "other"
file = "datamesh.off"
method = "qem"

[[instances]]
model = "other"
count = 7
placement = "grid"
box_min = [-10, 0, -20]
box_max = [10, 1, 20]
scale_range = [0.5, 2.0]
seed = 99

[[instances]]
model = "ball"
count = 3
scale = 4
)";
  SceneConfig c;
  const Status s = load(d, text, c);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(c.file, d.dir / "scene.toml");
  EXPECT_EQ(c.frames, 120u);
  EXPECT_EQ(c.threads, 2u);
  EXPECT_DOUBLE_EQ(c.rate_hz, 30.5);
  EXPECT_EQ(c.selection.budget, 123456u);
  EXPECT_EQ(c.selection.count, BudgetCount::levels);
  EXPECT_FALSE(c.selection.reserve_blends);
  EXPECT_FLOAT_EQ(c.pixel_error, 2.5f);
  EXPECT_FLOAT_EQ(c.hysteresis, 0.5f);
  EXPECT_FLOAT_EQ(c.camera.lens.fov_y_deg, 70);
  EXPECT_EQ(c.camera.lens.width, 800);
  EXPECT_EQ(c.camera.lens.height, 600);
  EXPECT_EQ(c.camera.kind, PathKind::keyframes);
  EXPECT_EQ(c.camera.center, glm::vec3(1, 2, 3));
  EXPECT_FLOAT_EQ(c.camera.radius, 250);
  EXPECT_FLOAT_EQ(c.camera.height_above, 12.5f);
  EXPECT_EQ(c.camera.period_frames, 90u);
  EXPECT_FLOAT_EQ(c.camera.lens.near_plane, 0.25f);
  EXPECT_FLOAT_EQ(c.camera.lens.far_plane, 3000);
  ASSERT_EQ(c.camera.keyframes.size(), 2u);
  EXPECT_EQ(c.camera.keyframes[0].frame, 0u) << "keyframes come out sorted by frame";
  EXPECT_EQ(c.camera.keyframes[0].position, glm::vec3(0, 5, 10));
  EXPECT_EQ(c.camera.keyframes[1].frame, 60u);
  EXPECT_EQ(c.camera.keyframes[1].look_at, glm::vec3(0, 0, 0));

  ASSERT_EQ(c.models.size(), 2u);
  EXPECT_EQ(c.models[0].name, "ball");
  EXPECT_EQ(c.models[0].file, d.dir / "ball.off") << "config folder first";
  EXPECT_EQ(c.models[0].bake.ratios, (std::vector<float>{1.0f, 0.5f, 0.25f}));
  EXPECT_EQ(c.models[0].bake.method, SimplifyMethod::extreme);
  EXPECT_EQ(c.models[0].bake.extreme_threshold, 5000u);
  EXPECT_TRUE(c.models[0].view_dependent);
  EXPECT_EQ(c.models[0].vd_parts, 4u);
  EXPECT_FALSE(c.models[1].view_dependent);
  EXPECT_EQ(c.models[1].vd_parts, 1u);
  EXPECT_EQ(c.models[1].file, d.data / "datamesh.off") << "then the data directory";
  EXPECT_TRUE(c.models[1].bake.ratios.empty()) << "absent ratios = defaults by size";
  EXPECT_EQ(c.models[1].bake.method, SimplifyMethod::qem);

  ASSERT_EQ(c.instances.size(), 2u);
  const InstanceConfig& a = c.instances[0];
  EXPECT_EQ(a.model, 1u);
  EXPECT_EQ(a.count, 7u);
  EXPECT_TRUE(a.grid);
  EXPECT_FLOAT_EQ(a.box_min[2], -20);
  EXPECT_FLOAT_EQ(a.box_max[1], 1);
  EXPECT_FLOAT_EQ(a.scale_min, 0.5f);
  EXPECT_FLOAT_EQ(a.scale_max, 2.0f);
  EXPECT_EQ(a.seed, 99u);
  const InstanceConfig& b = c.instances[1];
  EXPECT_EQ(b.model, 0u);
  EXPECT_FALSE(b.grid);
  EXPECT_FLOAT_EQ(b.scale_min, 4);
  EXPECT_FLOAT_EQ(b.scale_max, 4);
}

TEST(SceneConfig, MinimalConfigTakesTheDefaults) {
  ConfigDir d;
  SceneConfig c;
  ASSERT_TRUE(load(d, kModel + kInstances, c).ok);
  const SceneConfig defaults;
  EXPECT_EQ(c.frames, defaults.frames);
  EXPECT_EQ(c.threads, defaults.threads);
  EXPECT_EQ(c.selection.budget, defaults.selection.budget);
  EXPECT_EQ(c.selection.count, BudgetCount::triangles);
  EXPECT_TRUE(c.selection.reserve_blends);
  EXPECT_EQ(c.camera.kind, PathKind::orbit);
  EXPECT_EQ(c.instances[0].seed, 1u);
  EXPECT_FALSE(c.instances[0].grid);
}

TEST(SceneConfig, ShippedConfigsLoad) {
  // The repository's own configs must stay loadable (their meshes come from the build's data).
  const fs::path configs = fs::path(LOD_SOURCE_DIR) / "configs";
  if (!fs::is_directory(configs) || test::data_dir().empty())
    GTEST_SKIP() << "no configs/ or no extracted meshes";
  size_t loaded = 0;
  for (const auto& e : fs::directory_iterator(configs)) {
    if (e.path().extension() != ".toml") continue;
    SceneConfig c;
    const Status s = load_scene_config(e.path(), test::data_dir(), c);
    // A config may name ../shared scans that are absent; anything else is a bug.
    if (!s.ok && s.message.find("not found; tried") != std::string::npos) continue;
    EXPECT_TRUE(s.ok) << s.message;
    loaded += s.ok;
  }
  EXPECT_GT(loaded, 0u);
}

TEST(SceneConfig, SyntaxErrorNamesFileLineAndColumn) {
  ConfigDir d;
  SceneConfig c;
  const Status s = load(d, "[run]\nframes = 10\nthreads = = 2\n", c);
  ASSERT_FALSE(s.ok);
  EXPECT_EQ(s.message.rfind((d.dir / "scene.toml").string() + ":3:", 0), 0u) << s.message;
}

TEST(SceneConfig, MissingFileIsRefused) {
  SceneConfig c;
  const Status s = load_scene_config("/nonexistent/scene.toml", "", c);
  ASSERT_FALSE(s.ok);
  EXPECT_NE(s.message.find("/nonexistent/scene.toml"), std::string::npos);
}

TEST(SceneConfig, MissingMeshListsBothPlacesTried) {
  ConfigDir d;
  SceneConfig c;
  const Status s = load(d, "[[model]]\nname = \"x\"\nfile = \"nothere.off\"\n" + kInstances, c);
  ASSERT_FALSE(s.ok);
  EXPECT_NE(s.message.find("model[0].file"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find((d.dir / "nothere.off").string()), std::string::npos) << s.message;
  EXPECT_NE(s.message.find((d.data / "nothere.off").string()), std::string::npos) << s.message;
}

TEST(SceneConfig, MeshPathRelativeToTheConfigFolder) {
  ConfigDir d;
  fs::create_directories(d.dir / "meshes");
  test::write_text(d.dir / "meshes" / "sub.off", test::sphere_off(3, 4));
  SceneConfig c;
  ASSERT_TRUE(load(d, "[[model]]\nname = \"ball\"\nfile = \"meshes/sub.off\"\n" + kInstances, c).ok);
  EXPECT_EQ(c.models[0].file, d.dir / "meshes" / "sub.off");
}

TEST(SceneConfig, RefusesUnknownTopLevelKey) {
  expect_refused("[render]\nx = 1\n" + kModel + kInstances, "render", "unknown key");
}
TEST(SceneConfig, RefusesUnknownKeyInsideATable) {
  expect_refused("[run]\nframs = 10\n" + kModel + kInstances, "run.frams", "unknown key");
}
TEST(SceneConfig, RefusesZeroFrames) {
  expect_refused("[run]\nframes = 0\n" + kModel + kInstances, "run.frames");
}
TEST(SceneConfig, RefusesNegativeFrames) {
  expect_refused("[run]\nframes = -5\n" + kModel + kInstances, "run.frames");
}
TEST(SceneConfig, RefusesFramesOfTheWrongType) {
  expect_refused("[run]\nframes = \"ten\"\n" + kModel + kInstances, "run.frames", "integer");
}
TEST(SceneConfig, RefusesTooManyThreads) {
  expect_refused("[run]\nthreads = 1025\n" + kModel + kInstances, "run.threads");
}
TEST(SceneConfig, RefusesNegativeThreads) {
  expect_refused("[run]\nthreads = -1\n" + kModel + kInstances, "run.threads");
}
TEST(SceneConfig, RefusesZeroRate) {
  expect_refused("[run]\nrate_hz = 0\n" + kModel + kInstances, "run.rate_hz");
}
TEST(SceneConfig, RefusesZeroBudget) {
  expect_refused("[budget]\ntriangles = 0\n" + kModel + kInstances, "budget.triangles");
}
TEST(SceneConfig, RefusesReserveBlendsThatIsNotABoolean) {
  expect_refused("[budget]\nreserve_blends = 1\n" + kModel + kInstances, "budget.reserve_blends", "true or false");
}
TEST(SceneConfig, RefusesNegativeBudget) {
  expect_refused("[budget]\ntriangles = -100\n" + kModel + kInstances, "budget.triangles");
}
TEST(SceneConfig, RefusesUnknownBudgetCount) {
  expect_refused("[budget]\ncount = \"vertices\"\n" + kModel + kInstances, "budget.count");
}
TEST(SceneConfig, RefusesZeroPixelError) {
  expect_refused("[lod]\npixel_error = 0\n" + kModel + kInstances, "lod.pixel_error");
}
TEST(SceneConfig, RefusesNegativeHysteresis) {
  expect_refused("[lod]\nhysteresis = -0.1\n" + kModel + kInstances, "lod.hysteresis");
}
TEST(SceneConfig, RefusesZeroWidth) {
  expect_refused("[camera]\nwidth = 0\n" + kModel + kInstances, "camera.width");
}
TEST(SceneConfig, RefusesNegativeHeight) {
  expect_refused("[camera]\nheight = -720\n" + kModel + kInstances, "camera.height");
}
TEST(SceneConfig, RefusesHugeWidth) {
  expect_refused("[camera]\nwidth = 16385\n" + kModel + kInstances, "camera.width");
}
TEST(SceneConfig, RefusesFovOfOneDegree) {
  expect_refused("[camera]\nfov_deg = 1\n" + kModel + kInstances, "camera.fov_deg");
}
TEST(SceneConfig, RefusesFovOf179Degrees) {
  expect_refused("[camera]\nfov_deg = 179\n" + kModel + kInstances, "camera.fov_deg");
}
TEST(SceneConfig, RefusesNonFiniteFov) {
  expect_refused("[camera]\nfov_deg = nan\n" + kModel + kInstances, "camera.fov_deg", "finite");
}
TEST(SceneConfig, RefusesUnknownCameraPath) {
  expect_refused("[camera]\npath = \"spiral\"\n" + kModel + kInstances, "camera.path");
}
TEST(SceneConfig, RefusesFarBeforeNear) {
  expect_refused("[camera]\nnear = 10\nfar = 5\n" + kModel + kInstances, "camera.far");
}
TEST(SceneConfig, RefusesZeroVdParts) {
  expect_refused(kModel + "view_dependent = true\nvd_parts = 0\n" + kInstances, "model[0].vd_parts", "[1, 64]");
}
TEST(SceneConfig, RefusesVdPartsWithoutViewDependence) {
  expect_refused(kModel + "vd_parts = 4\n" + kInstances, "model[0].vd_parts", "view_dependent");
}
TEST(SceneConfig, RefusesZeroNear) {
  expect_refused("[camera]\nnear = 0\n" + kModel + kInstances, "camera.near");
}
TEST(SceneConfig, RefusesZeroPeriod) {
  expect_refused("[camera]\nperiod_frames = 0\n" + kModel + kInstances, "camera.period_frames");
}
TEST(SceneConfig, RefusesCenterWithTwoNumbers) {
  expect_refused("[camera]\ncenter = [1, 2]\n" + kModel + kInstances, "camera.center");
}
TEST(SceneConfig, RefusesKeyframePathWithoutKeyframes) {
  expect_refused("[camera]\npath = \"keyframes\"\n" + kModel + kInstances, "camera.keyframe");
}
TEST(SceneConfig, RefusesKeyframeWithoutPosition) {
  expect_refused("[[camera.keyframe]]\nframe = 0\nlook_at = [0, 0, 0]\n" + kModel + kInstances,
                 "camera.keyframe[0].position", "missing");
}
TEST(SceneConfig, RefusesKeyframeLookingAtItself) {
  expect_refused(
      "[[camera.keyframe]]\nframe = 0\nposition = [1, 1, 1]\nlook_at = [1, 1, 1]\n" + kModel + kInstances,
      "camera.keyframe[0].look_at");
}
TEST(SceneConfig, RefusesTwoKeyframesOnOneFrame) {
  const std::string k = "[[camera.keyframe]]\nframe = 5\nposition = [1, 1, 1]\nlook_at = [0, 0, 0]\n";
  expect_refused(k + k + kModel + kInstances, "camera.keyframe[1].frame", "twice");
}
TEST(SceneConfig, RefusesNoModels) { expect_refused(kInstances, "model"); }
TEST(SceneConfig, RefusesModelWithoutName) {
  expect_refused("[[model]]\nfile = \"ball.off\"\n" + kInstances, "model[0].name");
}
TEST(SceneConfig, RefusesModelNameWithASlash) {
  expect_refused("[[model]]\nname = \"a/b\"\nfile = \"ball.off\"\n" + kInstances, "model[0].name");
}
TEST(SceneConfig, RefusesDuplicateModelNames) {
  expect_refused(kModel + kModel + kInstances, "model[1].name", "twice");
}
TEST(SceneConfig, RefusesRatioAboveOne) {
  expect_refused(kModel + "ratios = [1.0, 1.5]\n" + kInstances, "model[0].ratios[1]");
}
TEST(SceneConfig, RefusesZeroRatioBeforeTheLast) {
  expect_refused(kModel + "ratios = [1.0, 0.0, 0.25]\n" + kInstances, "model[0].ratios[1]", "only be the last");
  expect_refused(kModel + "ratios = [0.0]\n" + kInstances, "model[0].ratios[0]");
}
TEST(SceneConfig, RefusesNegativeRatio) {
  expect_refused(kModel + "ratios = [1.0, -0.5]\n" + kInstances, "model[0].ratios[1]");
}
TEST(SceneConfig, RefusesIncreasingRatios) {
  expect_refused(kModel + "ratios = [1.0, 0.25, 0.5]\n" + kInstances, "model[0].ratios[2]", "decrease");
}
TEST(SceneConfig, RefusesRepeatedRatio) {
  expect_refused(kModel + "ratios = [1.0, 0.5, 0.5]\n" + kInstances, "model[0].ratios[2]");
}
TEST(SceneConfig, RefusesRatiosNotStartingAtOne) {
  expect_refused(kModel + "ratios = [0.5, 0.25]\n" + kInstances, "model[0].ratios[0]");
}
TEST(SceneConfig, RefusesEmptyRatios) {
  expect_refused(kModel + "ratios = []\n" + kInstances, "model[0].ratios");
}
TEST(SceneConfig, RefusesUnknownMethod) {
  expect_refused(kModel + "method = \"magic\"\n" + kInstances, "model[0].method");
}
TEST(SceneConfig, RefusesZeroExtremeThreshold) {
  expect_refused(kModel + "extreme_threshold = 0\n" + kInstances, "model[0].extreme_threshold");
}
TEST(SceneConfig, RefusesNoInstances) { expect_refused(kModel, "instances"); }
TEST(SceneConfig, RefusesUnknownModelName) {
  expect_refused(kModel + "[[instances]]\nmodel = \"cow\"\ncount = 1\n", "instances[0].model",
                 "unknown model \"cow\"");
}
TEST(SceneConfig, RefusesZeroCount) {
  expect_refused(kModel + "[[instances]]\nmodel = \"ball\"\ncount = 0\n", "instances[0].count");
}
TEST(SceneConfig, RefusesNegativeCount) {
  expect_refused(kModel + "[[instances]]\nmodel = \"ball\"\ncount = -3\n", "instances[0].count");
}
TEST(SceneConfig, RefusesMissingCount) {
  expect_refused(kModel + "[[instances]]\nmodel = \"ball\"\n", "instances[0].count", "missing");
}
TEST(SceneConfig, RefusesMoreThanTenMillionObjects) {
  const std::string block = "[[instances]]\nmodel = \"ball\"\ncount = 6000000\n";
  expect_refused(kModel + block + block, "instances[1].count", "10000000");
}
TEST(SceneConfig, RefusesUnknownPlacement) {
  expect_refused(kModel + kInstances + "placement = \"spiral\"\n", "instances[0].placement");
}
TEST(SceneConfig, RefusesInvertedBox) {
  expect_refused(kModel + kInstances + "box_min = [0, 0, 0]\nbox_max = [10, -1, 10]\n",
                 "instances[0].box_max", "on y");
}
TEST(SceneConfig, RefusesZeroScale) {
  expect_refused(kModel + kInstances + "scale = 0\n", "instances[0].scale");
}
TEST(SceneConfig, RefusesNegativeScale) {
  expect_refused(kModel + kInstances + "scale = -2\n", "instances[0].scale");
}
TEST(SceneConfig, RefusesScaleRangeStartingAtZero) {
  expect_refused(kModel + kInstances + "scale_range = [0.0, 2.0]\n", "instances[0].scale_range[0]");
}
TEST(SceneConfig, RefusesInvertedScaleRange) {
  expect_refused(kModel + kInstances + "scale_range = [2.0, 1.0]\n", "instances[0].scale_range[1]");
}
TEST(SceneConfig, RefusesScaleAndScaleRangeTogether) {
  expect_refused(kModel + kInstances + "scale = 1\nscale_range = [1.0, 2.0]\n", "instances[0].scale_range");
}
TEST(SceneConfig, RefusesNegativeSeed) {
  expect_refused(kModel + kInstances + "seed = -1\n", "instances[0].seed");
}

// Finite as double but 0 or infinity as the float they feed (the old reader took them and
// every frame then saw 0 objects): refused naming the key.
TEST(SceneConfig, RefusesValuesThatDoNotFitTheirFloat) {
  const std::string cam = "[camera]\n";
  expect_refused(kModel + kInstances + cam + "near = 1e-50\n", "camera.near", "does not fit the 32-bit float");
  expect_refused(kModel + kInstances + cam + "far = 1e39\n", "camera.far", "1e+39");
  expect_refused(kModel + kInstances + cam + "radius = 1e39\n", "camera.radius");
  expect_refused(kModel + kInstances + cam + "center = [0, 1e39, 0]\n", "camera.center[1]");
  expect_refused(kModel + kInstances + "scale = 1e39\n", "instances[0].scale");
  expect_refused(kModel + kInstances + "scale_range = [1e-40, 1.0]\n", "instances[0].scale_range[0]");
  expect_refused(kModel + kInstances + "box_max = [1e20, 0, 1]\n", "instances[0].box_max[0]");
  expect_refused("[lod]\npixel_error = 1e-30\n" + kModel + kInstances, "lod.pixel_error");
  // Zero and ordinary values are fine.
  ConfigDir d;
  SceneConfig c;
  ASSERT_TRUE(load(d, kModel + kInstances + "box_min = [-1e6, 0, -1e6]\nbox_max = [1e6, 0, 1e6]\n", c).ok);
}

// Blocks without a seed used to share seed 1: two blocks in one box put their objects on the
// same spots. Block 0 keeps seed 1; later blocks get distinct ones; a given seed is kept.
TEST(SceneConfig, InstanceBlocksWithoutASeedGetDistinctSeeds) {
  ConfigDir d;
  SceneConfig c;
  const std::string text = kModel + kInstances + kInstances + kInstances + kInstances + "seed = 1\n";
  const Status s = load(d, text, c);
  ASSERT_TRUE(s.ok) << s.message;
  ASSERT_EQ(c.instances.size(), 4u);
  EXPECT_EQ(c.instances[0].seed, 1u);
  EXPECT_NE(c.instances[1].seed, c.instances[0].seed);
  EXPECT_NE(c.instances[2].seed, c.instances[1].seed);
  EXPECT_NE(c.instances[2].seed, c.instances[0].seed);
  EXPECT_EQ(c.instances[3].seed, 1u);
  SceneConfig again;
  ASSERT_TRUE(load(d, text, again).ok);
  EXPECT_EQ(again.instances[1].seed, c.instances[1].seed);  // deterministic
}

TEST(SceneConfig, RefusesRepeatedRatios) {
  expect_refused(kModel + "ratios = [1.0, 0.5, 0.5]\n" + kInstances, "model[0].ratios[2]", "must decrease");
}

TEST(SceneConfig, DefaultDataDirIsTheCompiledInOne) { EXPECT_EQ(default_data_dir(), fs::path(LOD_DATA_DIR)); }

}  // namespace
}  // namespace lod

namespace lod {
namespace {

TEST(SceneConfigMotion, ParsesMotionAndSpeed) {
  ConfigDir d;
  SceneConfig c;
  const Status s = load(d, kModel + kInstances + "motion = \"wander\"\nspeed = 12.5\n", c);
  ASSERT_TRUE(s.ok) << s.message;
  ASSERT_EQ(c.instances.size(), 1u);
  EXPECT_EQ(c.instances[0].motion.kind, MotionKind::wander);
  EXPECT_EQ(c.instances[0].motion.speed, 12.5f);
  SceneConfig o;
  ASSERT_TRUE(load(d, kModel + kInstances + "motion = \"orbit\"\nspeed = 3\n", o).ok);
  EXPECT_EQ(o.instances[0].motion.kind, MotionKind::orbit);
  SceneConfig n;
  ASSERT_TRUE(load(d, kModel + kInstances, n).ok);
  EXPECT_EQ(n.instances[0].motion.kind, MotionKind::none);
}

TEST(SceneConfigMotion, RefusesBadMotion) {
  expect_refused(kModel + kInstances + "motion = \"teleport\"\nspeed = 1\n", "instances[0].motion", "wander");
  expect_refused(kModel + kInstances + "motion = \"wander\"\n", "instances[0].speed", "missing");
  expect_refused(kModel + kInstances + "motion = \"wander\"\nspeed = 0\n", "instances[0].speed", "(0, 1e6]");
  expect_refused(kModel + kInstances + "motion = \"orbit\"\nspeed = -3\n", "instances[0].speed");
  expect_refused(kModel + kInstances + "motion = \"orbit\"\nspeed = nan\n", "instances[0].speed");
  expect_refused(kModel + kInstances + "speed = 4\n", "instances[0].speed", "needs motion");
}

}  // namespace
}  // namespace lod

namespace lod {
namespace {

TEST(SceneConfigStrict, ParsesAndRefusesBudgetStrict) {
  ConfigDir d;
  SceneConfig c;
  ASSERT_TRUE(load(d, "[budget]\nstrict = true\n" + kModel + kInstances, c).ok);
  EXPECT_TRUE(c.selection.strict);
  expect_refused("[budget]\nstrict = 1\n" + kModel + kInstances, "budget.strict", "true or false");
  expect_refused("[budget]\nstrict = true\ncount = \"levels\"\n" + kModel + kInstances, "budget.strict", "triangles");
}

}  // namespace
}  // namespace lod

namespace lod {
namespace {

TEST(SceneConfigVisibility, ParsesAndRefusesOcclusionKeys) {
  ConfigDir d;
  SceneConfig c;
  ASSERT_TRUE(load(d, "[visibility]\nocclusion = true\noccluders = 12\n" + kModel + kInstances, c).ok);
  EXPECT_TRUE(c.occlusion);
  EXPECT_EQ(c.occluders, 12u);
  EXPECT_TRUE(frame_graph_options(c).occlusion.enabled);
  expect_refused("[visibility]\nocclusion = \"yes\"\n" + kModel + kInstances, "visibility.occlusion");
  expect_refused("[visibility]\noccluders = 0\n" + kModel + kInstances, "visibility.occluders");
  expect_refused("[visibility]\nhiz = 1\n" + kModel + kInstances, "visibility.hiz", "unknown key");
  EXPECT_FALSE(frame_graph_options(c).occlusion.make_tracer) << "raster by default";
  ASSERT_TRUE(load(d, "[visibility]\nocclusion = true\nocclusion_method = \"embree\"\n" + kModel + kInstances, c).ok);
  EXPECT_TRUE(frame_graph_options(c).occlusion.make_tracer);
  ASSERT_TRUE(load(d, "[visibility]\nocclusion_method = \"raster\"\n" + kModel + kInstances, c).ok);
  EXPECT_FALSE(frame_graph_options(c).occlusion.make_tracer);
  expect_refused("[visibility]\nocclusion_method = \"masked\"\n" + kModel + kInstances, "visibility.occlusion_method",
                 "\"raster\" or \"embree\"");
}

}  // namespace
}  // namespace lod

namespace lod {
namespace {

TEST(SceneConfigFiles, DirectoryOrFifoIsNotARegularFile) {
  ConfigDir d;
  SceneConfig c;
  const Status s = load_scene_config(d.dir, d.data, c);
  ASSERT_FALSE(s.ok);
  EXPECT_NE(s.message.find("not a regular file"), std::string::npos) << s.message;
  const fs::path missing = d.dir / "missing.toml";
  const Status m = load_scene_config(missing, d.data, c);
  ASSERT_FALSE(m.ok);
  EXPECT_NE(m.message.find(missing.string() + ": config file not found"), std::string::npos) << m.message;
}

TEST(SceneConfigFiles, ParsesTextLikeTheFile) {
  ConfigDir d;
  SceneConfig from_file, from_text;
  const std::string text = kModel + kInstances + "[budget]\ntriangles = 12345\n";
  ASSERT_TRUE(load_scene_config(d.write(text), d.data, from_file).ok);
  const Status s = parse_scene_config(text, d.dir / "scene.toml", d.data, from_text);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(from_text.selection.budget, 12345u);
  ASSERT_EQ(from_text.models.size(), 1u);
  EXPECT_EQ(from_text.models[0].file, from_file.models[0].file) << "mesh paths start at the config's folder";
}

// Found by the scene fuzz target: nested array-of-table brackets (an assert inside toml++'s
// header-only parser; the library lodkit links refuses them).
TEST(SceneConfigFiles, FuzzFindingsAreRefusedWithAPosition) {
  ConfigDir d;
  for (const char* text : {"[[[a]]", "[[[", "\xef\xbb\xbf[[[[#x\n"}) {
    SceneConfig c;
    const Status s = parse_scene_config(text, "fuzzed.toml", d.data, c);
    ASSERT_FALSE(s.ok) << text;
    EXPECT_EQ(s.message.rfind("fuzzed.toml:1:", 0), 0u) << s.message;
  }
}

TEST(SceneConfigBudgetModes, AcceptsACulledLastLevel) {
  ConfigDir d;
  SceneConfig c;
  ASSERT_TRUE(load(d, kModel + "ratios = [1.0, 0.5, 0.0]\n" + kInstances, c).ok);
  ASSERT_EQ(c.models[0].bake.ratios.size(), 3u);
  EXPECT_EQ(c.models[0].bake.ratios.back(), 0.0f);
  expect_refused(kModel + "ratios = [1.0, 0.5, 0.0]\nview_dependent = true\n" + kInstances, "model[0].ratios",
                 "view_dependent");
}

TEST(SceneConfigBudgetModes, ParsesAndRefusesMaxDistance) {
  ConfigDir d;
  SceneConfig c;
  ASSERT_TRUE(load(d, "[lod]\nmax_distance = 250\n" + kModel + kInstances, c).ok);
  EXPECT_EQ(c.max_distance, 250.f);
  EXPECT_EQ(frame_graph_options(c).max_distance, 250.f);
  SceneConfig none;
  ASSERT_TRUE(load(d, kModel + kInstances, none).ok);
  EXPECT_EQ(none.max_distance, 0.f) << "absent: no limit";
  expect_refused("[lod]\nmax_distance = 0\n" + kModel + kInstances, "lod.max_distance");
  expect_refused("[lod]\nmax_distance = -3\n" + kModel + kInstances, "lod.max_distance");
}

TEST(SceneConfigBudgetModes, ParsesAndRefusesSelector) {
  ConfigDir d;
  SceneConfig c;
  EXPECT_EQ(c.selection.selector, Selector::greedy) << "default";
  ASSERT_TRUE(load(d, "[budget]\nselector = \"greedy_multi\"\n" + kModel + kInstances, c).ok);
  EXPECT_EQ(c.selection.selector, Selector::greedy_multi);
  EXPECT_EQ(frame_graph_options(c).selection.selector, Selector::greedy_multi);
  ASSERT_TRUE(load(d, "[budget]\nselector = \"greedy\"\n" + kModel + kInstances, c).ok);
  EXPECT_EQ(c.selection.selector, Selector::greedy);
  ASSERT_TRUE(load(d, "[budget]\nselector = \"benefit_cost\"\n" + kModel + kInstances, c).ok);
  EXPECT_EQ(frame_graph_options(c).selection.selector, Selector::benefit_cost);
  expect_refused("[budget]\nselector = \"optimal\"\n" + kModel + kInstances, "budget.selector", "greedy_multi");
}


// HLOD models and the stream pager ([stream], hlod = true, min_verts).
const std::string kHlodModel = "[[model]]\nname = \"ball\"\nfile = \"ball.off\"\nhlod = true\n";
const std::string kOneInstance = "[[instances]]\nmodel = \"ball\"\ncount = 1\n";

TEST(SceneConfig, ParsesHlodModelAndStream) {
  ConfigDir d;
  SceneConfig c;
  const Status s = load(d, "[stream]\nbudget_mb = 3\nloader_threads = 4\n" + kHlodModel + "min_verts = 500\n" + kOneInstance, c);
  ASSERT_TRUE(s.ok) << s.message;
  ASSERT_EQ(c.models.size(), 1u);
  EXPECT_TRUE(c.models[0].hlod);
  EXPECT_EQ(c.models[0].min_verts, 500u);
  EXPECT_EQ(c.stream.budget_mb, 3u);
  EXPECT_EQ(c.stream.loader_threads, 4u);
}
TEST(SceneConfig, HlodAndStreamDefaults) {
  ConfigDir d;
  SceneConfig c;
  ASSERT_TRUE(load(d, kHlodModel + kOneInstance, c).ok);
  EXPECT_EQ(c.models[0].min_verts, 1000u);
  EXPECT_EQ(c.stream.budget_mb, 256u);
  EXPECT_EQ(c.stream.loader_threads, 2u);
  SceneConfig plain;
  ASSERT_TRUE(load(d, kModel + kInstances, plain).ok);
  EXPECT_FALSE(plain.models[0].hlod);
}
TEST(SceneConfig, RefusesHlodThatIsNotABoolean) {
  expect_refused(kModel + "hlod = 1\n" + kOneInstance, "model[0].hlod", "true or false");
}
TEST(SceneConfig, RefusesMinVertsWithoutHlod) { expect_refused(kModel + "min_verts = 500\n" + kInstances, "model[0].min_verts", "hlod"); }
TEST(SceneConfig, RefusesTinyMinVerts) { expect_refused(kHlodModel + "min_verts = 0\n" + kOneInstance, "model[0].min_verts"); }
TEST(SceneConfig, RefusesHlodViewDependentModel) {
  expect_refused(kHlodModel + "view_dependent = true\n" + kOneInstance, "model[0].hlod");
}
TEST(SceneConfig, RefusesHlodInstancesOfMoreThanOne) {
  expect_refused(kHlodModel + kInstances, "instances[0].count", "count = 1");
}
TEST(SceneConfig, RefusesZeroStreamBudget) { expect_refused("[stream]\nbudget_mb = 0\n" + kModel + kInstances, "stream.budget_mb"); }
TEST(SceneConfig, RefusesNegativeStreamBudget) {
  expect_refused("[stream]\nbudget_mb = -5\n" + kModel + kInstances, "stream.budget_mb");
}
TEST(SceneConfig, RefusesZeroLoaderThreads) {
  expect_refused("[stream]\nloader_threads = 0\n" + kModel + kInstances, "stream.loader_threads");
}
TEST(SceneConfig, RefusesUnknownStreamKey) {
  expect_refused("[stream]\nbudget = 5\n" + kModel + kInstances, "stream.budget", "unknown key");
}

}  // namespace
}  // namespace lod
