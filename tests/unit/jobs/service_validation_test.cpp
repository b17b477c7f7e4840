// lod::Service refuses what service.hpp documents as invalid: a commit whose tick goes back
// (false, last_error(), the staged changes kept for the next commit) and runtime settings that
// are NaN, infinite or outside their ranges (false, last_error(), the setting unchanged).
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <string>

#include "jobs/service.h"
#include "jobs/service_impl.h"
#include "unit/jobs/service_fixture.h"

namespace lod {
namespace {

using test::DynamicService;
using test::entry_of;
using test::placed;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

TEST(ServiceValidation, DecreasingTickIsRefusedAndTheStagedChangesApplyLater) {
  DynamicService d;
  Service& s = d.service();
  const ObjectHandle a = s.create(0, placed(0, 0, 0));
  ASSERT_TRUE(s.commit(10)) << s.last_error();
  const ObjectHandle b = s.create(1, placed(2, 0, 0));
  ASSERT_TRUE(s.destroy(a));
  for (uint64_t back : {uint64_t(5), uint64_t(0), uint64_t(3), uint64_t(9)}) {
    EXPECT_FALSE(s.commit(back)) << "tick " << back << " after 10";
    const std::string why = s.last_error();
    EXPECT_NE(why.find("tick " + std::to_string(back)), std::string::npos) << why;
    EXPECT_NE(why.find("10"), std::string::npos) << why;
    ASSERT_TRUE(s.step(0.01));
    const FrameRef f = s.acquire_frame();
    EXPECT_EQ(f->tick, 10u);
    EXPECT_EQ(f->object_count, 1u);
    EXPECT_GE(entry_of(*f, a), 0) << "the staged destroy must not apply";
    EXPECT_LT(entry_of(*f, b), 0) << "the staged create must not apply";
  }
  EXPECT_EQ(s.stats().commits, 2u) << "the tick-0 commit of the objects and tick 10; refusals not counted";
  ASSERT_TRUE(s.commit(12)) << s.last_error();
  ASSERT_TRUE(s.step(0.01));
  const FrameRef f = s.acquire_frame();
  EXPECT_EQ(f->tick, 12u);
  EXPECT_EQ(f->object_count, 1u);
  EXPECT_LT(entry_of(*f, a), 0);
  EXPECT_GE(entry_of(*f, b), 0);
}

TEST(ServiceValidation, EqualTickIsAccepted) {
  DynamicService d;
  Service& s = d.service();
  EXPECT_TRUE(s.commit(0)) << "make_service committed at 0: " << s.last_error();
  EXPECT_TRUE(s.commit(4));
  EXPECT_TRUE(s.commit(4));
  EXPECT_FALSE(s.commit(3));
}

TEST(ServiceValidation, BudgetBelowOneIsRefusedAndKept) {
  DynamicService d;
  Service& s = d.service();
  ASSERT_TRUE(s.set_budget(5000));
  EXPECT_FALSE(s.set_budget(0));
  EXPECT_NE(s.last_error().find("set_budget"), std::string::npos) << s.last_error();
  ASSERT_TRUE(s.step(0.01));
  EXPECT_EQ(s.acquire_frame()->budget, 5000u);
  EXPECT_TRUE(s.set_budget(kMinBudget));
  EXPECT_TRUE(s.set_budget(UINT64_MAX));
}

struct Setter {
  const char* name;
  bool (Service::*set)(float);
  std::atomic<float> Service::Impl::*stored;
  float kept;
  std::initializer_list<float> refused, accepted;
};

TEST(ServiceValidation, SettersRefuseNanInfinityAndOutOfRangeKeepingTheirValue) {
  DynamicService d;
  Service& s = d.service();
  const Setter setters[] = {
      {"set_pixel_error", &Service::set_pixel_error, &Service::Impl::pixel_error, 2.5f,
       {kNaN, kInf, -kInf, 0.f, -0.f, -3.f, 10000.01f, 1e30f}, {1e-6f, 1.f, kMaxPixelError}},
      {"set_hysteresis", &Service::set_hysteresis, &Service::Impl::hysteresis, 0.5f,
       {kNaN, kInf, -kInf, -1e-6f, 10.5f, 1e30f}, {0.f, 0.25f, kMaxHysteresis}},
      {"set_blend_seconds", &Service::set_blend_seconds, &Service::Impl::blend_seconds, 1.5f,
       {kNaN, kInf, -kInf, -1e-6f, 60.5f, 1e30f}, {0.f, 0.25f, kMaxBlendSeconds}},
  };
  for (const Setter& st : setters) {
    ASSERT_TRUE((s.*st.set)(st.kept)) << st.name;
    for (float v : st.refused) {
      EXPECT_FALSE((s.*st.set)(v)) << st.name << "(" << v << ") accepted";
      EXPECT_NE(s.last_error().find(st.name), std::string::npos) << s.last_error();
      EXPECT_EQ((s.impl().*st.stored).load(), st.kept) << st.name << "(" << v << ") changed the setting";
    }
    for (float v : st.accepted) {
      EXPECT_TRUE((s.*st.set)(v)) << st.name << "(" << v << "): " << s.last_error();
      EXPECT_EQ((s.impl().*st.stored).load(), v);
    }
  }
  EXPECT_TRUE(s.step(0.01)) << s.last_error();
}

TEST(ServiceValidation, ViewsOutsideTheFieldOfViewRangeAreRefused) {
  DynamicService d;
  Service& s = d.service();
  Camera c = test::camera_at(0, 2, 60, 0, 0, -1);
  for (float fov : {kNaN, 0.f, 1e-20f, 0.0009f, 179.5f, 180.f}) {
    c.fov_y_deg = fov;
    EXPECT_FALSE(s.set_view(0, c)) << fov;
    EXPECT_NE(s.last_error().find("fov_y_deg"), std::string::npos) << s.last_error();
  }
  for (float fov : {kMinFovYDeg, 90.f, kMaxFovYDeg}) {
    c.fov_y_deg = fov;
    EXPECT_TRUE(s.set_view(0, c)) << fov << ": " << s.last_error();
  }
}

}  // namespace
}  // namespace lod
