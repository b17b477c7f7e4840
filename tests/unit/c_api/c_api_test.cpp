// The C API (lodkit.h): every failure is a return value plus a message, never a crash or an
// exception; error buffers are always terminated and never written past their size; frames
// are held until released, exactly once.
#include "lodkit/lodkit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <thread>

#include "lodkit/types.hpp"
#include "test_support.h"

namespace {

namespace fs = std::filesystem;

// A one-model scene (the CGAL cow) with an absolute mesh path; empty when the mesh is absent.
fs::path cow_scene() {
  const fs::path cow = fs::path(LOD_DATA_DIR) / "cow.off";
  if (!fs::exists(cow)) return {};
  const fs::path dir = lod::test::temp_dir("c-api-scene");
  lod::test::write_text(dir / "scene.toml", "[run]\nthreads = 2\n\n[budget]\ntriangles = 100000\n\n[[model]]\n"
                                            "name = \"cow\"\nfile = \"" + cow.string() +
                                                "\"\nratios = [1.0, 0.5, 0.25]\n");
  return dir / "scene.toml";
}

#define LOD_REQUIRE_COW_SCENE(var)                                                  \
  const fs::path var = cow_scene();                                                 \
  if (var.empty()) GTEST_SKIP() << "needs " LOD_DATA_DIR "/cow.off (extracted by the configure step)"

lod_service* create_or_fail(const fs::path& scene) {
  char error[512] = "";
  lod_service* s = lod_service_create(scene.c_str(), error, sizeof error);
  EXPECT_NE(s, nullptr) << error;
  return s;
}

lod_view front_view() {
  return lod_view{{10, 2, 40}, {0, 0, -1}, {0, 1, 0}, 60, 1280, 720, 0.1f, 1000};
}

TEST(CApi, NullArgumentsFailWithAMessage) {
  char error[256] = "untouched";
  EXPECT_EQ(lod_service_create(nullptr, error, sizeof error), nullptr);
  EXPECT_NE(std::string(error).find("NULL"), std::string::npos) << error;
  EXPECT_NE(std::string(lod_last_error()).find("NULL"), std::string::npos);

  lod_model model = 0;
  const lod_transform t = {{0, 0, 0}, {0, 0, 0, 1}, 1};
  EXPECT_NE(lod_model_add(nullptr, "x.off", &model, error, sizeof error), 0);
  EXPECT_EQ(lod_model_level_count(nullptr, 0), 0u);
  EXPECT_EQ(lod_model_level_triangles(nullptr, 0, 0), 0u);
  EXPECT_EQ(lod_object_create(nullptr, 0, &t), 0u);
  EXPECT_NE(lod_object_destroy(nullptr, 1), 0);
  EXPECT_NE(lod_object_set_transform(nullptr, 1, &t), 0);
  EXPECT_NE(lod_set_view(nullptr, 0, nullptr), 0);
  EXPECT_NE(lod_set_view_count(nullptr, 1), 0);
  EXPECT_NE(lod_start(nullptr), 0);
  EXPECT_NE(lod_step(nullptr, 0.01), 0);
  EXPECT_EQ(lod_frame_acquire(nullptr), nullptr);
  lod_commit(nullptr, 1);
  lod_set_budget(nullptr, 1);
  lod_stop(nullptr);
  lod_frame_release(nullptr, nullptr);
  lod_service_destroy(nullptr);

  lod_frame_info info;
  std::memset(&info, 0xab, sizeof info);
  lod_frame_info_get(nullptr, &info);
  EXPECT_EQ(info.index, 0u);
  EXPECT_EQ(info.visible, 0u);
  lod_frame_entry entry;
  EXPECT_NE(lod_frame_entry_get(nullptr, 0, &entry), 0);
}

TEST(CApi, DefaultOptionsAreTheCppDefaults) {
  lod_object_options o;
  std::memset(&o, 0xab, sizeof o);
  lod_object_options_default(&o);
  const lod::ObjectOptions d;
  EXPECT_EQ(o.lod_bias, d.lod_bias);
  EXPECT_EQ(o.min_level, d.min_level);
  EXPECT_EQ(o.max_level, d.max_level);
  EXPECT_EQ(o.priority, d.priority);
  EXPECT_EQ(o.forced_level, d.forced_level);
  EXPECT_EQ(o.never_cull != 0, d.never_cull);
}

TEST(CApi, ErrorBuffersAreTerminatedAndNeverOverrun) {
  const std::string missing = (lod::test::temp_dir("c-api-missing") / "no-such-scene.toml").string();
  for (size_t size : {size_t(1), size_t(2), size_t(8), size_t(64), size_t(512)}) {
    char buffer[600];
    std::memset(buffer, 'X', sizeof buffer);
    EXPECT_EQ(lod_service_create(missing.c_str(), buffer, size), nullptr);
    const size_t len = strnlen(buffer, size);
    EXPECT_LT(len, size) << "not terminated within " << size;
    for (size_t k = size; k < sizeof buffer; ++k) ASSERT_EQ(buffer[k], 'X') << "written past " << size;
    if (size == 512) {
      EXPECT_NE(std::string(buffer).find("no-such-scene.toml"), std::string::npos) << buffer;
    }
  }
  EXPECT_EQ(lod_service_create(missing.c_str(), nullptr, 0), nullptr);  // no buffer at all
  EXPECT_NE(std::string(lod_last_error()).find("no-such-scene.toml"), std::string::npos);
}

TEST(CApi, LastErrorIsPerThread) {
  lod_commit(nullptr, 1);  // fails on this thread
  const std::string here = lod_last_error();
  ASSERT_FALSE(here.empty());
  std::string there_before, there_after;
  std::thread other([&] {
    there_before = lod_last_error();
    lod_set_view_count(nullptr, 3);
    there_after = lod_last_error();
  });
  other.join();
  EXPECT_EQ(there_before, "");
  EXPECT_NE(there_after.find("lod_set_view_count"), std::string::npos);
  EXPECT_EQ(std::string(lod_last_error()), here);
}

TEST(CApi, FramesCarryTheCommittedObjectsExactly) {
  LOD_REQUIRE_COW_SCENE(scene);
  lod_service* s = create_or_fail(scene);
  ASSERT_NE(s, nullptr);
  const uint32_t levels = lod_model_level_count(s, 0);
  ASSERT_GE(levels, 2u);
  EXPECT_GT(lod_model_level_triangles(s, 0, 0), lod_model_level_triangles(s, 0, levels - 1));
  EXPECT_EQ(lod_model_level_triangles(s, 0, levels), 0u);

  std::map<lod_object, lod_transform> placed;
  for (int i = 0; i < 6; ++i) {
    const float a = 0.3f * float(i);
    const lod_transform t = {{3.0f * float(i), 0.25f, -1.0f}, {0, std::sin(a), 0, std::cos(a)}, 1.0f + 0.1f * float(i)};
    const lod_object h = lod_object_create(s, 0, &t);
    ASSERT_NE(h, 0u) << lod_last_error();
    placed[h] = t;
  }
  lod_commit(s, 3);
  const lod_view v = front_view();
  ASSERT_EQ(lod_set_view(s, 0, &v), 0) << lod_last_error();
  ASSERT_EQ(lod_step(s, 1.0 / 60), 0) << lod_last_error();

  const lod_frame* f = lod_frame_acquire(s);
  ASSERT_NE(f, nullptr) << lod_last_error();
  lod_frame_info info;
  lod_frame_info_get(f, &info);
  EXPECT_EQ(info.tick, 3u);
  EXPECT_EQ(info.objects, placed.size());
  EXPECT_GT(info.visible, 0u);
  for (uint32_t i = 0; i < info.visible; ++i) {
    lod_frame_entry e;
    ASSERT_EQ(lod_frame_entry_get(f, i, &e), 0) << lod_last_error();
    ASSERT_TRUE(placed.count(e.object)) << "entry " << i << " has a handle never created";
    const lod_transform& t = placed[e.object];
    EXPECT_EQ(std::memcmp(&e.transform, &t, sizeof t), 0) << "entry " << i << ": transform not as set";
    EXPECT_LT(e.level, levels);
    EXPECT_NE(e.view_mask & 1u, 0u);
  }
  lod_frame_entry e;
  EXPECT_NE(lod_frame_entry_get(f, info.visible, &e), 0);
  lod_frame_release(s, f);
  lod_service_destroy(s);
}

TEST(CApi, StaleHandlesAndBadValuesAreRefused) {
  LOD_REQUIRE_COW_SCENE(scene);
  lod_service* s = create_or_fail(scene);
  ASSERT_NE(s, nullptr);
  const lod_transform t = {{0, 0, 0}, {0, 0, 0, 1}, 1};
  const lod_object h = lod_object_create(s, 0, &t);
  ASSERT_NE(h, 0u) << lod_last_error();
  EXPECT_EQ(lod_object_create(s, 99, &t), 0u);  // no such model
  const lod_transform bad_scale = {{0, 0, 0}, {0, 0, 0, 1}, 0};
  EXPECT_EQ(lod_object_create(s, 0, &bad_scale), 0u);
  EXPECT_EQ(lod_object_destroy(s, h), 0) << lod_last_error();
  EXPECT_NE(lod_object_destroy(s, h), 0);
  EXPECT_NE(lod_object_set_transform(s, h, &t), 0);
  EXPECT_NE(lod_object_destroy(s, 0), 0);

  const lod_object g = lod_object_create(s, 0, &t);
  ASSERT_NE(g, 0u);
  lod_object_options o;
  lod_object_options_default(&o);
  EXPECT_EQ(lod_object_set_options(s, g, &o), 0) << lod_last_error();
  o.min_level = 300;
  EXPECT_NE(lod_object_set_options(s, g, &o), 0);
  lod_object_options_default(&o);
  o.forced_level = -5;
  EXPECT_NE(lod_object_set_options(s, g, &o), 0);
  lod_object_options_default(&o);
  o.max_level = 100000;  // "coarsest there is"
  EXPECT_EQ(lod_object_set_options(s, g, &o), 0) << lod_last_error();

  const lod_view v = front_view();
  EXPECT_NE(lod_set_view(s, 8, &v), 0);
  EXPECT_NE(lod_set_view(s, 0, nullptr), 0);
  lod_view backwards = v;
  backwards.near_z = 10, backwards.far_z = 1;
  EXPECT_NE(lod_set_view(s, 0, &backwards), 0);
  EXPECT_NE(lod_set_view_count(s, 0), 0);
  EXPECT_NE(lod_set_view_count(s, 9), 0);
  EXPECT_EQ(lod_set_view(s, 1, &v), 0) << lod_last_error();
  EXPECT_EQ(lod_set_view_count(s, 2), 0) << lod_last_error();

  EXPECT_EQ(lod_start(s), 0) << lod_last_error();
  EXPECT_NE(lod_start(s), 0);
  EXPECT_NE(lod_step(s, 0.01), 0);  // not while running
  lod_stop(s);
  EXPECT_EQ(lod_step(s, 0.01), 0) << lod_last_error();
  lod_service_destroy(s);
}

TEST(CApi, AFrameIsReleasedExactlyOnceAndOnlyByItsService) {
  LOD_REQUIRE_COW_SCENE(scene);
  lod_service* a = create_or_fail(scene);
  lod_service* b = create_or_fail(scene);
  ASSERT_TRUE(a && b);
  const lod_view v = front_view();
  ASSERT_EQ(lod_set_view(a, 0, &v), 0);
  ASSERT_EQ(lod_step(a, 0.01), 0) << lod_last_error();
  const lod_frame* f = lod_frame_acquire(a);
  const lod_frame* g = lod_frame_acquire(a);  // consumers hold frames independently
  ASSERT_TRUE(f && g) << lod_last_error();
  EXPECT_EQ(lod_frame_acquire(b), nullptr);  // b never ran a frame

  lod_frame_release(b, f);  // not b's
  EXPECT_NE(std::string(lod_last_error()).find("not a frame"), std::string::npos) << lod_last_error();
  lod_frame_info info;
  lod_frame_info_get(f, &info);  // still held by a
  EXPECT_EQ(info.tick, 0u);
  lod_frame_release(a, f);
  lod_frame_release(a, f);  // twice
  EXPECT_NE(std::string(lod_last_error()).find("released already"), std::string::npos) << lod_last_error();
  lod_service_destroy(a);  // releases g, which the caller forgot
  lod_service_destroy(b);
}

}  // namespace
