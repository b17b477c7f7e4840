// Service with dynamic objects: staged creates, destroys, moves and options become visible
// together at commit(tick); per-object control; several views; the blend clock in seconds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "jobs/service.h"
#include "unit/jobs/service_fixture.h"

namespace lod {
namespace {

using test::DynamicService;
using test::entry_of;
using test::placed;

TEST(ServiceObjects, CommitMakesStagedChangesVisibleTogether) {
  DynamicService d;
  Service& s = d.service();
  const ObjectHandle a = s.create(0, placed(-2, 0, 0));
  const ObjectHandle b = s.create(1, placed(0, 0, 0));
  const ObjectHandle c = s.create(2, placed(2, 0, 0));
  ASSERT_NE(a, 0u);
  ASSERT_NE(b, 0u);
  ASSERT_NE(c, 0u);
  ASSERT_TRUE(s.step(0.01));
  {
    const FrameRef f = s.acquire_frame();
    EXPECT_EQ(f->tick, 0u);
    EXPECT_EQ(f->object_count, 0u) << "nothing is visible before its commit";
  }
  s.commit(5);
  ASSERT_TRUE(s.step(0.01));
  {
    const FrameRef f = s.acquire_frame();
    EXPECT_EQ(f->tick, 5u);
    EXPECT_EQ(f->object_count, 3u);
    EXPECT_EQ(f->visible, 3u);
    const int k = entry_of(*f, b);
    ASSERT_GE(k, 0);
    EXPECT_EQ(f->models[k], 1u);
    EXPECT_EQ(f->view_masks[k], 1u);
  }
  Transform moved = placed(1, 0, 0);
  moved.rotation[0] = 0.3f, moved.rotation[3] = 0.9f;  // not normalised: given back as set
  ASSERT_TRUE(s.set_transform(a, moved));
  ASSERT_TRUE(s.destroy(c));
  ASSERT_TRUE(s.step(0.01));
  {
    const FrameRef f = s.acquire_frame();
    EXPECT_EQ(f->tick, 5u) << "staged, not committed";
    EXPECT_EQ(f->object_count, 3u);
    EXPECT_EQ(f->transforms[entry_of(*f, a)].position[0], -2.f);
  }
  s.commit(6);
  ASSERT_TRUE(s.step(0.01));
  const FrameRef f = s.acquire_frame();
  EXPECT_EQ(f->tick, 6u);
  EXPECT_EQ(f->object_count, 2u);
  EXPECT_LT(entry_of(*f, c), 0);
  const Transform& t = f->transforms[entry_of(*f, a)];
  EXPECT_EQ(0, std::memcmp(&t, &moved, sizeof t)) << "the transform exactly as the caller set it";
}

TEST(ServiceObjects, StaleUnknownAndBadInputIsRefused) {
  DynamicService d;
  Service& s = d.service();
  const ObjectHandle a = s.create(0, placed(0, 0, 0));
  EXPECT_TRUE(s.alive(a));
  EXPECT_TRUE(s.destroy(a));
  EXPECT_FALSE(s.alive(a));
  EXPECT_FALSE(s.destroy(a));
  EXPECT_NE(s.last_error().find("stale"), std::string::npos) << s.last_error();
  EXPECT_FALSE(s.set_transform(a, placed(1, 0, 0)));
  EXPECT_FALSE(s.set_options(a, ObjectOptions{}));
  EXPECT_FALSE(s.destroy(0));
  EXPECT_FALSE(s.destroy(make_handle(12345, 1)));
  EXPECT_EQ(s.create(99, placed(0, 0, 0)), 0u);
  EXPECT_NE(s.last_error().find("unknown model 99"), std::string::npos) << s.last_error();
  Transform bad = placed(0, 0, 0);
  bad.scale = 0;
  EXPECT_EQ(s.create(0, bad), 0u);
  bad = placed(NAN, 0, 0);
  EXPECT_EQ(s.create(0, bad), 0u);
  bad = placed(0, 0, 0);
  bad.rotation[3] = 0;
  EXPECT_EQ(s.create(0, bad), 0u) << "a zero quaternion";
  const ObjectHandle b = s.create(0, placed(0, 0, 0));
  EXPECT_NE(b, a) << "a reused slot has a new generation";
  EXPECT_FALSE(s.set_transform(b, bad));
  EXPECT_FALSE(s.set_options(b, ObjectOptions{.priority = -1}));
  Camera cam;
  cam.fov_y_deg = 0;
  EXPECT_FALSE(s.set_view(0, cam));
  EXPECT_FALSE(s.set_view(8, Camera{}));
  cam = Camera{};
  cam.up[0] = 0, cam.up[1] = 0, cam.up[2] = -1;  // parallel to forward
  EXPECT_FALSE(s.set_view(1, cam));
  EXPECT_FALSE(s.set_view_count(0));
  EXPECT_FALSE(s.set_view_count(9));
  EXPECT_EQ(s.stats().live_objects, 1u);
}

// An object's level, blend and history stay its own while others are created and destroyed
// around it (its dense index moves): nothing pops because something else spawned.
TEST(ServiceObjects, StateFollowsAnObjectThroughOthersChurn) {
  DynamicService d;
  Service& s = d.service();
  s.set_blend_seconds(1.0f);
  std::vector<ObjectHandle> others;
  for (int i = 0; i < 50; ++i) others.push_back(s.create(0, placed(float(i % 10) - 5, 0, -float(i / 10))));
  const ObjectHandle watched = s.create(1, placed(0, 0, 20));  // close to the eye: fine level
  s.commit(1);
  ASSERT_TRUE(s.step(0.1));
  // Move it away: its level coarsens and a 1 s blend starts.
  ASSERT_TRUE(s.set_transform(watched, placed(0, 0, -400)));
  s.commit(2);
  ASSERT_TRUE(s.step(0.1));
  const FrameRef before = s.acquire_frame();
  const int k0 = entry_of(*before, watched);
  ASSERT_GE(k0, 0);
  ASSERT_NE(before->levels[k0], before->from_levels[k0]) << "the scene must make it blend";
  const float morph0 = before->morph[k0];
  // Destroy the objects created before it (its dense index moves) and create new ones.
  for (int i = 0; i < 40; ++i) ASSERT_TRUE(s.destroy(others[i]));
  for (int i = 0; i < 40; ++i) ASSERT_NE(s.create(2, placed(float(i % 8) - 4, 1, -2)), 0u);
  s.commit(3);
  ASSERT_TRUE(s.step(0.1));
  const FrameRef after = s.acquire_frame();
  const int k1 = entry_of(*after, watched);
  ASSERT_GE(k1, 0);
  EXPECT_NE(after->objects[k1], before->objects[k0]) << "its place in the object order changed";
  EXPECT_EQ(after->levels[k1], before->levels[k0]);
  EXPECT_EQ(after->from_levels[k1], before->from_levels[k0]);
  EXPECT_NEAR(after->morph[k1], morph0 + 0.1f, 1e-4f) << "the blend went on, 0.1 s further";
}

TEST(ServiceObjects, BlendsAdvanceInSecondsOfTheServiceClock) {
  DynamicService d;
  Service& s = d.service();
  s.set_blend_seconds(2.0f);
  const ObjectHandle h = s.create(1, placed(0, 0, 20));
  s.commit(1);
  ASSERT_TRUE(s.step(1.0 / 60));
  ASSERT_TRUE(s.set_transform(h, placed(0, 0, -400)));
  s.commit(2);
  ASSERT_TRUE(s.step(0.0));  // the change happens at this frame's time
  ASSERT_TRUE(s.step(0.5));  // a quarter of the blend, whatever the frame rate
  const FrameRef f = s.acquire_frame();
  const int k = entry_of(*f, h);
  ASSERT_GE(k, 0);
  EXPECT_NEAR(f->morph[k], 0.25f, 1e-5f);
  EXPECT_NEAR(f->time_s, 1.0 / 60 + 0.5, 1e-9);
}

TEST(ServiceObjects, ForcedMinAndMaxLevelsHold) {
  DynamicService d;
  Service& s = d.service();
  ObjectOptions forced;
  forced.forced_level = 2;
  ObjectOptions capped;
  capped.max_level = 1;  // never coarser than level 1, whatever the budget
  ObjectOptions fine;
  fine.min_level = 3;  // never finer than level 3, even up close
  const ObjectHandle a = s.create(2, placed(-3, 0, 0), forced);
  const ObjectHandle b = s.create(2, placed(0, 0, 0), capped);
  const ObjectHandle c = s.create(2, placed(1, 0, 50), fine);  // up close
  const ObjectHandle twin = s.create(2, placed(-1, 0, 50));
  s.commit(1);
  ASSERT_TRUE(s.step(0.01));
  {
    const FrameRef f = s.acquire_frame();
    ASSERT_EQ(f->visible, 4u);
    EXPECT_EQ(f->levels[entry_of(*f, a)], 2);
    EXPECT_EQ(f->levels[entry_of(*f, c)], 3);
    EXPECT_LT(f->levels[entry_of(*f, twin)], 3) << "without the limit it would be finer";
  }
  s.set_budget(1000);  // far below what even the capped object alone needs
  ASSERT_TRUE(s.step(0.01));
  const FrameRef f = s.acquire_frame();
  EXPECT_EQ(f->levels[entry_of(*f, a)], 2);
  EXPECT_EQ(f->levels[entry_of(*f, b)], 1);
  EXPECT_EQ(f->levels[entry_of(*f, twin)], s.level_count(2) - 1) << "the budget takes a free one to its coarsest";
  EXPECT_TRUE(f->over_budget) << "the capped object alone exceeds M, and the frame says so";
}

TEST(ServiceObjects, PriorityAndBiasSteerTheLevel) {
  DynamicService d(2, UINT64_MAX);
  Service& s = d.service();
  ObjectOptions coarse;
  coarse.lod_bias = 3;  // tolerates 8x the pixel error
  const ObjectHandle plain = s.create(1, placed(-1, 0, 0));
  const ObjectHandle biased = s.create(1, placed(1, 0, 0), coarse);
  s.commit(1);
  ASSERT_TRUE(s.step(0.01));
  uint64_t both = 0;
  {
    const FrameRef f = s.acquire_frame();
    EXPECT_GT(f->levels[entry_of(*f, biased)], f->levels[entry_of(*f, plain)]);
    both = f->tris_selected;
  }
  // Four alike at about one distance; a budget that takes two of them one level down: the
  // one with priority 8 is never among them, though its twin is as far away.
  ASSERT_TRUE(s.set_options(biased, ObjectOptions{}));
  const ObjectHandle important = s.create(1, placed(3, 0, 0), ObjectOptions{.priority = 8});
  const ObjectHandle twin = s.create(1, placed(-3, 0, 0));
  s.commit(2);
  ASSERT_TRUE(s.step(0.01));
  uint8_t free_level = 0;
  uint64_t free_tris = 0;
  {
    const FrameRef f = s.acquire_frame();
    free_level = f->levels[entry_of(*f, important)];
    ASSERT_EQ(f->levels[entry_of(*f, twin)], free_level);
    ASSERT_LT(free_level + 1u, s.level_count(1));
    free_tris = f->tris_selected;
  }
  const uint64_t step_saves = s.level_triangles(1, free_level) - s.level_triangles(1, free_level + 1);
  s.set_budget(free_tris - 2 * step_saves);
  ASSERT_TRUE(s.step(0.01));
  const FrameRef f = s.acquire_frame();
  EXPECT_LE(f->tris_selected, free_tris - 2 * step_saves);
  EXPECT_EQ(f->levels[entry_of(*f, important)], free_level);
  EXPECT_EQ(f->levels[entry_of(*f, twin)], free_level + 1);
  (void)both;
}

TEST(ServiceObjects, SeveralViewsCountAnObjectOnceAtTheFinestLevel) {
  DynamicService d(2, UINT64_MAX);
  Service& s = d.service();
  // View 0 looks down -z from z = 60; view 1 looks down +z from z = -60.
  Camera back = test::camera_at(0, 2, -60, 0, 0, 1);
  const ObjectHandle front_only = s.create(1, placed(0, 0, 40));
  const ObjectHandle both = s.create(1, placed(0, 0, -40));  // far from view 0, near view 1
  ObjectOptions always;
  always.never_cull = true;
  const ObjectHandle hidden = s.create(1, placed(500, 0, 0), always);  // outside both frusta
  s.commit(1);
  ASSERT_TRUE(s.step(0.01));
  uint8_t level_one_view = 0;
  {
    const FrameRef f = s.acquire_frame();
    level_one_view = f->levels[entry_of(*f, both)];
    EXPECT_EQ(f->view_count, 1u);
  }
  ASSERT_TRUE(s.set_view(1, back));
  ASSERT_TRUE(s.step(0.01));
  const FrameRef f = s.acquire_frame();
  EXPECT_EQ(f->view_count, 2u);
  EXPECT_EQ(f->object_count, 3u);
  EXPECT_EQ(f->visible, 3u) << "each object counts once";
  EXPECT_EQ(f->view_masks[entry_of(*f, both)], 3u);
  EXPECT_EQ(f->view_masks[entry_of(*f, front_only)] & 1u, 1u);
  EXPECT_EQ(f->view_masks[entry_of(*f, hidden)], 3u) << "never_cull: every view";
  EXPECT_LT(f->levels[entry_of(*f, both)], level_one_view) << "the finest any view needs";
  uint64_t tris = 0;
  for (uint32_t k = 0; k < f->visible; ++k) tris += s.level_triangles(f->models[k], f->levels[k]);
  EXPECT_EQ(f->tris_selected, tris);
  ASSERT_TRUE(s.set_view_count(1));
  ASSERT_TRUE(s.step(0.01));
  EXPECT_EQ(s.acquire_frame()->view_count, 1u);
}

TEST(ServiceObjects, ChurnOfAMillionKeepsHandlesHonestAndMemoryFlat) {
  DynamicService d;
  Service& s = d.service();
  std::vector<ObjectHandle> live;
  std::vector<ObjectHandle> dead;
  constexpr int kChurn = 1000000;
  for (int i = 0; i < kChurn; ++i) {
    if (live.size() < 256 && (live.empty() || (uint64_t(i) * 7919u) % 3 != 0)) {
      live.push_back(s.create(uint32_t(i % 3), placed(float(i % 20) - 10, 0, -float(i % 13))));
      ASSERT_NE(live.back(), 0u);
    } else {
      const size_t k = size_t(i) % live.size();
      ASSERT_TRUE(s.destroy(live[k]));
      if (dead.size() < 4096) dead.push_back(live[k]);
      live[k] = live.back();
      live.pop_back();
    }
    if (i % 1000 == 999) s.commit(uint64_t(i));
    if (i % 20000 == 19999) {
      ASSERT_TRUE(s.step(0.01));
    }
  }
  s.commit(kChurn);
  ASSERT_TRUE(s.step(0.01));
  for (ObjectHandle h : dead) EXPECT_FALSE(s.destroy(h));
  const ServiceStats st = s.stats();
  EXPECT_EQ(st.live_objects, live.size());
  EXPECT_LE(st.handle_slots, 256u) << "slots are reused: the table stays at its peak";
  EXPECT_EQ(s.acquire_frame()->object_count, live.size());
}

}  // namespace
}  // namespace lod
