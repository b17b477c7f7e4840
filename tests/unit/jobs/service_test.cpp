// Service: the LOD thread, driven and free-running, with views and budgets from other threads.
#include "jobs/service.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>

#include "unit/jobs/synthetic_scene.h"

namespace lod {
namespace {

using namespace std::chrono_literals;

FrameGraphOptions small_options(uint64_t budget = 200000) {
  FrameGraphOptions o;
  o.threads = 2;
  o.grain = 128;
  o.selection.budget = budget;
  return o;
}

// Polls `pred` until it holds or a generous deadline passes (a wait, not a timing assertion).
template <class Pred>
bool eventually(Pred pred) {
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (!pred()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(1ms);
  }
  return true;
}

struct Fixture {
  Scene scene = test::synthetic_scene(2000, 200);
  CameraPath path = test::synthetic_config(2000, 200).camera;
};

TEST(Service, DrivenStepPublishesOneFrame) {
  Fixture fx;
  Service s(fx.scene, small_options(), 60);
  EXPECT_EQ(s.latest_frame().index, 0u) << "nothing published yet";
  const View view = view_at(fx.path, 3);
  ASSERT_TRUE(s.step(view));
  const Frame& f = s.latest_frame();
  EXPECT_EQ(f.index, 1u);
  EXPECT_EQ(f.object_count, 2000u);
  EXPECT_EQ(f.view.eye, view.eye);

  FrameGraph g(fx.scene, small_options());
  Frame expected;
  g.run(view, expected);
  EXPECT_EQ(f.objects, expected.objects);
  EXPECT_EQ(f.levels, expected.levels);
  EXPECT_EQ(s.stats().frames, 1u);
  EXPECT_EQ(s.stats().errors, 0u);
  EXPECT_FALSE(s.running());
}

TEST(Service, StartStopAndRestart) {
  Fixture fx;
  Service s(fx.scene, small_options(), 500);
  s.set_view(view_at(fx.path, 0));
  s.start();
  EXPECT_TRUE(s.running());
  ASSERT_TRUE(eventually([&] { return s.stats().frames >= 3; }));
  s.stop();
  EXPECT_FALSE(s.running());
  const uint64_t after_stop = s.stats().frames;
  std::this_thread::sleep_for(20ms);
  EXPECT_EQ(s.stats().frames, after_stop) << "no frames after stop()";
  EXPECT_EQ(s.latest_frame().index, after_stop);

  s.start();
  s.start();  // a second start is a no-op
  ASSERT_TRUE(eventually([&] { return s.stats().frames >= after_stop + 3; }));
  s.stop();
  s.stop();  // so is a second stop
  EXPECT_GT(s.latest_frame().index, after_stop);
  EXPECT_EQ(s.stats().errors, 0u);
  EXPECT_GT(s.stats().mean_ms, 0.0);
}

TEST(Service, StepIsRefusedWhileRunning) {
  Fixture fx;
  Service s(fx.scene, small_options(), 200);
  s.start();
  EXPECT_FALSE(s.step(view_at(fx.path, 0)));
  s.stop();
  EXPECT_EQ(s.stats().errors, 0u);
  EXPECT_TRUE(s.step(view_at(fx.path, 0)));
}

TEST(Service, DestructorStopsARunningService) {
  Fixture fx;
  auto s = std::make_unique<Service>(fx.scene, small_options(), 1000);
  s->start();
  ASSERT_TRUE(eventually([&] { return s->stats().frames >= 1; }));
  s.reset();  // joins the thread; a leak or a hang fails the test run
  SUCCEED();
}

TEST(Service, ViewsSetFromAnotherThreadGiveConsistentFrames) {
  Fixture fx;
  const View views[2] = {view_at(fx.path, 0), view_at(fx.path, 100)};
  // What each view must give, from a separate graph.
  uint32_t expected_visible[2];
  for (int k = 0; k < 2; ++k) {
    FrameGraph g(fx.scene, small_options());
    Frame f;
    g.run(views[k], f);
    expected_visible[k] = f.visible;
  }
  ASSERT_NE(expected_visible[0], expected_visible[1]);

  Service s(fx.scene, small_options(), 2000);
  s.set_view(views[0]);
  s.start();
  std::atomic<bool> stop{false};
  std::thread steer([&] {
    for (int k = 0; !stop.load(); k ^= 1) {
      s.set_view(views[k]);
      std::this_thread::sleep_for(200us);
    }
  });
  uint64_t last = 0, checked = 0, inconsistent = 0, backwards = 0;
  bool saw[2] = {false, false};
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while ((checked < 200 || !saw[0] || !saw[1]) && std::chrono::steady_clock::now() < deadline) {
    const Frame& f = s.latest_frame();
    if (f.index == 0) continue;
    if (f.index < last) ++backwards;
    if (f.index != last) {
      ++checked;
      const int k = f.view.eye == views[0].eye ? 0 : f.view.eye == views[1].eye ? 1 : -1;
      if (k < 0 || f.visible != expected_visible[k] || f.objects.size() != f.visible ||
          f.levels.size() != f.visible || (!f.over_budget && f.tris_selected > f.budget))
        ++inconsistent;
      else
        saw[k] = true;
    }
    last = f.index;
  }
  stop.store(true);
  steer.join();
  s.stop();
  EXPECT_EQ(inconsistent, 0u);
  EXPECT_EQ(backwards, 0u);
  EXPECT_TRUE(saw[0] && saw[1]) << "both views must have reached the service";
}

TEST(Service, SetBudgetAppliesToTheNextFrame) {
  Fixture fx;
  Service s(fx.scene, small_options(UINT64_MAX), 60);
  const View view = view_at(fx.path, 0);
  ASSERT_TRUE(s.step(view));
  const uint64_t free_tris = s.latest_frame().tris_selected;
  std::thread other([&] { s.set_budget(free_tris / 3); });
  other.join();
  ASSERT_TRUE(s.step(view));
  const Frame& f = s.latest_frame();
  EXPECT_EQ(f.budget, free_tris / 3);
  EXPECT_LE(f.tris_selected, free_tris / 3);
}

TEST(Service, FailedDrivenFrameKeepsTheLastGoodFrame) {
  Fixture fx;
  std::atomic<bool> fail{false};
  FrameGraphOptions o = small_options();
  o.stage_hook = [&](Stage st) {
    if (st == Stage::selection && fail.load()) throw std::runtime_error("injected failure");
  };
  Service s(fx.scene, o, 60);
  ASSERT_TRUE(s.step(view_at(fx.path, 0)));
  const Frame good = s.latest_frame();
  fail.store(true);
  EXPECT_FALSE(s.step(view_at(fx.path, 50)));
  const Frame& kept = s.latest_frame();
  EXPECT_EQ(kept.index, good.index);
  EXPECT_EQ(kept.objects, good.objects);
  EXPECT_EQ(kept.levels, good.levels);
  EXPECT_EQ(s.stats().errors, 1u);
  EXPECT_EQ(s.stats().frames, 1u);
  fail.store(false);
  ASSERT_TRUE(s.step(view_at(fx.path, 50)));
  EXPECT_GT(s.latest_frame().index, good.index);
  EXPECT_EQ(s.stats().frames, 2u);
}

TEST(Service, KeepsRunningThroughFailingFrames) {
  Fixture fx;
  std::atomic<uint64_t> calls{0};
  FrameGraphOptions o = small_options();
  o.stage_hook = [&](Stage st) {
    // Every third frame fails in importance.
    if (st == Stage::importance && calls.fetch_add(1) % 3 == 2) throw std::runtime_error("injected failure");
  };
  Service s(fx.scene, o, 2000);
  s.set_view(view_at(fx.path, 0));
  s.start();
  ASSERT_TRUE(eventually([&] { return s.stats().errors >= 3 && s.stats().frames >= 6; }));
  EXPECT_TRUE(s.running());
  const Frame& f = s.latest_frame();
  EXPECT_GT(f.index, 0u);
  EXPECT_EQ(f.objects.size(), f.visible);
  s.stop();
}

}  // namespace
}  // namespace lod
