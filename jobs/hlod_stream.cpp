// HlodStream: select, then page, once per frame.
#include "jobs/hlod_stream.h"

#include <utility>

namespace lod {

HlodStream::HlodStream(HlodTree tree, const StreamPagerConfig& config, NodeLoader load)
    : tree_(std::move(tree)), pager_(tree_, config, std::move(load)), update_(&none_) {
  prepare_hlod_cut(cut_, scratch_, tree_);
}

const HlodCut& HlodStream::frame(uint64_t frame, const Transform& transform, const HlodView& view,
                                 const HlodSelectParams& params) {
  select_hlod_cut(cut_, scratch_, tree_, pager_.residency(), transform, view, params);
  update_ = &pager_.update(frame, cut_.requests, cut_.kept);
  return cut_;
}

HlodStreamFigures HlodStream::figures() const {
  HlodStreamFigures f;
  const StreamCounters& c = pager_.counters();
  f.hlod_nodes_drawn = uint32_t(cut_.drawn.size());
  f.hlod_triangles = cut_.triangles;
  f.resident_bytes = pager_.resident_bytes();
  f.stream_requests = c.requests;
  f.stream_loads = c.loads;
  f.stream_failures = c.failures;
  f.stream_evictions = c.evictions;
  f.holes = cut_.holes;
  f.wanted = uint32_t(cut_.requests.size());
  return f;
}

}  // namespace lod
