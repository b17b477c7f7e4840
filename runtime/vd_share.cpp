// Budget shares of view-dependent objects split over regions.
#include "runtime/vd_share.h"

#include <algorithm>
#include <cassert>

namespace lod {

void share_region_caps(std::span<uint32_t> caps, std::span<const uint32_t> region_tris, uint64_t cap) {
  assert(caps.size() == region_tris.size() && !caps.empty());
  if (caps.size() == 1) {
    caps[0] = static_cast<uint32_t>(std::min<uint64_t>(cap, UINT32_MAX));
    return;
  }
  uint64_t used = 0;
  for (uint32_t t : region_tris) used += t;
  const uint64_t room = used < cap ? (cap - used) / caps.size() : 0;
  for (size_t r = 0; r < caps.size(); ++r)
    caps[r] = static_cast<uint32_t>(std::min<uint64_t>(std::max<uint64_t>(region_tris[r] + room, 1), UINT32_MAX));
}

FrontStats sum_region_stats(std::span<const FrontStats> stats) {
  FrontStats sum;
  if (!stats.empty()) sum.threshold = stats[0].threshold;
  for (const FrontStats& st : stats) {
    sum.splits += st.splits, sum.collapses += st.collapses, sum.visited += st.visited;
    sum.blocked += st.blocked, sum.active_tris += st.active_tris;
    sum.full_pass = sum.full_pass || st.full_pass;
  }
  return sum;
}

}  // namespace lod
