// Service: the LOD thread, driven and free-running, with views and budgets from other threads.
#include "jobs/service.h"

#include <gtest/gtest.h>

#include <new>
#include <mutex>
#include <condition_variable>

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

std::unique_ptr<Service> service_of(const Fixture& fx, const FrameGraphOptions& o, double rate) {
  return make_service(fx.scene, o, rate);
}

// Driven mode as the CLI uses it: the view, then one frame 1/60 s later.
bool step(Service& s, const View& view) { return set_view(s, 0, view) && s.step(1.0 / 60); }

uint64_t latest_index(const Service& s) {
  const FrameRef f = s.acquire_frame();
  return f ? f->index : 0;
}

TEST(Service, DrivenStepPublishesOneFrame) {
  Fixture fx;
  auto owned = service_of(fx, small_options(), 60);
  Service& s = *owned;
  EXPECT_FALSE(s.acquire_frame()) << "nothing published yet";
  const View view = view_at(fx.path, 3);
  ASSERT_TRUE(step(s, view));
  const FrameRef held = s.acquire_frame();
  const Frame& f = *held;
  EXPECT_EQ(f.index, 1u);
  EXPECT_EQ(f.object_count, 2000u);
  EXPECT_EQ(f.tick, 0u) << "the scene's objects are committed at tick 0";
  EXPECT_EQ(view_of(f.views[0]).eye, view.eye);

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
  auto owned = service_of(fx, small_options(), 500);
  Service& s = *owned;
  set_view(s, 0, view_at(fx.path, 0));
  EXPECT_TRUE(s.start());
  EXPECT_TRUE(s.running());
  ASSERT_TRUE(eventually([&] { return s.stats().frames >= 3; }));
  s.stop();
  EXPECT_FALSE(s.running());
  const uint64_t after_stop = s.stats().frames;
  std::this_thread::sleep_for(20ms);
  EXPECT_EQ(s.stats().frames, after_stop) << "no frames after stop()";
  EXPECT_EQ(latest_index(s), after_stop);

  EXPECT_TRUE(s.start());
  EXPECT_FALSE(s.start());  // a second start is refused and changes nothing
  ASSERT_TRUE(eventually([&] { return s.stats().frames >= after_stop + 3; }));
  s.stop();
  s.stop();  // so is a second stop
  EXPECT_GT(latest_index(s), after_stop);
  EXPECT_EQ(s.stats().errors, 0u);
  EXPECT_GT(s.stats().mean_ms, 0.0);
}

TEST(Service, StepIsRefusedWhileRunning) {
  Fixture fx;
  auto owned = service_of(fx, small_options(), 200);
  Service& s = *owned;
  ASSERT_TRUE(step(s, view_at(fx.path, 0)));  // stepped, then started, stopped and stepped again
  s.start();
  EXPECT_FALSE(step(s, view_at(fx.path, 0)));
  EXPECT_NE(s.last_error().find("running"), std::string::npos) << s.last_error();
  s.stop();
  EXPECT_EQ(s.stats().errors, 0u);
  EXPECT_TRUE(step(s, view_at(fx.path, 0)));
  EXPECT_FALSE(s.step(-1.0)) << "a negative dt is refused";
}

TEST(Service, DestructorStopsARunningService) {
  Fixture fx;
  auto s = service_of(fx, small_options(), 1000);
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

  auto owned = service_of(fx, small_options(), 2000);
  Service& s = *owned;
  set_view(s, 0, views[0]);
  s.start();
  std::atomic<bool> stop{false};
  std::thread steer([&] {
    for (int k = 0; !stop.load(); k ^= 1) {
      set_view(s, 0, views[k]);
      std::this_thread::sleep_for(200us);
    }
  });
  uint64_t last = 0, checked = 0, inconsistent = 0, backwards = 0;
  bool saw[2] = {false, false};
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while ((checked < 200 || !saw[0] || !saw[1]) && std::chrono::steady_clock::now() < deadline) {
    const FrameRef held = s.acquire_frame();
    if (!held) continue;
    const Frame& f = *held;
    if (f.index < last) ++backwards;
    if (f.index != last) {
      ++checked;
      const glm::vec3 eye = view_of(f.views[0]).eye;
      const int k = eye == views[0].eye ? 0 : eye == views[1].eye ? 1 : -1;
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
  auto owned = service_of(fx, small_options(UINT64_MAX), 60);
  Service& s = *owned;
  const View view = view_at(fx.path, 0);
  ASSERT_TRUE(step(s, view));
  const uint64_t free_tris = s.acquire_frame()->tris_selected;
  std::thread other([&] { s.set_budget(free_tris / 3); });
  other.join();
  ASSERT_TRUE(step(s, view));
  const FrameRef held = s.acquire_frame();
  const Frame& f = *held;
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
  auto owned = service_of(fx, o, 60);
  Service& s = *owned;
  ASSERT_TRUE(step(s, view_at(fx.path, 0)));
  const Frame good = *s.acquire_frame();
  fail.store(true);
  EXPECT_FALSE(step(s, view_at(fx.path, 50)));
  const FrameRef held = s.acquire_frame();
  const Frame& kept = *held;
  EXPECT_EQ(kept.index, good.index);
  EXPECT_EQ(kept.objects, good.objects);
  EXPECT_EQ(kept.levels, good.levels);
  EXPECT_EQ(s.stats().errors, 1u);
  EXPECT_EQ(s.stats().frames, 1u);
  fail.store(false);
  ASSERT_TRUE(step(s, view_at(fx.path, 50)));
  EXPECT_GT(latest_index(s), good.index);
  EXPECT_EQ(s.stats().frames, 2u);
}

// Fault injection in every node: a failing allocation (std::bad_alloc thrown where the stage
// starts) loses that frame only; the last good frame stays published and the fault is counted.
TEST(Service, FailingAllocationInAnyNodeKeepsTheLastGoodFrame) {
  size_t injected = 0;
  for (size_t k = 0; k < kStageCount; ++k) {
    const Stage target = static_cast<Stage>(k);
    Fixture fx;
    std::atomic<bool> armed{false}, hit{false};
    FrameGraphOptions o = small_options();
    o.stage_hook = [&](Stage st) {
      if (st == target && armed.load()) {
        hit.store(true);
        throw std::bad_alloc();
      }
    };
    auto owned = service_of(fx, o, 60);
    Service& s = *owned;
    ASSERT_TRUE(step(s, view_at(fx.path, 0)));
    const Frame good = *s.acquire_frame();
    armed.store(true);
    const bool ok = step(s, view_at(fx.path, 40));
    armed.store(false);
    if (!hit.load()) {  // this scene has no view-dependent objects: their nodes never run
      EXPECT_TRUE(ok) << kStageNames[k];
      continue;
    }
    ++injected;
    EXPECT_FALSE(ok) << kStageNames[k];
    EXPECT_EQ(s.stats().errors, 1u) << kStageNames[k];
    EXPECT_EQ(latest_index(s), good.index) << kStageNames[k] << ": the last good frame stays published";
    ASSERT_TRUE(step(s, view_at(fx.path, 40))) << kStageNames[k] << ": the next frame recovers";
    EXPECT_GT(latest_index(s), good.index) << kStageNames[k];
  }
  EXPECT_GE(injected, kStageCount - 2) << "every node but the two view-dependent ones was reached";
}

// A node that stalls (blocked here until the test lets it go) holds up only the frame it is
// in: consumers keep getting the last good frame at once, and simulation calls still stage.
TEST(Service, StalledNodeNeverBlocksConsumersOrTheSimulation) {
  Fixture fx;
  std::mutex m;
  std::condition_variable cv;
  bool stall = false, stalled = false, release = false;
  FrameGraphOptions o = small_options();
  o.stage_hook = [&](Stage st) {
    if (st != Stage::selection) return;
    std::unique_lock lock(m);
    if (!stall) return;
    stalled = true;
    cv.notify_all();
    cv.wait(lock, [&] { return release; });
  };
  auto owned = service_of(fx, o, 240);
  Service& s = *owned;
  set_view(s, 0, view_at(fx.path, 0));
  ASSERT_TRUE(s.start());
  ASSERT_TRUE(eventually([&] { return s.stats().frames >= 2; }));
  {
    std::unique_lock lock(m);
    stall = true;
    cv.wait(lock, [&] { return stalled; });
  }
  const uint64_t during = latest_index(s);  // returns while the LOD thread is stuck in a node
  EXPECT_GT(during, 0u);
  const ObjectHandle h = s.create(0, Transform{});
  EXPECT_TRUE(s.alive(h)) << "staging works during the stall";
  s.commit(77);
  EXPECT_EQ(latest_index(s), during) << "no frame is published while the node is stalled";
  {
    std::lock_guard lock(m);
    stall = false, release = true;
  }
  cv.notify_all();
  ASSERT_TRUE(eventually([&] {
    const FrameRef f = s.acquire_frame();
    return f && f->tick == 77;
  }));
  s.stop();
  EXPECT_EQ(s.stats().errors, 0u);
}

TEST(Service, KeepsRunningThroughFailingFrames) {
  Fixture fx;
  std::atomic<uint64_t> calls{0};
  FrameGraphOptions o = small_options();
  o.stage_hook = [&](Stage st) {
    // Every third frame fails in importance.
    if (st == Stage::importance && calls.fetch_add(1) % 3 == 2) throw std::runtime_error("injected failure");
  };
  auto owned = service_of(fx, o, 2000);
  Service& s = *owned;
  set_view(s, 0, view_at(fx.path, 0));
  s.start();
  ASSERT_TRUE(eventually([&] { return s.stats().errors >= 3 && s.stats().frames >= 6; }));
  EXPECT_TRUE(s.running());
  const FrameRef held = s.acquire_frame();
  ASSERT_TRUE(held);
  EXPECT_GT(held->index, 0u);
  EXPECT_EQ(held->objects.size(), held->visible);
  s.stop();
}

}  // namespace
}  // namespace lod
