// Stream residency: which HLOD nodes are loaded, loading or failed, under a byte budget, and
// which to load or evict next. The bookkeeping of the out-of-core pager (jobs/stream_pager),
// kept here as plain single-threaded state: jobs/ only moves nodes between this and its
// loader threads.
//
// Rules:
//   - bytes are reserved when a load is issued, so resident + loading <= budget always, however
//     the loads complete (reserved_bytes is what the budget bounds);
//   - loads are issued in the order of the cut's requests (hlod_select's priority), at most
//     `max_in_flight` at a time; the first request that cannot be made room for stops the
//     pass (so a large important node is not starved by small unimportant ones);
//   - room is made by evicting resident nodes least recently used first, never one in use
//     this frame (the cut draws, opens or waits with it);
//   - a failed node stays failed: never issued again, so its parent stays drawn.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "runtime/hlod_select.h"
#include "runtime/hlod_tree.h"

namespace lod {

enum class NodeLoad : uint8_t { absent, loading, resident, failed };

struct StreamCounters {
  uint64_t requests = 0;  // loads issued (bytes reserved)
  uint64_t loads = 0;     // completed
  uint64_t failures = 0;  // completed with an error, or larger than the whole budget
  uint64_t evictions = 0;
  uint64_t dropped = 0;  // issued, no longer wanted, dropped before they were read
};

struct StreamResidency {
  // Per node, by id.
  std::vector<uint8_t> resident;    // 1 when loaded: the span select_hlod_cut reads
  std::vector<uint8_t> load;        // NodeLoad
  std::vector<uint64_t> bytes;      // HlodNode::resident_bytes
  std::vector<uint64_t> last_used;  // frame it was last in use (UINT64_MAX: never)
  std::vector<uint64_t> wanted_in;  // frame it was last requested
  std::vector<uint32_t> rank;       // its index in that frame's requests
  // Resident nodes in least-recently-used order, a doubly linked list through node ids.
  std::vector<uint32_t> lru_prev, lru_next;
  uint32_t lru_head = kNone, lru_tail = kNone;

  uint64_t budget = 0;
  uint64_t resident_bytes = 0;
  uint64_t reserved_bytes = 0;  // resident + loading: never above budget
  uint32_t in_flight = 0;       // loading
  StreamCounters counters;

  static constexpr uint32_t kNone = UINT32_MAX;
};

// Over any flat node space: one entry of `node_bytes` per node (several trees can share one
// residency, their nodes numbered one after another).
void init_stream_residency(StreamResidency& s, std::span<const uint64_t> node_bytes, uint64_t budget_bytes);
void init_stream_residency(StreamResidency& s, const HlodTree& tree, uint64_t budget_bytes);

// The nodes' resident_bytes, by id.
std::vector<uint64_t> node_bytes_of(const HlodTree& tree);

// Marks this frame: `in_use` nodes move to the most-recently-used end, `wanted` nodes get
// their rank (index) for this frame.
void mark_stream_frame(StreamResidency& s, uint64_t frame, std::span<const HlodRequest> wanted,
                       std::span<const uint32_t> in_use);

// True when `node` was requested in `frame` (after mark_stream_frame).
inline bool stream_wanted(const StreamResidency& s, uint32_t node, uint64_t frame) {
  return s.wanted_in[node] == frame;
}

struct StreamPlan {
  uint32_t issued = 0;     // written to `issue`
  uint32_t evicted = 0;    // written to `evicted`
  uint32_t too_large = 0;  // written to `too_large`: failed, larger than the budget
};

// Issues loads for `wanted` (in its order) that are absent, evicting as needed. `issue` needs
// room for max_in_flight, `evicted` for every node, `too_large` for wanted.size().
StreamPlan plan_stream_loads(std::span<uint32_t> issue, std::span<uint32_t> evicted,
                             std::span<uint32_t> too_large, StreamResidency& s, uint64_t frame,
                             std::span<const HlodRequest> wanted, uint32_t max_in_flight);

// A load issued by plan_stream_loads ended: loaded (counted as used in `frame`, the one whose
// update takes it in, so it is not evicted before the cut has seen it), failed (reservation
// released, never issued again) or dropped unread (reservation released, may be issued again).
// Call them before mark_stream_frame of the same frame.
void stream_loaded(StreamResidency& s, uint32_t node, uint64_t frame);
void stream_failed(StreamResidency& s, uint32_t node);
void stream_dropped(StreamResidency& s, uint32_t node);

}  // namespace lod
