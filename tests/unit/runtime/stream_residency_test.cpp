// Stream residency without threads: the reservation, the in-flight cap, the priority order,
// LRU eviction and what is never evicted.
#include "runtime/stream_residency.h"

#include <gtest/gtest.h>

#include <vector>

#include "unit/runtime/hlod_fixtures.h"

namespace lod {
namespace {

struct Planner {
  StreamResidency s;
  std::vector<uint32_t> issue, evicted, too_large;
  Planner(const HlodTree& t, uint64_t budget) {
    init_stream_residency(s, t, budget);
    issue.resize(t.nodes.size());
    evicted.resize(t.nodes.size());
    too_large.resize(t.nodes.size());
  }
  StreamPlan plan(uint64_t frame, const std::vector<HlodRequest>& wanted, const std::vector<uint32_t>& in_use,
                  uint32_t max_in_flight = 64) {
    mark_stream_frame(s, frame, wanted, in_use);
    return plan_stream_loads(issue, evicted, too_large, s, frame, wanted, max_in_flight);
  }
};

std::vector<HlodRequest> wanted_of(std::initializer_list<uint32_t> nodes) {
  std::vector<HlodRequest> r;
  for (uint32_t n : nodes) r.push_back({n, 1, 1});
  return r;
}

HlodTree leaves_of_equal_size() { return test::full_octree({.depth = 1}); }  // nodes 1..8 alike

TEST(StreamResidency, ReservesBeforeIssuingAndCapsInFlight) {
  const HlodTree t = leaves_of_equal_size();
  const uint64_t b = t.nodes[1].resident_bytes;
  Planner p(t, 10 * b);
  const StreamPlan plan = p.plan(1, wanted_of({1, 2, 3, 4, 5}), {}, 3);
  ASSERT_EQ(plan.issued, 3u);
  EXPECT_EQ(p.issue[0], 1u);  // in the requests' order
  EXPECT_EQ(p.issue[2], 3u);
  EXPECT_EQ(p.s.reserved_bytes, 3 * b);
  EXPECT_EQ(p.s.resident_bytes, 0u);
  EXPECT_EQ(p.s.in_flight, 3u);
  EXPECT_EQ(p.plan(2, wanted_of({1, 2, 3, 4, 5}), {}, 3).issued, 0u);  // capped, and not issued twice
  stream_loaded(p.s, 1, 2);
  EXPECT_EQ(p.s.resident_bytes, b);
  EXPECT_EQ(p.s.reserved_bytes, 3 * b);
  const StreamPlan next = p.plan(3, wanted_of({1, 2, 3, 4, 5}), {}, 3);
  ASSERT_EQ(next.issued, 1u);
  EXPECT_EQ(p.issue[0], 4u);
}

TEST(StreamResidency, StopsAtTheFirstRequestItCannotMakeRoomFor) {
  const HlodTree t = leaves_of_equal_size();
  const uint64_t b = t.nodes[1].resident_bytes;
  Planner p(t, 2 * b);
  ASSERT_EQ(p.plan(1, wanted_of({1, 2}), {}).issued, 2u);
  stream_loaded(p.s, 1, 1);
  stream_loaded(p.s, 2, 1);
  // Both in use: node 3 cannot get room, and node 4 behind it is not issued either.
  const StreamPlan plan = p.plan(2, wanted_of({3, 4}), {1, 2});
  EXPECT_EQ(plan.issued, 0u);
  EXPECT_EQ(plan.evicted, 0u);
  EXPECT_EQ(p.s.reserved_bytes, 2 * b);
}

TEST(StreamResidency, EvictsTheLeastRecentlyUsedAndNeverANodeInUse) {
  const HlodTree t = leaves_of_equal_size();
  const uint64_t b = t.nodes[1].resident_bytes;
  Planner p(t, 3 * b);
  p.plan(1, wanted_of({1, 2, 3}), {});
  for (uint32_t n : {1u, 2u, 3u}) stream_loaded(p.s, n, 1);
  p.plan(2, {}, {2});
  p.plan(3, {}, {1});  // least recently used first: 3, 2, 1
  StreamPlan plan = p.plan(4, wanted_of({4}), {});
  ASSERT_EQ(plan.evicted, 1u);
  EXPECT_EQ(p.evicted[0], 3u);
  EXPECT_EQ(p.s.counters.evictions, 1u);
  EXPECT_FALSE(p.s.resident[3]);
  stream_loaded(p.s, 4, 5);  // counted as used in frame 5: not evicted in it
  plan = p.plan(5, wanted_of({5, 6}), {2});
  EXPECT_EQ(plan.evicted, 1u);
  EXPECT_EQ(p.evicted[0], 1u);  // 2 in use, 4 just loaded: 1 goes
  EXPECT_EQ(plan.issued, 1u);   // and 6 waits
  EXPECT_LE(p.s.reserved_bytes, 3 * b);
}

TEST(StreamResidency, FailedNodesAreNeverIssuedAgainDroppedOnesAre) {
  const HlodTree t = leaves_of_equal_size();
  Planner p(t, 1ull << 30);
  p.plan(1, wanted_of({1, 2}), {});
  stream_failed(p.s, 1);
  stream_dropped(p.s, 2);
  EXPECT_EQ(p.s.reserved_bytes, 0u);
  EXPECT_EQ(p.s.in_flight, 0u);
  const StreamPlan plan = p.plan(2, wanted_of({1, 2}), {});
  ASSERT_EQ(plan.issued, 1u);
  EXPECT_EQ(p.issue[0], 2u);
  EXPECT_EQ(p.s.counters.failures, 1u);
  EXPECT_EQ(p.s.counters.dropped, 1u);
}

TEST(StreamResidency, NodeLargerThanTheBudgetFailsWithoutEvictingAnything) {
  const HlodTree t = test::full_octree({.depth = 1});
  const uint64_t leaf = t.nodes[1].resident_bytes;
  ASSERT_GT(t.nodes[0].resident_bytes, leaf);  // the root carries a boundary patch too
  Planner p(t, leaf);
  p.plan(1, wanted_of({1}), {});
  stream_loaded(p.s, 1, 1);
  const StreamPlan plan = p.plan(2, wanted_of({0}), {});
  ASSERT_EQ(plan.too_large, 1u);
  EXPECT_EQ(p.too_large[0], 0u);
  EXPECT_EQ(plan.evicted, 0u);
  EXPECT_TRUE(p.s.resident[1]);
  EXPECT_EQ(p.plan(3, wanted_of({0}), {}).too_large, 0u);  // once
}

}  // namespace
}  // namespace lod
