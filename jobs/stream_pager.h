// StreamPager: the out-of-core loader of HLOD nodes (one tree's, or several trees' numbered one
// after another, sharing one budget: jobs/hlod_stream). A few loader threads read node payloads
// through a callback, in the cut's priority order, under a byte budget; the per-frame side
// (update) never waits on I/O: it takes in what finished, drops what is no longer wanted,
// evicts least-recently-used nodes the cut does not use, and hands out new reads.
//
//   frame thread                           loader threads (config.loader_threads)
//   ------------                           ---------------------------------------
//   select_hlod_cut(residency()) -> cut
//   update(frame, cut.requests, cut.kept)
//     take completions      <-- mutex --   push {node, status, payload}
//     drop stale queued     -- mutex -->   pop the most important queued node
//     evict (LRU), reserve, queue new      load(node, payload)   (no lock held)
//
// The bookkeeping (budget, LRU, states) is runtime/stream_residency; this class only moves
// nodes between it and the threads. Everything but the loaders runs on one frame thread.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "runtime/hlod_select.h"
#include "runtime/hlod_tree.h"
#include "runtime/status.h"
#include "runtime/stream_residency.h"

namespace lod {

struct StreamPagerConfig {
  uint32_t loader_threads = 2;          // [stream] loader_threads
  uint64_t budget_bytes = 64ull << 20;  // [stream] budget_mb
  uint32_t max_in_flight = 8;           // queued + being read
};

// Reads one node's payload (any source: a .hlod file, memory, the network). Called on the
// loader threads, possibly several at once (it must be safe to), for each node at most once
// per issue; an error's message says why ("truncated at byte 812"); the pager names the
// node. A payload larger than its node's resident_bytes (4 bytes per position, normal, uv and
// index value, 16 per material run, as hlod_resident_bytes counts) is refused as a failure: the budget reserved
// only that much.
using NodeLoader = std::function<Status(uint32_t node, HlodPayload& out)>;

struct StreamFailure {
  uint32_t node;
  std::string message;  // "node 17: truncated at byte 812"
  std::string why;      // the loader's message alone ("truncated at byte 812"), or the pager's reason
};

// What one update changed; valid until the next update.
struct StreamUpdate {
  std::vector<uint32_t> loaded;         // now resident
  std::vector<uint32_t> evicted;        // no longer resident
  std::vector<uint32_t> dropped;        // queued, no longer wanted, never read
  std::vector<uint32_t> issued;         // handed to the loaders
  std::vector<StreamFailure> failures;  // each failing node once, ever
};

class StreamPager {
 public:
  // Nodes 0..node_bytes.size() - 1, each taking node_bytes[i] once resident (its
  // HlodNode::resident_bytes). Starts the loader threads.
  StreamPager(std::span<const uint64_t> node_bytes, const StreamPagerConfig& config, NodeLoader load);
  // One tree's nodes.
  StreamPager(const HlodTree& tree, const StreamPagerConfig& config, NodeLoader load);
  // Stops the loaders; waits for reads in progress (their results are discarded).
  ~StreamPager();
  StreamPager(const StreamPager&) = delete;
  StreamPager& operator=(const StreamPager&) = delete;

  // Once per frame, after the cut: `wanted` = cut.requests (priority order), `in_use` =
  // cut.kept (never evicted this frame). Frames must increase.
  const StreamUpdate& update(uint64_t frame, std::span<const HlodRequest> wanted,
                             std::span<const uint32_t> in_use);

  // Frame-thread views, changed only by update.
  std::span<const uint8_t> residency() const { return state_.resident; }
  const std::shared_ptr<const HlodPayload>& payload(uint32_t node) const { return payloads_[node]; }
  const StreamCounters& counters() const { return state_.counters; }
  uint64_t resident_bytes() const { return state_.resident_bytes; }
  uint64_t reserved_bytes() const { return state_.reserved_bytes; }
  uint32_t in_flight() const { return state_.in_flight; }
  const StreamResidency& state() const { return state_; }

  struct Shared;  // the loaders' queue and completions (stream_pager.cpp)

 private:
  void take_completions(uint64_t frame);
  void requeue(uint64_t frame, std::span<const HlodRequest> wanted);

  StreamPagerConfig config_;
  StreamResidency state_;
  std::vector<std::shared_ptr<const HlodPayload>> payloads_;
  StreamUpdate update_;
  std::vector<uint32_t> too_large_;
  std::vector<uint32_t> issue_buf_, evict_buf_, too_large_buf_;  // plan_stream_loads' outputs
  std::unique_ptr<Shared> shared_;
};

}  // namespace lod
