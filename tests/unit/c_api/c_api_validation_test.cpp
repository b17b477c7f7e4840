// The C API refuses what lodkit.h documents as invalid: a commit whose tick goes back (its
// staged changes kept for the next commit), settings that are NaN, infinite or outside their
// ranges, views whose field of view is outside [LOD_MIN_FOV_Y_DEG, LOD_MAX_FOV_Y_DEG]. Each
// refusal returns nonzero and leaves a message in lod_last_error(). Views at both ends of the
// field-of-view range, with a far plane of 1e9, cull exactly the objects outside them.
#include "lodkit/lodkit.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "test_support.h"

namespace {

namespace fs = std::filesystem;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// A config with one generated model (a UV sphere of radius 0.5 units once placed at scale
// 0.5) and its own cache folder, so nothing is written outside the test's folder.
fs::path sphere_scene() {
  const fs::path dir = lod::test::temp_dir("c-api-validation");
  lod::test::write_text(dir / "sphere.off", lod::test::sphere_off(24, 48));
  lod::test::write_text(dir / "scene.toml",
                        "[run]\nthreads = 2\n\n[budget]\ntriangles = 100000000\n\n[cache]\ndir = \"cache\"\n\n"
                        "[[model]]\nname = \"sphere\"\nfile = \"sphere.off\"\nratios = [1.0, 0.5, 0.25]\n");
  return dir / "scene.toml";
}

class Service {
 public:
  Service() {
    char error[512] = "";
    s_ = lod_service_create(sphere_scene().c_str(), error, sizeof error);
    EXPECT_NE(s_, nullptr) << error;
  }
  ~Service() { lod_service_destroy(s_); }
  Service(const Service&) = delete;
  Service& operator=(const Service&) = delete;
  lod_service* get() const { return s_; }

 private:
  lod_service* s_ = nullptr;
};

lod_transform at(float x, float y, float z) { return lod_transform{{x, y, z}, {0, 0, 0, 1}, 0.5f}; }

// The tick and the visible handles of the newest frame after one driven step.
struct Seen {
  uint64_t tick = 0, budget = 0;
  uint32_t objects = 0;
  std::set<lod_object> visible;
};

Seen step_and_read(lod_service* s) {
  Seen out;
  EXPECT_EQ(lod_step(s, 1.0 / 60), 0) << lod_last_error();
  const lod_frame* f = lod_frame_acquire(s);
  EXPECT_NE(f, nullptr) << lod_last_error();
  if (!f) return out;
  lod_frame_info info;
  lod_frame_info_get(f, &info);
  out.tick = info.tick;
  out.budget = info.budget;
  out.objects = info.objects;
  for (uint32_t i = 0; i < info.visible; ++i) {
    lod_frame_entry e;
    EXPECT_EQ(lod_frame_entry_get(f, i, &e), 0) << lod_last_error();
    out.visible.insert(e.object);
  }
  lod_frame_release(s, f);
  return out;
}

// Leaves a message that names none of the calls tested here, so a stale one cannot pass.
void reset_error() { lod_set_view_count(nullptr, 1); }

// Runs a refused call: nonzero, and a message naming the setting replaces the previous one.
template <class Call>
void expect_refused(const char* name, Call call, const std::string& what) {
  reset_error();
  EXPECT_NE(call(), 0) << name << " accepted " << what;
  const std::string message = lod_last_error();
  EXPECT_NE(message.find(name), std::string::npos) << what << ": " << message;
}

#define LOD_SERVICE(var) \
  Service var;           \
  ASSERT_NE(var.get(), nullptr)

TEST(CApiValidation, DecreasingTickIsRefusedAndItsChangesStayStaged) {
  LOD_SERVICE(service);
  lod_service* s = service.get();
  const lod_transform t = at(0, 0, 0);
  const lod_object a = lod_object_create(s, 0, &t);
  ASSERT_NE(a, 0u) << lod_last_error();
  ASSERT_EQ(lod_commit(s, 10), 0) << lod_last_error();
  EXPECT_EQ(step_and_read(s).tick, 10u);

  const lod_transform u = at(1, 0, 0);
  const lod_object b = lod_object_create(s, 0, &u);
  ASSERT_NE(b, 0u) << lod_last_error();
  for (uint64_t back : {uint64_t(5), uint64_t(0), uint64_t(9)}) {
    reset_error();
    EXPECT_NE(lod_commit(s, back), 0) << "tick " << back << " after 10 accepted";
    const std::string message = lod_last_error();
    EXPECT_NE(message.find("tick " + std::to_string(back)), std::string::npos) << message;
    EXPECT_NE(message.find("10"), std::string::npos) << message;
    const Seen seen = step_and_read(s);
    EXPECT_EQ(seen.tick, 10u) << "a refused commit must not reach frames";
    EXPECT_EQ(seen.objects, 1u) << "the staged create must stay staged";
  }
  ASSERT_EQ(lod_commit(s, 10), 0) << "an equal tick is accepted: " << lod_last_error();
  Seen seen = step_and_read(s);
  EXPECT_EQ(seen.tick, 10u);
  EXPECT_EQ(seen.objects, 2u) << "the staged create applies at the next valid commit";
  EXPECT_EQ(seen.visible.count(b), 1u);
  ASSERT_EQ(lod_commit(s, 11), 0) << lod_last_error();
  EXPECT_NE(lod_commit(s, 3), 0);
  seen = step_and_read(s);
  EXPECT_EQ(seen.tick, 11u);
}

TEST(CApiValidation, BudgetBelowOneIsRefusedAndKept) {
  LOD_SERVICE(service);
  lod_service* s = service.get();
  ASSERT_EQ(lod_set_budget(s, 12345), 0) << lod_last_error();
  expect_refused("set_budget", [&] { return lod_set_budget(s, 0); }, "0");
  EXPECT_NE(std::string(lod_last_error()).find("0"), std::string::npos);
  EXPECT_EQ(step_and_read(s).budget, 12345u) << "the refused budget must not replace the last one";
  EXPECT_EQ(lod_set_budget(s, LOD_MIN_BUDGET), 0) << lod_last_error();
  EXPECT_EQ(step_and_read(s).budget, uint64_t(LOD_MIN_BUDGET));
  EXPECT_EQ(lod_set_budget(s, UINT64_MAX), 0) << lod_last_error();
}

struct FloatSetter {
  const char* name;
  int (*set)(lod_service*, float);
  std::vector<float> refused, accepted;
};

TEST(CApiValidation, FloatSettersRefuseNanInfinityAndOutOfRange) {
  LOD_SERVICE(service);
  lod_service* s = service.get();
  const FloatSetter setters[] = {
      {"set_pixel_error", lod_set_pixel_error,
       {kNaN, kInf, -kInf, 0.0f, -0.0f, -1.0f, -1e-30f, 10000.5f, 1e30f},
       {1e-6f, 0.15f, 1.0f, LOD_MAX_PIXEL_ERROR}},
      {"set_hysteresis", lod_set_hysteresis,
       {kNaN, kInf, -kInf, -1e-6f, -1.0f, 10.001f, 1e30f},
       {0.0f, 0.25f, 1.0f, LOD_MAX_HYSTERESIS}},
      {"set_blend_seconds", lod_set_blend_seconds,
       {kNaN, kInf, -kInf, -1e-6f, -0.5f, 60.01f, 3600.0f},
       {0.0f, 0.25f, 5.0f, LOD_MAX_BLEND_SECONDS}},
  };
  for (const FloatSetter& f : setters) {
    for (float v : f.refused) {
      expect_refused(f.name, [&] { return f.set(s, v); }, std::to_string(v));
    }
    for (float v : f.accepted) {
      EXPECT_EQ(f.set(s, v), 0) << f.name << "(" << v << "): " << lod_last_error();
    }
  }
  EXPECT_EQ(lod_step(s, 1.0 / 60), 0) << lod_last_error();  // the service still runs
}

TEST(CApiValidation, NullServiceIsRefusedByEverySetter) {
  expect_refused("commit", [] { return lod_commit(nullptr, 1); }, "NULL");
  expect_refused("set_budget", [] { return lod_set_budget(nullptr, 1); }, "NULL");
  expect_refused("set_pixel_error", [] { return lod_set_pixel_error(nullptr, 1); }, "NULL");
  expect_refused("set_hysteresis", [] { return lod_set_hysteresis(nullptr, 0); }, "NULL");
  expect_refused("set_blend_seconds", [] { return lod_set_blend_seconds(nullptr, 0); }, "NULL");
}

lod_view view_looking_down_z(float fov, float far_z) {
  return lod_view{{0, 0, 0}, {0, 0, -1}, {0, 1, 0}, fov, 1280, 720, 0.1f, far_z};
}

TEST(CApiValidation, FieldOfViewOutsideItsRangeIsRefused) {
  LOD_SERVICE(service);
  lod_service* s = service.get();
  for (float fov : {kNaN, kInf, -kInf, 0.0f, -1.0f, 1e-20f, 0.000999f, 179.01f, 180.0f, 1e30f}) {
    const lod_view v = view_looking_down_z(fov, 1000);
    reset_error();
    EXPECT_NE(lod_set_view(s, 0, &v), 0) << "fov " << fov << " accepted";
    EXPECT_NE(std::string(lod_last_error()).find("fov_y_deg"), std::string::npos) << lod_last_error();
  }
  for (float fov : {LOD_MIN_FOV_Y_DEG, 1.0f, 60.0f, LOD_MAX_FOV_Y_DEG}) {
    const lod_view v = view_looking_down_z(fov, 1000);
    EXPECT_EQ(lod_set_view(s, 0, &v), 0) << "fov " << fov << ": " << lod_last_error();
  }
}

// Objects placed clearly inside or clearly outside a view (margins far above their radius of
// 0.5), for a camera at the origin looking down -z, 1280 x 720, near 0.1.
struct Placed {
  float x, y, z;
  bool inside;
};

void expect_culling_matches(lod_service* s, float fov, float far_z, const std::vector<Placed>& objects) {
  std::vector<lod_object> handles;
  for (const Placed& p : objects) {
    const lod_transform t = at(p.x, p.y, p.z);
    handles.push_back(lod_object_create(s, 0, &t));
    ASSERT_NE(handles.back(), 0u) << lod_last_error();
  }
  ASSERT_EQ(lod_commit(s, 1), 0) << lod_last_error();
  const lod_view v = view_looking_down_z(fov, far_z);
  ASSERT_EQ(lod_set_view(s, 0, &v), 0) << lod_last_error();
  const Seen seen = step_and_read(s);
  ASSERT_EQ(seen.objects, objects.size());
  size_t inside = 0;
  for (size_t i = 0; i < objects.size(); ++i) {
    const Placed& p = objects[i];
    inside += p.inside;
    EXPECT_EQ(seen.visible.count(handles[i]) == 1, p.inside)
        << "fov " << fov << ", far " << far_z << ": object at (" << p.x << ", " << p.y << ", " << p.z << ") should be "
        << (p.inside ? "visible" : "culled");
  }
  EXPECT_EQ(seen.visible.size(), inside);
}

TEST(CApiValidation, NarrowestFieldOfViewCullsExactlyWithAFarPlaneOf1e9) {
  LOD_SERVICE(service);
  // fov 0.001 degrees: at depth d the view is d * 8.7e-6 high and d * 1.55e-5 wide (half).
  expect_culling_matches(service.get(), LOD_MIN_FOV_Y_DEG, 1e9f,
                         {
                             {0, 0, -10, true},           // on the axis, near
                             {0, 0, -1e6f, true},         // on the axis, far
                             {0, 0, -9e8f, true},         // near the far plane
                             {10, 0, -1e6f, true},        // half width 15.5 there
                             {0, 6, -1e6f, true},         // half height 8.7 there
                             {0, 0, -2e9f, false},        // beyond the far plane
                             {0, 0, 10, false},           // behind the eye
                             {0, 0, 1e6f, false},         // far behind the eye
                             {5, 0, -100, false},         // half width 0.0016 there
                             {0, -5, -100, false},
                             {-30, 0, -1e6f, false},      // twice the half width
                             {0, 20, -1e6f, false},
                             {1000, 1000, -1000, false},  // what a 60-degree view would see
                             {40, 0, -1e3f, false},
                         });
}

TEST(CApiValidation, WidestFieldOfViewCullsExactlyWithAFarPlaneOf1e9) {
  LOD_SERVICE(service);
  // fov 179 degrees: the top and bottom planes are 0.5 degrees from the image plane; with the
  // 16:9 aspect the side planes are 0.28 degrees from it.
  expect_culling_matches(service.get(), LOD_MAX_FOV_Y_DEG, 1e9f,
                         {
                             {0, 0, -10, true},
                             {0, 0, -9e8f, true},
                             {100, 0, -10, true},      // 84 degrees off the axis
                             {-100, 0, -10, true},
                             {0, 50, -10, true},       // 79 degrees
                             {0, -500, -10, true},     // 88.9 degrees
                             {0, 0, -2e9f, false},     // beyond the far plane
                             {0, 0, 10, false},        // behind the eye
                             {100, 0, 10, false},
                             {0, 50, 5, false},
                             {0, 1000, -1, false},     // 89.94 degrees: 7.7 units above the top plane
                             {0, -1000, -1, false},
                             {3000, 0, -2, false},     // 89.96 degrees: 12.7 units right of the right plane
                             {0, 0, 1e6f, false},
                         });
}

}  // namespace
