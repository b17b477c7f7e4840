// Crack check of an HLOD cut: does the drawn geometry open any hole the model does not have?
//
// A cut gives every node one state: a layer drawn, opened (its boundary patch drawn, its
// children in the cut), or outside the cut (below a drawn node). Edges are matched by their
// endpoints' exact positions: patches and the vertices locked below them are original vertices,
// bit for bit, so wherever layers meet correctly their edges coincide exactly.
#pragma once
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "runtime/hlod_tree.h"

namespace lod {

inline constexpr int8_t kHlodCutOpened = -1;   // boundary drawn, children in the cut
inline constexpr int8_t kHlodCutOutside = -2;  // not in the cut (an ancestor is drawn)

// True when `cut` (one state per node) is a cut: the root is in it, an opened node's children
// are in it, every other node's children are outside, every drawn layer exists. Otherwise
// `message` names the first node at fault.
bool validate_hlod_cut(const HlodTree& tree, std::span<const int8_t> cut, std::string* message);

namespace detail {
struct PositionKey {
  uint32_t x, y, z;  // float bits, -0 folded into +0
  bool operator==(const PositionKey&) const = default;
};
struct PositionHash {
  size_t operator()(const PositionKey& k) const;
};
}  // namespace detail

// What a model's own surface leaves open, learnt once from its finest cut (every leaf's
// layer 0 and every patch: the original mesh).
struct HlodCutReference {
  std::unordered_map<detail::PositionKey, uint32_t, detail::PositionHash> ids;  // vertex per position
  std::unordered_set<uint64_t> open_edges;  // used by one original triangle
};

// `payloads[i]` is node i's geometry; every one must be given (nullptr: that node adds nothing).
HlodCutReference hlod_cut_reference(const HlodTree& tree, std::span<const HlodPayload* const> payloads);

// Edges of the cut's drawn triangles (drawn layers, opened nodes' patches) used by exactly one
// of them and not open in the original: each is a crack or a hole the cut made. Only the cut's
// nodes' payloads are read; a drawn node without one contributes nothing, so its neighbours'
// edges count as gaps (a missing node is a hole). The cut must pass validate_hlod_cut.
// Thread-safe (const inputs, local scratch).
size_t count_cut_gaps(const HlodTree& tree, std::span<const HlodPayload* const> payloads, std::span<const int8_t> cut,
                      const HlodCutReference& reference);

}  // namespace lod
