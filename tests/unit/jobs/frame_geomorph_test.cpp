// FrameGraph's geomorph stage for discrete levels: the level each object morphs from follows a
// level change and settles back to the selected level after geomorph_seconds.
#include <gtest/gtest.h>

#include <algorithm>

#include "jobs/frame_graph.h"
#include "unit/jobs/synthetic_scene.h"

namespace lod {
namespace {

// The extra triangles a renderer draws for the frame's morphing objects (their finer level).
uint64_t extra_of(const Scene& scene, const Frame& f, uint32_t* morphing) {
  uint64_t extra = 0;
  *morphing = 0;
  for (size_t k = 0; k < f.objects.size(); ++k) {
    if (f.from_levels[k] == f.levels[k]) continue;
    const uint32_t first = scene.models.first_level[scene.objects.model[f.objects[k]]];
    ++*morphing;
    extra += scene.models.triangles[first + std::min(f.from_levels[k], f.levels[k])] -
             scene.models.triangles[first + f.levels[k]];
  }
  return extra;
}

// 0.25 s blends at 60 Hz, no budget yet, and no blend reserve: the levels only change when a
// test changes the budget.
FrameGraphOptions still_levels_options() {
  FrameGraphOptions o;
  o.threads = 2;
  o.grain = 64;
  o.selection.budget = UINT64_MAX;
  o.selection.reserve_blends = false;
  o.geomorph_seconds = 0.25f;
  o.frame_seconds = 1.0f / 60;
  return o;
}

TEST(FrameGeomorph, FromLevelsFollowALevelChangeAndSettle) {
  const Scene scene = test::synthetic_scene(3000, 250);
  const View view = view_at(test::synthetic_config(3000, 250).camera, 0);
  const FrameGraphOptions o = still_levels_options();
  FrameGraph g(scene, o);
  Frame f;
  g.run(view, f);
  ASSERT_GT(f.visible, 0u);
  ASSERT_EQ(f.from_levels.size(), f.visible);
  EXPECT_EQ(f.from_levels, f.levels) << "newly visible objects appear settled";
  EXPECT_EQ(f.morphing, 0u);
  EXPECT_EQ(f.tris_morph_extra, 0u);
  const std::vector<uint32_t> objects = f.objects;
  const std::vector<uint8_t> before = f.levels;

  g.set_budget(f.tris_selected / 3);  // forces many objects coarser
  g.run(view, f);
  ASSERT_EQ(f.objects, objects);
  const std::vector<uint8_t> after = f.levels;
  uint32_t changed = 0;
  for (size_t k = 0; k < f.objects.size(); ++k) {
    if (after[k] == before[k]) {
      EXPECT_EQ(f.from_levels[k], f.levels[k]);
      EXPECT_EQ(f.morph[k], 1.f);
      continue;
    }
    ++changed;
    EXPECT_EQ(f.from_levels[k], before[k]) << "object " << f.objects[k] << " morphs from the level it showed";
    EXPECT_EQ(f.morph[k], 0.f) << "a change starts looking like the old level";
  }
  ASSERT_GT(changed, 0u) << "the lower budget changed no level";
  uint32_t morphing = 0;
  EXPECT_EQ(f.tris_morph_extra, extra_of(scene, f, &morphing));
  EXPECT_EQ(f.morphing, changed);
  EXPECT_EQ(morphing, changed);
  EXPECT_GT(f.tris_morph_extra, 0u) << "coarsening objects draw their finer level while morphing";

  // 0.25 s at 60 Hz: still blending after 14 more frames, settled on the 15th.
  float last_morph = 0;
  for (int frame = 1; frame <= 15; ++frame) {
    g.run(view, f);
    ASSERT_EQ(f.levels, after) << "the levels must hold still for this test (frame " << frame << ")";
    float m = 1;
    for (size_t k = 0; k < f.objects.size(); ++k)
      if (after[k] != before[k]) m = std::min(m, f.morph[k]);
    EXPECT_GT(m, last_morph) << "frame " << frame;
    last_morph = m;
    EXPECT_EQ(f.tris_morph_extra, extra_of(scene, f, &morphing)) << "frame " << frame;
    EXPECT_EQ(f.morphing, morphing);
    if (frame < 15) {
      EXPECT_EQ(f.morphing, changed) << "frame " << frame;
    }
  }
  EXPECT_EQ(last_morph, 1.f);
  EXPECT_EQ(f.from_levels, f.levels);
  EXPECT_EQ(f.morphing, 0u);
  EXPECT_EQ(f.tris_morph_extra, 0u);
}

// A blend that reverses mid-way (the level goes back to where it came from) keeps its shape:
// the renderer's weight is continuous, only its direction flips.
TEST(FrameGeomorph, GoingBackMidBlendContinuesFromTheSameShape) {
  const Scene scene = test::synthetic_scene(3000, 250);
  const View view = view_at(test::synthetic_config(3000, 250).camera, 0);
  const FrameGraphOptions o = still_levels_options();
  FrameGraph g(scene, o);
  Frame f;
  g.run(view, f);
  const std::vector<uint8_t> before = f.levels;
  const uint64_t free_tris = f.tris_selected;
  g.set_budget(free_tris / 3);
  for (int i = 0; i < 6; ++i) g.run(view, f);  // 5 frames into a 15-frame blend
  const std::vector<uint8_t> coarse = f.levels;
  const std::vector<float> morph = f.morph;
  ASSERT_EQ(f.from_levels, before);
  g.set_budget(UINT64_MAX);
  g.run(view, f);
  uint32_t reversed = 0;
  for (size_t k = 0; k < f.objects.size(); ++k) {
    if (coarse[k] == before[k] || f.levels[k] == coarse[k]) continue;
    SCOPED_TRACE("object " + std::to_string(f.objects[k]));
    EXPECT_EQ(f.from_levels[k], coarse[k]);
    if (f.levels[k] != before[k]) {
      EXPECT_EQ(f.morph[k], 0.f);
      continue;
    }
    ++reversed;
    // Before: coarsening, weight = morph. Now: refining, weight = 1 - morph' = morph + one frame.
    EXPECT_NEAR(1 - f.morph[k], morph[k] + 4.f / 60, 1e-4f);  // one frame = 1/15 of the blend
  }
  EXPECT_GT(reversed, 0u) << "no object went back to its level when the budget came back";
}

// Selection holds back last frame's blend extra from M: selected + reserve stays within M,
// and the worst drawn frame (selected + blends) is nearer M than without the reserve.
TEST(FrameGeomorph, ReservingBlendsKeepsWhatIsDrawnNearerTheBudget) {
  const SceneConfig config = test::synthetic_config(3000, 250);
  const Scene scene = test::synthetic_scene(3000, 250);
  uint64_t free_tris = 0;
  {
    FrameGraphOptions o;
    o.selection.budget = UINT64_MAX;
    FrameGraph g(scene, o);
    Frame f;
    g.run(view_at(config.camera, 0), f);
    free_tris = f.tris_selected;
  }
  double worst[2] = {0, 0};
  for (int reserve = 0; reserve < 2; ++reserve) {
    FrameGraphOptions o;
    o.threads = 2;
    o.selection.budget = free_tris / 3;
    o.selection.reserve_blends = reserve == 1;
    o.geomorph_seconds = 0.25f;
    o.frame_seconds = 1.0f / 60;
    FrameGraph g(scene, o);
    Frame f;
    uint64_t last_extra = 0;
    uint32_t morphing_frames = 0;
    for (uint32_t n = 0; n < 240; ++n) {
      g.run(view_at(config.camera, n), f);
      if (reserve) {
        EXPECT_EQ(f.budget_morph_reserve, std::min(last_extra, o.selection.budget / 2)) << "frame " << n;
        if (!f.over_budget) {
          EXPECT_LE(f.tris_selected + f.budget_morph_reserve, o.selection.budget) << "frame " << n;
        }
      } else {
        EXPECT_EQ(f.budget_morph_reserve, 0u);
      }
      last_extra = f.tris_morph_extra;
      morphing_frames += f.morphing > 0;
      worst[reserve] = std::max(worst[reserve], double(f.tris_selected + f.tris_morph_extra) / o.selection.budget);
    }
    EXPECT_GT(morphing_frames, 20u) << "the path should make objects change level";
  }
  EXPECT_GT(worst[0], 1.0) << "without the reserve, blends push what is drawn over M";
  EXPECT_LT(worst[1], worst[0]);
}

TEST(FrameGeomorph, NoGeomorphTimeMeansNothingBlends) {
  const Scene scene = test::synthetic_scene(2000, 250);
  const View view = view_at(test::synthetic_config(2000, 250).camera, 0);
  FrameGraphOptions o;
  o.threads = 1;
  o.selection.budget = UINT64_MAX;
  o.geomorph_seconds = 0;
  FrameGraph g(scene, o);
  Frame f;
  g.run(view, f);
  g.set_budget(f.tris_selected / 3);
  g.run(view, f);
  EXPECT_EQ(f.from_levels, f.levels);
  EXPECT_EQ(f.morphing, 0u);
  EXPECT_EQ(f.tris_morph_extra, 0u);
}

}  // namespace
}  // namespace lod

namespace lod {
namespace {

// A budget cut makes many objects coarsen at once: their blends draw the finer level, which
// takes what is drawn over M. Strict mode drops the blends that do not fit.
TEST(FrameGeomorphStrict, WhatIsDrawnStaysWithinTheBudget) {
  const Scene scene = test::synthetic_scene(3000, 250);
  const CameraPath path = test::synthetic_config(3000, 250).camera;
  for (bool strict : {false, true}) {
    SCOPED_TRACE(strict ? "strict" : "not strict");
    FrameGraphOptions o = still_levels_options();
    o.selection.strict = strict;
    FrameGraph g(scene, o);
    Frame f;
    g.run(view_at(path, 0), f);
    const uint64_t budget = f.tris_selected / 3;
    g.set_budget(budget);
    uint64_t worst = 0, blends = 0;
    for (uint32_t n = 1; n < 60; ++n) {
      g.run(view_at(path, n), f);
      ASSERT_FALSE(f.over_budget);
      uint32_t morphing = 0;
      EXPECT_EQ(extra_of(scene, f, &morphing), f.tris_morph_extra) << "the frame's own count of what blends add";
      EXPECT_EQ(morphing, f.morphing);
      worst = std::max(worst, f.tris_selected + f.tris_morph_extra);
      blends += f.morphing;
    }
    if (strict) {
      EXPECT_LE(worst, budget);
      EXPECT_GT(blends, 0u) << "blends that fit still run";
    } else {
      EXPECT_GT(worst, budget) << "without strict mode this scene draws over M (else the test shows nothing)";
    }
  }
}

}  // namespace
}  // namespace lod
