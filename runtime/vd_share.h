// The budget share of a view-dependent object: the level selection gave it sets its triangle
// target, with a hard cap 10 % (+16) above; an object cut into regions splits the cap so that
// each region keeps what it has and may grow by an equal part of the room left, and their
// sum never passes it. One pixel threshold serves all regions, moved by feedback on the sum.
#pragma once
#include <cstdint>
#include <span>

#include "runtime/vertex_front.h"

namespace lod {

inline uint64_t vd_cap_of_share(uint32_t share) { return uint64_t{share} + share / 10 + 16; }

// caps[r] for regions with region_tris[r] active triangles now. One region gets the cap.
void share_region_caps(std::span<uint32_t> caps, std::span<const uint32_t> region_tris, uint64_t cap);

// The regions' stats summed (threshold left as in `stats[0]`).
FrontStats sum_region_stats(std::span<const FrontStats> stats);

}  // namespace lod
