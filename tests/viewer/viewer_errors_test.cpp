// lod-viewer fails clearly, never by crashing: no display -> 2, bad config or assets -> 1.
#include <gtest/gtest.h>

#include "test_support.h"
#include "viewer/viewer_harness.h"

namespace {

const char* kRun = "[run]\nframes = 1\nthreads = 1\n";
const char* kCamera = "[camera]\npath = \"orbit\"\nradius = 30.0\n";
const char* kOne = "[[instances]]\nmodel = \"sphere\"\ncount = 1\n";

TEST(ViewerErrors, NoDisplayExitsTwoWithAMessage) {
  const auto scene = lod::test::write_viewer_scene("nodisplay", kRun, kCamera, kOne);
  const auto r = lod::test::run_viewer(scene, "--frames 1", /*under_xvfb=*/false,
                                       "env -u DISPLAY -u WAYLAND_DISPLAY");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("cannot open a display"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("xvfb-run"), std::string::npos) << "the message says how to run headless";
}

TEST(ViewerErrors, OpenGlOlderThan33ExitsTwoNamingTheVersion) {
  LOD_REQUIRE_XVFB();
  const auto scene = lod::test::write_viewer_scene("oldgl", kRun, kCamera, kOne);
  // Mesa honours this override; other drivers ignore it and the run succeeds.
  const auto r = lod::test::run_viewer(scene, "--screenshot '" + (scene.dir / "x.png").string() + "'", true,
                                       "MESA_GL_VERSION_OVERRIDE=3.0");
  if (r.exit_code == 0 && r.output.find("Mesa") == std::string::npos)
    GTEST_SKIP() << "the GL driver is not Mesa, so its version cannot be lowered";
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("OpenGL 3.3 is needed"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("3.0"), std::string::npos) << "the message names what the display offers";
  EXPECT_FALSE(std::filesystem::exists(scene.dir / "x.png"));
}

TEST(ViewerErrors, MissingMeshExitsOneNamingTheFile) {
  auto scene = lod::test::write_viewer_scene("nomesh", kRun, kCamera, kOne);
  lod::test::write_text(scene.config, std::string(kRun) + kCamera +
                                          "[[model]]\nname = \"ghost\"\nfile = \"not-there.off\"\n"
                                          "[[instances]]\nmodel = \"ghost\"\ncount = 1\n");
  const auto r = lod::test::run_viewer(scene, "--frames 1", /*under_xvfb=*/false, "env -u DISPLAY");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("not-there.off"), std::string::npos) << r.output;
}

TEST(ViewerErrors, MalformedMeshExitsOneNamingTheFile) {
  auto scene = lod::test::write_viewer_scene("badmesh", kRun, kCamera, kOne);
  // Face 0 names vertex 7 of 3.
  lod::test::write_text(scene.dir / "sphere.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  const auto r = lod::test::run_viewer(scene, "--frames 1", /*under_xvfb=*/false, "env -u DISPLAY");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("sphere.off"), std::string::npos) << r.output;
}

TEST(ViewerErrors, BadConfigKeyExitsOne) {
  auto scene = lod::test::write_viewer_scene("badkey", kRun, kCamera, kOne);
  lod::test::write_text(scene.config, "[run]\nframes = -3\n");
  const auto r = lod::test::run_viewer(scene, "--frames 1", /*under_xvfb=*/false, "env -u DISPLAY");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("config.toml"), std::string::npos) << r.output;
}

TEST(ViewerErrors, BadCommandLineExitsOne) {
  const auto scene = lod::test::write_viewer_scene("badargs", kRun, kCamera, kOne);
  EXPECT_EQ(lod::test::run_viewer(scene, "--frames 0", false, "env -u DISPLAY").exit_code, 1);
  EXPECT_EQ(lod::test::run_viewer(scene, "--width -5", false, "env -u DISPLAY").exit_code, 1);
  EXPECT_EQ(lod::test::run_viewer(scene, "--no-such-flag", false, "env -u DISPLAY").exit_code, 1);
}

}  // namespace
