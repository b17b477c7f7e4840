// One budget M for two kinds of geometry selected by different passes (discrete levels, HLOD
// cuts): when what both ask for at the pixel threshold fits, each takes what it asks; when it
// does not, M is split in proportion to the demands, so both give up detail together instead
// of the pass that runs first starving the other.
#pragma once
#include <cstdint>

namespace lod {

// The first pass's part of `budget` given both demands (triangles at the pixel threshold).
inline uint64_t first_share(uint64_t budget, uint64_t first_demand, uint64_t second_demand) {
  const unsigned __int128 total = (unsigned __int128)first_demand + second_demand;
  if (total <= budget || second_demand == 0) return budget;
  return uint64_t((unsigned __int128)budget * first_demand / total);
}

}  // namespace lod
