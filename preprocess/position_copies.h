// Vertices that share a position: the copies an attribute seam (uv, normal or material) leaves,
// one per side. The QEM simplifier moves a pair of them only along its seam; the vertex
// hierarchy pins them. Both find them here, so both agree on what a seam is.
#pragma once
#include <cstddef>
#include <cstdint>
#include <span>

namespace lod {

inline constexpr uint32_t kNoCopy = ~0u;

// first[v] = the lowest-numbered vertex whose position equals v's bit for bit (v itself when
// none comes before it); kNoCopy where `usable` (optional, per vertex) is 0. Returns, per
// vertex, how many share its position in `copies` (optional, sized like `first`; 0 for
// unusable ones). Linear expected time (an open-addressing table of the positions' bits).
void find_position_copies(std::span<uint32_t> first, std::span<uint32_t> copies, const float* positions,
                          size_t vertex_count, const uint8_t* usable = nullptr);

}  // namespace lod
