// Stream residency: reservation accounting and an intrusive LRU list, O(1) per touch and
// per eviction.
#include "runtime/stream_residency.h"

#include <cassert>

namespace lod {
namespace {

using Node = uint32_t;
constexpr Node kNone = StreamResidency::kNone;

void lru_unlink(StreamResidency& s, Node n) {
  const Node p = s.lru_prev[n], x = s.lru_next[n];
  (p == kNone ? s.lru_head : s.lru_next[p]) = x;
  (x == kNone ? s.lru_tail : s.lru_prev[x]) = p;
  s.lru_prev[n] = s.lru_next[n] = kNone;
}

void lru_push_back(StreamResidency& s, Node n) {
  s.lru_prev[n] = s.lru_tail;
  s.lru_next[n] = kNone;
  (s.lru_tail == kNone ? s.lru_head : s.lru_next[s.lru_tail]) = n;
  s.lru_tail = n;
}

// Evicts the least recently used node unless it is in use this frame (then every node after
// it is too: in-use nodes were moved to the back this frame). Returns it, or kNone.
Node evict_one(StreamResidency& s, uint64_t frame) {
  const Node n = s.lru_head;
  if (n == kNone || s.last_used[n] == frame) return kNone;
  lru_unlink(s, n);
  s.resident[n] = 0;
  s.load[n] = uint8_t(NodeLoad::absent);
  s.resident_bytes -= s.bytes[n];
  s.reserved_bytes -= s.bytes[n];
  ++s.counters.evictions;
  return n;
}

void end_loading(StreamResidency& s, Node n, NodeLoad to) {
  assert(s.load[n] == uint8_t(NodeLoad::loading));
  s.load[n] = uint8_t(to);
  --s.in_flight;
}

}  // namespace

std::vector<uint64_t> node_bytes_of(const HlodTree& tree) {
  std::vector<uint64_t> b(tree.nodes.size());
  for (size_t i = 0; i < b.size(); ++i) b[i] = tree.nodes[i].resident_bytes;
  return b;
}

void init_stream_residency(StreamResidency& s, const HlodTree& tree, uint64_t budget_bytes) {
  init_stream_residency(s, node_bytes_of(tree), budget_bytes);
}

void init_stream_residency(StreamResidency& s, std::span<const uint64_t> node_bytes, uint64_t budget_bytes) {
  const size_t n = node_bytes.size();
  s.resident.assign(n, 0);
  s.load.assign(n, uint8_t(NodeLoad::absent));
  s.bytes.assign(node_bytes.begin(), node_bytes.end());
  s.last_used.assign(n, UINT64_MAX);
  s.wanted_in.assign(n, UINT64_MAX);
  s.rank.assign(n, 0);
  s.lru_prev.assign(n, kNone);
  s.lru_next.assign(n, kNone);
  s.lru_head = s.lru_tail = kNone;
  s.budget = budget_bytes;
  s.resident_bytes = s.reserved_bytes = 0;
  s.in_flight = 0;
  s.counters = {};
}

void mark_stream_frame(StreamResidency& s, uint64_t frame, std::span<const HlodRequest> wanted,
                       std::span<const uint32_t> in_use) {
  for (const uint32_t n : in_use) {
    if (s.last_used[n] == frame) continue;  // listed twice
    s.last_used[n] = frame;
    if (!s.resident[n]) continue;
    lru_unlink(s, n);
    lru_push_back(s, n);
  }
  for (uint32_t i = 0; i < wanted.size(); ++i) {
    s.wanted_in[wanted[i].node] = frame;
    s.rank[wanted[i].node] = i;
  }
}

StreamPlan plan_stream_loads(std::span<uint32_t> issue, std::span<uint32_t> evicted,
                             std::span<uint32_t> too_large, StreamResidency& s, uint64_t frame,
                             std::span<const HlodRequest> wanted, uint32_t max_in_flight) {
  StreamPlan plan;
  for (const HlodRequest& r : wanted) {
    if (s.in_flight >= max_in_flight) break;
    const Node n = r.node;
    if (s.load[n] != uint8_t(NodeLoad::absent)) continue;
    const uint64_t b = s.bytes[n];
    if (b > s.budget) {  // could never fit: fail it once rather than evict everything for it
      s.load[n] = uint8_t(NodeLoad::failed);
      ++s.counters.failures;
      too_large[plan.too_large++] = n;
      continue;
    }
    while (s.reserved_bytes + b > s.budget) {
      const Node e = evict_one(s, frame);
      if (e == kNone) return plan;  // everything resident is in use: wait
      evicted[plan.evicted++] = e;
    }
    s.load[n] = uint8_t(NodeLoad::loading);
    s.reserved_bytes += b;
    ++s.in_flight;
    ++s.counters.requests;
    issue[plan.issued++] = n;
  }
  return plan;
}

void stream_loaded(StreamResidency& s, uint32_t n, uint64_t frame) {
  end_loading(s, n, NodeLoad::resident);
  // Counted as used this frame, so it is not evicted before the cut has seen it.
  s.last_used[n] = frame;
  s.resident[n] = 1;
  s.resident_bytes += s.bytes[n];
  ++s.counters.loads;
  lru_push_back(s, n);
}

void stream_failed(StreamResidency& s, uint32_t n) {
  end_loading(s, n, NodeLoad::failed);
  s.reserved_bytes -= s.bytes[n];
  ++s.counters.failures;
}

void stream_dropped(StreamResidency& s, uint32_t n) {
  end_loading(s, n, NodeLoad::absent);
  s.reserved_bytes -= s.bytes[n];
  ++s.counters.dropped;
}

}  // namespace lod
