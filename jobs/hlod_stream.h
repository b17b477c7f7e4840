// HlodStream: one streamed HLOD model, as one frame-graph node. Owns the model's tree, its
// pager (loader threads) and its cut; each frame selects the cut from what is resident, then
// hands the cut's requests and kept nodes to the pager:
//
//   view, transform, share of M --> select_hlod_cut(residency) --> cut --> pager.update
//                                                                   |
//                                                 drawn layers + opened boundaries to draw
//
// The frame never waits on I/O (StreamPager::update does not). Not thread-safe: one frame
// thread calls frame(); the payloads of the cut's nodes stay valid until the next frame().
#pragma once
#include <cstdint>

#include "jobs/stream_pager.h"
#include "runtime/hlod_select.h"
#include "runtime/hlod_tree.h"

namespace lod {

// The figures `lod run --json` reports per frame for HLOD models.
struct HlodStreamFigures {
  uint32_t hlod_nodes_drawn = 0;
  uint64_t hlod_triangles = 0;   // drawn layers + opened boundaries
  uint64_t resident_bytes = 0;
  uint64_t stream_requests = 0;  // loads issued so far
  uint64_t stream_loads = 0;     // completed so far
  uint64_t stream_failures = 0;
  uint64_t stream_evictions = 0;
  uint32_t holes = 0;            // requested nodes with no drawn ancestor (only a missing root)
  uint32_t wanted = 0;           // this frame's requests
};

class HlodStream {
 public:
  HlodStream(HlodTree tree, const StreamPagerConfig& config, NodeLoader load);

  // One frame: the cut for this view and transform under `params`, then the pager's update.
  // `frame` must increase from call to call.
  const HlodCut& frame(uint64_t frame, const Transform& transform, const HlodView& view,
                       const HlodSelectParams& params);

  const HlodTree& tree() const { return tree_; }
  const HlodCut& cut() const { return cut_; }
  const StreamUpdate& last_update() const { return *update_; }
  const StreamPager& pager() const { return pager_; }
  const std::shared_ptr<const HlodPayload>& payload(uint32_t node) const { return pager_.payload(node); }
  HlodStreamFigures figures() const;

 private:
  HlodTree tree_;  // before pager_: the pager keeps a reference to it
  StreamPager pager_;
  HlodCut cut_;
  HlodCutScratch scratch_;
  const StreamUpdate* update_ = nullptr;
  StreamUpdate none_;
};

}  // namespace lod
