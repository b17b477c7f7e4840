// StreamPager: loader threads, the byte budget, LRU eviction, stale drops, failures, and
// select + update on a moving camera (run under ThreadSanitizer: scripts/run-tests.sh).
#include "jobs/stream_pager.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <stdexcept>
#include <thread>

#include "runtime/hlod_select.h"
#include "unit/runtime/hlod_fixtures.h"

namespace lod {
namespace {

using namespace std::chrono_literals;

// An in-memory source: node i's payload has one level per layer, and its first index is i
// (so a test can tell whose payload it holds).
Status synthetic_payload(const HlodTree& t, uint32_t node, HlodPayload& out) {
  const HlodNode& n = t.nodes[node];
  out.layers.resize(n.layer_count);
  uint32_t first = 0;
  for (uint32_t l = 0; l < n.layer_count; ++l) {
    out.layers[l].first_index = first;
    out.layers[l].index_count = 3 * std::min(n.layers[l].triangles, 8u);
    out.layers[l].error = n.layers[l].error;
    first += out.layers[l].index_count;
  }
  out.indices.assign(first + 1, node);
  out.positions.assign(9, float(node));
  out.normals.assign(9, 0.f);
  return Status::success();
}

// Records which nodes were read, how often.
struct ReadLog {
  std::mutex mutex;
  std::map<uint32_t, int> reads;
  void add(uint32_t n) {
    std::lock_guard lock(mutex);
    ++reads[n];
  }
  int count(uint32_t n) {
    std::lock_guard lock(mutex);
    return reads.count(n) ? reads[n] : 0;
  }
};

// Calls update on increasing frames until `done` holds (or 10 s pass).
template <class Done>
bool pump(StreamPager& pager, uint64_t& frame, std::span<const HlodRequest> wanted,
          std::span<const uint32_t> in_use, Done done) {
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (std::chrono::steady_clock::now() < until) {
    pager.update(++frame, wanted, in_use);
    if (done()) return true;
    std::this_thread::sleep_for(200us);
  }
  return false;
}

std::vector<HlodRequest> requests_for(std::initializer_list<uint32_t> nodes) {
  std::vector<HlodRequest> r;
  float deficit = 100;
  for (uint32_t n : nodes) r.push_back({n, deficit--, 1});
  return r;
}

TEST(StreamPager, EvictsLeastRecentlyUsedFirstAndNeverWhatIsInUse) {
  const HlodTree t = test::full_octree({.depth = 1});  // nodes 1..8: leaves of equal size
  const uint64_t node_bytes = t.nodes[1].resident_bytes;
  StreamPager pager(t, {.loader_threads = 1, .budget_bytes = 3 * node_bytes, .max_in_flight = 4},
                    [&](uint32_t n, HlodPayload& out) { return synthetic_payload(t, n, out); });
  uint64_t frame = 0;
  const std::vector<uint32_t> none;
  auto load = [&](uint32_t n, const std::vector<uint32_t>& in_use) {
    const auto wanted = requests_for({n});
    return pump(pager, frame, wanted, in_use, [&] { return pager.residency()[n] != 0; });
  };
  ASSERT_TRUE(load(1, none));
  ASSERT_TRUE(load(2, none));
  ASSERT_TRUE(load(3, none));
  EXPECT_EQ(pager.resident_bytes(), 3 * node_bytes);
  const std::vector<uint32_t> one{1};
  pager.update(++frame, {}, one);  // 1 used last: the order is now 2, 3, 1
  ASSERT_TRUE(load(4, none));
  EXPECT_FALSE(pager.residency()[2]);
  EXPECT_TRUE(pager.residency()[1] && pager.residency()[3]);
  const std::vector<uint32_t> four{4};
  ASSERT_TRUE(load(5, four));
  EXPECT_FALSE(pager.residency()[3]);
  EXPECT_TRUE(pager.residency()[1] && pager.residency()[4] && pager.residency()[5]);
  // Everything resident in use: node 6 waits, nothing is evicted.
  const std::vector<uint32_t> all{1, 4, 5};
  const auto six = requests_for({6});
  for (int i = 0; i < 20; ++i) {
    const StreamUpdate& u = pager.update(++frame, six, all);
    EXPECT_TRUE(u.evicted.empty());
    EXPECT_TRUE(u.issued.empty());
  }
  // Released: 1, the least recently used, goes.
  ASSERT_TRUE(load(6, four));
  EXPECT_FALSE(pager.residency()[1]);
  EXPECT_EQ(pager.counters().evictions, 3u);
  EXPECT_LE(pager.resident_bytes(), 3 * node_bytes);
}

TEST(StreamPager, DropsStaleRequestsBeforeTheyAreRead) {
  const HlodTree t = test::full_octree({.depth = 1});
  ReadLog log;
  std::mutex gate_mutex;
  std::condition_variable gate_cv;
  bool open = false;
  std::atomic<bool> first_started{false};
  StreamPager pager(t, {.loader_threads = 1, .budget_bytes = 1ull << 30, .max_in_flight = 4},
                    [&](uint32_t n, HlodPayload& out) {
                      log.add(n);
                      first_started = true;
                      std::unique_lock lock(gate_mutex);
                      gate_cv.wait(lock, [&] { return open; });
                      return synthetic_payload(t, n, out);
                    });
  uint64_t frame = 0;
  const auto first = requests_for({1, 2, 3});
  const StreamUpdate& u1 = pager.update(++frame, first, {});
  EXPECT_EQ(u1.issued.size(), 3u);
  while (!first_started) std::this_thread::sleep_for(100us);  // node 1 (the most important) is being read
  const auto second = requests_for({4});
  const StreamUpdate& u2 = pager.update(++frame, second, {});
  EXPECT_EQ(std::set<uint32_t>(u2.dropped.begin(), u2.dropped.end()), (std::set<uint32_t>{2, 3}));
  {
    std::lock_guard lock(gate_mutex);
    open = true;
  }
  gate_cv.notify_all();
  ASSERT_TRUE(pump(pager, frame, second, {}, [&] { return pager.residency()[4] != 0; }));
  EXPECT_EQ(log.count(1), 1);
  EXPECT_EQ(log.count(4), 1);
  EXPECT_EQ(log.count(2), 0);
  EXPECT_EQ(log.count(3), 0);
  EXPECT_EQ(pager.counters().dropped, 2u);
  EXPECT_EQ(pager.reserved_bytes(), pager.resident_bytes());
}

TEST(StreamPager, FailuresAreReportedOnceNeverRetriedAndTheParentStaysDrawn) {
  const HlodTree t = test::full_octree({.depth = 1});
  ReadLog log;
  StreamPager pager(t, {.loader_threads = 2, .budget_bytes = 1ull << 30, .max_in_flight = 8},
                    [&](uint32_t n, HlodPayload& out) -> Status {
                      log.add(n);
                      if (n == 3) return Status::error("truncated at byte 812");
                      if (n == 5) throw std::runtime_error("checksum mismatch");
                      return synthetic_payload(t, n, out);
                    });
  HlodCut cut;
  HlodCutScratch scratch;
  prepare_hlod_cut(cut, scratch, t);
  View v;
  v.eye = {0, 0, 70};  // inside the root's bounds: it wants to open
  v.target = {0, 0, 0};
  std::vector<StreamFailure> failures;
  uint64_t frame = 0;
  // Until both failed and nothing is in flight, then 200 frames more: never reported again.
  for (int i = 0, after = 0; i < 40000 && after < 200; ++i) {
    if (failures.size() >= 2 && pager.in_flight() == 0) ++after;
    select_hlod_cut(cut, scratch, t, pager.residency(), {}, hlod_view_of(v), {1.0f, UINT64_MAX});
    if (pager.residency()[0]) {
      EXPECT_EQ(cut.holes, 0u);
    }
    const StreamUpdate& u = pager.update(++frame, cut.requests, cut.kept);
    failures.insert(failures.end(), u.failures.begin(), u.failures.end());
    std::this_thread::sleep_for(200us);
  }
  ASSERT_EQ(failures.size(), 2u);
  std::sort(failures.begin(), failures.end(), [](auto& a, auto& b) { return a.node < b.node; });
  EXPECT_EQ(failures[0].node, 3u);
  EXPECT_NE(failures[0].message.find("node 3"), std::string::npos) << failures[0].message;
  EXPECT_NE(failures[0].message.find("truncated at byte 812"), std::string::npos) << failures[0].message;
  EXPECT_EQ(failures[1].node, 5u);
  EXPECT_NE(failures[1].message.find("checksum mismatch"), std::string::npos) << failures[1].message;
  EXPECT_EQ(log.count(3), 1);
  EXPECT_EQ(log.count(5), 1);
  EXPECT_EQ(pager.counters().failures, 2u);
  EXPECT_FALSE(pager.residency()[3]);
  // The root waits for its two failed children forever: drawn, never opened.
  ASSERT_EQ(cut.drawn.size(), 1u);
  EXPECT_EQ(cut.drawn[0].node, 0u);
  EXPECT_TRUE(cut.opened.empty());
  EXPECT_EQ(pager.reserved_bytes(), pager.resident_bytes());
}

TEST(StreamPager, PayloadLargerThanItsNodeRecordsIsRefused) {
  const HlodTree t = test::full_octree({.depth = 1});
  StreamPager pager(t, {.loader_threads = 1, .budget_bytes = 1ull << 30, .max_in_flight = 2},
                    [&](uint32_t n, HlodPayload& out) {
                      synthetic_payload(t, n, out);
                      if (n == 2)
                        out.indices.resize(t.nodes[n].resident_bytes / 4 + 1);  // one index too many
                      return Status::success();
                    });
  uint64_t frame = 0;
  const auto wanted = requests_for({1, 2});
  std::vector<StreamFailure> failures;
  for (int i = 0; i < 20000 && !(pager.residency()[1] && !failures.empty()); ++i) {
    for (const StreamFailure& f : pager.update(++frame, wanted, {}).failures) failures.push_back(f);
    std::this_thread::sleep_for(200us);
  }
  for (int i = 0; i < 20; ++i) {  // and never again
    for (const StreamFailure& f : pager.update(++frame, wanted, {}).failures) failures.push_back(f);
  }
  ASSERT_EQ(failures.size(), 1u);
  EXPECT_EQ(failures[0].node, 2u);
  EXPECT_NE(failures[0].message.find("node 2: its payload takes"), std::string::npos) << failures[0].message;
  EXPECT_FALSE(pager.residency()[2]);
  EXPECT_FALSE(pager.payload(2));
  EXPECT_EQ(pager.reserved_bytes(), pager.resident_bytes());
}

TEST(StreamPager, NodeLargerThanTheBudgetFailsOnceUnread) {
  const HlodTree t = test::full_octree({.depth = 1});
  ReadLog log;
  StreamPager pager(t,
                    {.loader_threads = 1, .budget_bytes = t.nodes[1].resident_bytes - 1, .max_in_flight = 2},
                    [&](uint32_t n, HlodPayload& out) {
                      log.add(n);
                      return synthetic_payload(t, n, out);
                    });
  uint64_t frame = 0;
  const auto wanted = requests_for({1});
  size_t failures = 0;
  for (int i = 0; i < 10; ++i) {
    const StreamUpdate& u = pager.update(++frame, wanted, {});
    for (const StreamFailure& f : u.failures) {
      ++failures;
      EXPECT_NE(f.message.find("node 1: needs"), std::string::npos) << f.message;
    }
  }
  EXPECT_EQ(failures, 1u);
  EXPECT_EQ(log.count(1), 0);
}

TEST(StreamPager, ResidentBytesNeverExceedTheBudget) {
  const HlodTree t = test::random_octree(21, 600, 5);
  uint64_t total = 0;
  for (const HlodNode& n : t.nodes) total += n.resident_bytes;
  const uint64_t budget = total / 10;
  StreamPager pager(t, {.loader_threads = 3, .budget_bytes = budget, .max_in_flight = 6},
                    [&](uint32_t n, HlodPayload& out) {
                      std::this_thread::sleep_for(std::chrono::microseconds(n % 7 * 50));
                      return synthetic_payload(t, n, out);
                    });
  std::mt19937 rng(4);
  uint64_t frame = 0;
  std::vector<HlodRequest> wanted;
  std::vector<uint32_t> in_use;
  // 400 frames at least, and on until the budget has made it evict and requests were dropped
  // (how soon depends on how much CPU the loaders get, not on the pager).
  for (int i = 0;
       i < 400 || ((pager.counters().evictions <= 20 || pager.counters().dropped == 0) && i < 40000); ++i) {
    wanted.clear();
    in_use.clear();
    for (uint32_t k = 0, m = rng() % 40; k < m; ++k) {
      const uint32_t n = uint32_t(rng() % t.nodes.size());
      if (std::none_of(wanted.begin(), wanted.end(), [&](auto& r) { return r.node == n; }))
        wanted.push_back({n, float(rng() % 100), 1});
    }
    std::sort(wanted.begin(), wanted.end(), request_before);
    for (uint32_t n = 0; n < t.nodes.size(); ++n)
      if (pager.residency()[n] && rng() % 4 == 0) in_use.push_back(n);
    const StreamUpdate& u = pager.update(++frame, wanted, in_use);
    for (uint32_t e : u.evicted)
      EXPECT_EQ(std::count(in_use.begin(), in_use.end(), e), 0) << "evicted in use";
    ASSERT_LE(pager.reserved_bytes(), budget);
    ASSERT_LE(pager.resident_bytes(), pager.reserved_bytes());
    ASSERT_LE(pager.in_flight(), 6u);
    uint64_t held = 0;
    for (uint32_t n = 0; n < t.nodes.size(); ++n) {
      EXPECT_EQ(pager.residency()[n] != 0, pager.payload(n) != nullptr) << n;
      if (pager.residency()[n]) held += t.nodes[n].resident_bytes;
    }
    ASSERT_EQ(held, pager.resident_bytes());
    if (i % 3 == 0) std::this_thread::sleep_for(300us);
  }
  EXPECT_GT(pager.counters().evictions, 20u);  // the budget was tight enough to matter
  EXPECT_GT(pager.counters().dropped, 0u);
}

// Select + update each frame over a moving camera: the cut never has a hole once the root is
// in, draws only resident nodes whose payload is theirs, and the pager never evicts them.
void fly_through(uint32_t loader_threads) {
  const HlodTree t = test::full_octree({.depth = 4, .half = 64, .root_error = 16, .triangles = 400});
  uint64_t total = 0;
  for (const HlodNode& n : t.nodes) total += n.resident_bytes;
  const uint64_t budget = total / 6;
  std::atomic<uint64_t> reads{0};
  StreamPager pager(
      t, {.loader_threads = loader_threads, .budget_bytes = budget, .max_in_flight = 2 * loader_threads},
      [&](uint32_t n, HlodPayload& out) {
        ++reads;
        std::this_thread::sleep_for(std::chrono::microseconds(100 + n % 5 * 100));
        return synthetic_payload(t, n, out);
      });
  HlodCut cut;
  HlodCutScratch scratch;
  prepare_hlod_cut(cut, scratch, t);
  uint64_t frame = 0;
  uint64_t drawn_total = 0, opened_total = 0;
  // 600 frames at least, and on until enough has been loaded and evicted (how soon depends
  // on how much CPU the loaders get).
  auto enough = [&] {
    return pager.counters().loads > 50 && pager.counters().evictions > 0 && opened_total > 0;
  };
  for (int i = 0; i < 600 || (!enough() && i < 40000); ++i) {
    const float a = float(i) * 0.02f;
    View v;
    v.eye = glm::vec3(150 * std::cos(a), 30 * std::sin(3 * a), 150 * std::sin(a)) *
            (0.6f + 0.4f * std::cos(0.5f * a));
    v.target = glm::vec3(0, 0, 0);
    v.far_plane = 1e4f;
    select_hlod_cut(cut, scratch, t, pager.residency(), {}, hlod_view_of(v), {1.0f, UINT64_MAX});
    if (pager.residency()[0]) {
      ASSERT_EQ(cut.holes, 0u) << "frame " << i;
    }
    for (const HlodDraw& d : cut.drawn) {
      const auto& p = pager.payload(d.node);
      ASSERT_TRUE(p) << "frame " << i << " node " << d.node;
      ASSERT_EQ(p->indices.front(), d.node);
    }
    for (uint32_t o : cut.opened) ASSERT_TRUE(pager.payload(o));
    drawn_total += cut.drawn.size();
    opened_total += cut.opened.size();
    pager.update(++frame, cut.requests, cut.kept);
    ASSERT_LE(pager.reserved_bytes(), budget);
    for (const HlodDraw& d : cut.drawn) ASSERT_TRUE(pager.residency()[d.node]) << "evicted while drawn";
    std::this_thread::sleep_for(300us);
  }
  EXPECT_TRUE(enough()) << "loads " << pager.counters().loads << " evictions " << pager.counters().evictions;
  EXPECT_GT(drawn_total, 0u);
  EXPECT_EQ(pager.counters().failures, 0u);
}

TEST(StreamPager, MovingCameraNeverHasAHoleWithTwoLoaders) { fly_through(2); }
TEST(StreamPager, MovingCameraNeverHasAHoleWithFourLoaders) { fly_through(4); }

TEST(StreamPager, StreamedCutConvergesToTheFullyResidentCut) {
  const HlodTree t = test::full_octree({.depth = 3});
  StreamPager pager(t, {.loader_threads = 2, .budget_bytes = 1ull << 30, .max_in_flight = 4},
                    [&](uint32_t n, HlodPayload& out) { return synthetic_payload(t, n, out); });
  HlodCut cut, full;
  HlodCutScratch scratch, full_scratch;
  prepare_hlod_cut(cut, scratch, t);
  prepare_hlod_cut(full, full_scratch, t);
  View v;
  v.eye = {40, 30, 120};
  v.target = {0, 0, 0};
  const std::vector<uint8_t> all(t.nodes.size(), 1);
  select_hlod_cut(full, full_scratch, t, all, {}, hlod_view_of(v), {1.0f, UINT64_MAX});
  uint64_t frame = 0;
  const auto until = std::chrono::steady_clock::now() + 10s;
  do {
    select_hlod_cut(cut, scratch, t, pager.residency(), {}, hlod_view_of(v), {1.0f, UINT64_MAX});
    pager.update(++frame, cut.requests, cut.kept);
    std::this_thread::sleep_for(200us);
  } while (!cut.requests.empty() && std::chrono::steady_clock::now() < until);
  ASSERT_TRUE(cut.requests.empty());
  ASSERT_EQ(cut.drawn.size(), full.drawn.size());
  for (size_t i = 0; i < cut.drawn.size(); ++i) {
    EXPECT_EQ(cut.drawn[i].node, full.drawn[i].node);
    EXPECT_EQ(cut.drawn[i].layer, full.drawn[i].layer);
  }
  EXPECT_GT(full.opened.size(), 1u);
}

}  // namespace
}  // namespace lod
