// The service under real concurrency (run under ThreadSanitizer by run-tests.sh): a simulation
// thread staging and committing creates, destroys and moves while the service free-runs and
// two consumers hold frames, every frame checked against what was committed at its tick; the
// same recorded update script at 1 and 2 threads; frame slots shared without blocking.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <map>
#include <mutex>
#include <random>
#include <thread>

#include "jobs/frame_pool.h"
#include "jobs/service.h"
#include "unit/jobs/service_fixture.h"

namespace lod {
namespace {

using namespace std::chrono_literals;
using test::DynamicService;
using test::placed;

// Where the simulation puts object h at tick t: every live object moves every tick, so a
// frame of tick t must show exactly this transform for each of its entries.
Transform position_at(ObjectHandle h, uint64_t t) {
  Transform x = placed(float(handle_slot(h) % 17) - 8.f, float(t % 5) * 0.25f, -float((t + handle_slot(h)) % 23));
  const float a = 0.01f * float(t % 100);
  x.rotation[1] = std::sin(a), x.rotation[3] = std::cos(a);
  return x;
}

struct Committed {
  std::mutex mutex;
  std::map<uint64_t, std::vector<ObjectHandle>> live;  // per tick, sorted
};

struct ConsumerResult {
  uint64_t frames = 0, bad = 0;
  std::string first_problem;
};

// Checks one frame against the state committed at its tick.
bool frame_matches(const Frame& f, Committed& committed, const Service& s, std::string* why) {
  std::vector<ObjectHandle> live;
  {
    std::lock_guard lock(committed.mutex);
    const auto it = committed.live.find(f.tick);
    if (it == committed.live.end()) return *why = "tick " + std::to_string(f.tick) + " was never committed", false;
    live = it->second;
  }
  if (f.object_count != live.size())
    return *why = "tick " + std::to_string(f.tick) + ": " + std::to_string(f.object_count) + " objects, committed " +
                  std::to_string(live.size()),
           false;
  uint64_t tris = 0;
  for (uint32_t k = 0; k < f.visible; ++k) {
    const ObjectHandle h = f.handles[k];
    if (!std::binary_search(live.begin(), live.end(), h)) return *why = "an entry not live at its tick", false;
    const Transform want = position_at(h, f.tick);
    if (std::memcmp(&want, &f.transforms[k], sizeof want) != 0) return *why = "a transform not of its tick", false;
    if (f.levels[k] >= s.level_count(f.models[k])) return *why = "a level out of range", false;
    tris += s.level_triangles(f.models[k], f.levels[k]);
  }
  if (tris != f.tris_selected) return *why = "tris_selected is not the sum of the entries", false;
  if (!f.over_budget && f.tris_selected > f.budget) return *why = "over M without over_budget", false;
  return true;
}

TEST(ServiceThreads, SimulationCommitsWhileTheServiceRunsAndTwoConsumersRead) {
  DynamicService d(2, 60000, 2000);
  Service& s = d.service();
  Committed committed;
  committed.live[0] = {};
  std::atomic<bool> done{false};
  constexpr uint64_t kTicks = 150;

  std::thread sim([&] {
    std::mt19937 rng(11);
    std::vector<ObjectHandle> live;
    for (uint64_t t = 1; t <= kTicks; ++t) {
      const int creates = int(rng() % 12), destroys = live.empty() ? 0 : int(rng() % std::min<size_t>(8, live.size()));
      for (int i = 0; i < destroys; ++i) {
        const size_t k = rng() % live.size();
        ASSERT_TRUE(s.destroy(live[k]));
        live[k] = live.back();
        live.pop_back();
      }
      for (int i = 0; i < creates && live.size() < 300; ++i) live.push_back(s.create(uint32_t(rng() % 3), placed(0, 0, 0)));
      for (ObjectHandle h : live) ASSERT_TRUE(s.set_transform(h, position_at(h, t)));
      std::vector<ObjectHandle> sorted = live;
      std::sort(sorted.begin(), sorted.end());
      {
        std::lock_guard lock(committed.mutex);
        committed.live[t] = std::move(sorted);
      }
      s.commit(t);
      std::this_thread::sleep_for(std::chrono::microseconds(rng() % 400));
    }
  });
  auto consume = [&](ConsumerResult& r, unsigned seed) {
    std::mt19937 rng(seed);
    uint64_t last = 0;
    // Each consumer reads until the writer is done and it has seen a few frames itself: on a
    // loaded 2-core machine one consumer can be starved for the whole simulation (seen once).
    const auto give_up = std::chrono::steady_clock::now() + 120s;
    while (!done.load() || (r.frames <= 5 && std::chrono::steady_clock::now() < give_up)) {
      const FrameRef f = s.acquire_frame();
      if (!f || f->index == last) continue;
      last = f->index;
      ++r.frames;
      std::string why;
      if (!frame_matches(*f, committed, s, &why)) {
        if (r.bad++ == 0) r.first_problem = why;
      }
      // Hold it a while, so both consumers and the writer overlap on the slots.
      std::this_thread::sleep_for(std::chrono::microseconds(rng() % 300));
    }
  };
  ASSERT_TRUE(s.start());
  ConsumerResult a, b;
  std::thread c1(consume, std::ref(a), 1u), c2(consume, std::ref(b), 2u);
  sim.join();
  // The last commit appears within a frame period and a frame (a wait, not a timing assertion).
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (std::chrono::steady_clock::now() < deadline) {
    const FrameRef f = s.acquire_frame();
    if (f && f->tick == kTicks) break;
    std::this_thread::sleep_for(1ms);
  }
  done.store(true);
  c1.join();
  c2.join();
  s.stop();
  const FrameRef last = s.acquire_frame();
  ASSERT_TRUE(last);
  EXPECT_EQ(last->tick, kTicks);
  EXPECT_GT(a.frames, 5u);
  EXPECT_GT(b.frames, 5u);
  EXPECT_EQ(a.bad, 0u) << a.first_problem;
  EXPECT_EQ(b.bad, 0u) << b.first_problem;
  EXPECT_EQ(s.stats().errors, 0u);
}

// A recorded script of updates, stepped: the frames must not depend on the thread count.
std::vector<Frame> run_script(uint32_t threads) {
  DynamicService d(threads, 40000);
  Service& s = d.service();
  std::mt19937 rng(7);
  std::vector<ObjectHandle> live;
  std::vector<Frame> frames;
  for (uint64_t t = 1; t <= 60; ++t) {
    for (int i = 0; i < 30 && live.size() < 2000; ++i)
      live.push_back(s.create(uint32_t(rng() % 3), position_at(make_handle(uint32_t(rng() % 1000), 1), t)));
    for (int i = 0; i < 10 && !live.empty(); ++i) {
      const size_t k = rng() % live.size();
      s.destroy(live[k]);
      live[k] = live.back();
      live.pop_back();
    }
    for (size_t k = 0; k < live.size(); k += 3) s.set_transform(live[k], position_at(live[k], t));
    s.commit(t);
    s.step(1.0 / 30);
    frames.push_back(*s.acquire_frame());
  }
  return frames;
}

TEST(ServiceThreads, RecordedScriptGivesTheSameFramesAtOneAndTwoThreads) {
  const std::vector<Frame> one = run_script(1), two = run_script(2);
  ASSERT_EQ(one.size(), two.size());
  for (size_t i = 0; i < one.size(); ++i) {
    SCOPED_TRACE("frame " + std::to_string(i));
    EXPECT_EQ(one[i].tick, two[i].tick);
    EXPECT_EQ(one[i].object_count, two[i].object_count);
    EXPECT_EQ(one[i].handles, two[i].handles);
    EXPECT_EQ(one[i].levels, two[i].levels);
    EXPECT_EQ(one[i].from_levels, two[i].from_levels);
    EXPECT_EQ(one[i].morph, two[i].morph);
    EXPECT_EQ(one[i].tris_selected, two[i].tris_selected);
    ASSERT_EQ(one[i].transforms.size(), two[i].transforms.size());
    EXPECT_EQ(0, std::memcmp(one[i].transforms.data(), two[i].transforms.data(),
                             one[i].transforms.size() * sizeof(Transform)));
  }
  EXPECT_GT(one.back().visible, 100u);
}

TEST(FramePool, WriterNeverWaitsForHeldFrames) {
  FramePool pool;
  EXPECT_EQ(pool.acquire(), nullptr);
  pool.back().index = 1;
  pool.publish();
  FrameSlot* held1 = pool.acquire();
  ASSERT_NE(held1, nullptr);
  EXPECT_EQ(held1->frame.index, 1u);
  // Hold every frame published: the writer makes new slots instead of waiting.
  std::vector<FrameSlot*> held = {held1};
  for (uint64_t i = 2; i <= 6; ++i) {
    Frame& f = pool.back();
    for (FrameSlot* h : held) ASSERT_NE(&h->frame, &f) << "never writes a held frame";
    f.index = i;
    pool.publish();
    held.push_back(pool.acquire());
    EXPECT_EQ(held.back()->frame.index, i);
  }
  EXPECT_EQ(held1->frame.index, 1u) << "a held frame stays unchanged";
  for (FrameSlot* h : held) FramePool::release(h);
  const size_t slots = pool.slots();
  for (uint64_t i = 7; i < 50; ++i) {
    pool.back().index = i;
    pool.publish();
  }
  EXPECT_EQ(pool.slots(), slots) << "released slots are reused";
}

TEST(FramePool, ManyReadersNeverSeeATornFrame) {
  FramePool pool;
  std::atomic<bool> stop{false};
  std::atomic<uint64_t> torn{0}, reads{0};
  auto reader = [&] {
    while (!stop.load()) {
      FrameSlot* s = pool.acquire();
      if (!s) continue;
      const Frame& f = s->frame;
      // The writer fills every column with its index: a mix would be a torn frame.
      for (uint32_t v : f.objects) torn += v != uint32_t(f.index);
      ++reads;
      FramePool::release(s);
    }
  };
  std::thread r1(reader), r2(reader), r3(reader);
  // Write until the readers have read a good number of frames (bounded, not timed).
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  for (uint64_t i = 1; i <= 3000 || (reads.load() < 3000 && std::chrono::steady_clock::now() < deadline); ++i) {
    Frame& f = pool.back();
    f.index = i;
    f.objects.assign(64, uint32_t(i));
    pool.publish();
  }
  stop.store(true);
  r1.join(), r2.join(), r3.join();
  EXPECT_EQ(torn.load(), 0u);
  EXPECT_GE(reads.load(), 3000u);
}

}  // namespace
}  // namespace lod
