// Selection through the C API when what the camera sees changes at once: a host whose camera
// turns from a busy, budget-bound view to the sky, to one object and back, at budgets that bind
// and budgets below the coarsest levels, gets a frame for every step.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "lodkit/lodkit.h"
#include "test_support.h"

namespace {

namespace fs = std::filesystem;

struct Host {
  lod_service* service = nullptr;
  lod_model model = 0;
  ~Host() { lod_service_destroy(service); }
};

// Twenty spheres of 4,720 triangles in a row along x, under a 20,000-triangle budget.
void make_host(Host& h, const std::string& selector) {
  const fs::path dir = lod::test::temp_dir("c-api-selection-" + selector);
  lod::test::write_text(dir / "ball.off", lod::test::sphere_off(40, 60));
  lod::test::write_text(dir / "scene.toml", "[run]\nthreads = 2\n\n[budget]\ntriangles = 20000\nselector = \"" +
                                                selector + "\"\n\n[[model]]\nname = \"ball\"\nfile = \"" +
                                                (dir / "ball.off").string() + "\"\nratios = [1.0, 0.5, 0.25, 0.12]\n");
  char error[512] = "";
  h.service = lod_service_create((dir / "scene.toml").c_str(), error, sizeof error);
  ASSERT_NE(h.service, nullptr) << error;
  ASSERT_EQ(lod_model_add(h.service, (dir / "ball.off").c_str(), &h.model, error, sizeof error), 0) << error;
  for (int k = 0; k < 20; ++k) {
    const lod_transform t = {{float(k) * 3.0f, 0, 0}, {0, 0, 0, 1}, 1};
    ASSERT_NE(lod_object_create(h.service, h.model, &t), 0u) << lod_last_error();
  }
  lod_commit(h.service, 1);
}

lod_frame_info step(Host& h, const lod_view& view, uint64_t budget) {
  lod_frame_info info{};
  EXPECT_EQ(lod_set_view(h.service, 0, &view), 0) << lod_last_error();
  lod_set_budget(h.service, budget);
  EXPECT_EQ(lod_step(h.service, 1.0 / 60), 0) << lod_last_error();
  const lod_frame* f = lod_frame_acquire(h.service);
  EXPECT_NE(f, nullptr);
  lod_frame_info_get(f, &info);
  uint64_t triangles = 0;
  for (uint32_t i = 0; i < info.visible; ++i) {
    lod_frame_entry e;
    EXPECT_EQ(lod_frame_entry_get(f, i, &e), 0);
    triangles += lod_model_level_triangles(h.service, h.model, e.level);
  }
  EXPECT_EQ(triangles, info.tris_selected);
  if (!info.over_budget) {
    EXPECT_LE(info.tris_selected, info.budget);
  }
  lod_frame_release(h.service, f);
  return info;
}

class CApiSelection : public ::testing::TestWithParam<const char*> {};

TEST_P(CApiSelection, CameraTurningAwayAfterABusyFrameGetsAFrame) {
  Host h;
  make_host(h, GetParam());
  if (HasFatalFailure()) return;
  const lod_view busy = {{28.5f, 2, 40}, {0, 0, -1}, {0, 1, 0}, 60, 1280, 720, 0.1f, 1000};
  const lod_view sky = {{28.5f, 2, 40}, {0, 1, 0}, {0, 0, 1}, 60, 1280, 720, 0.1f, 1000};
  const lod_view one = {{0, 0, 3}, {0, 0, -1}, {0, 1, 0}, 30, 1280, 720, 0.1f, 5};

  const lod_frame_info first = step(h, busy, 20000);
  ASSERT_EQ(first.visible, 20u);
  ASSERT_FALSE(first.over_budget);
  for (int round = 0; round < 2; ++round) {
    EXPECT_EQ(step(h, sky, 20000).visible, 0u);
    EXPECT_EQ(step(h, busy, 20000).visible, 20u);
    EXPECT_EQ(step(h, one, 20000).visible, 1u);
    EXPECT_EQ(step(h, sky, 20000).visible, 0u);
    EXPECT_TRUE(step(h, busy, 1).over_budget);
    EXPECT_EQ(step(h, sky, 1).visible, 0u);
    EXPECT_TRUE(step(h, one, 1).over_budget);
    EXPECT_EQ(step(h, busy, 20000).visible, 20u);
  }
}

INSTANTIATE_TEST_SUITE_P(EverySelector, CApiSelection, ::testing::Values("greedy", "greedy_multi", "benefit_cost"));

}  // namespace
