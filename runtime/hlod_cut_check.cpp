// Cut crack check: count every undirected edge of the drawn triangles by exact endpoint
// positions; an edge seen once is open, and open edges the original does not have are gaps.
#include "runtime/hlod_cut_check.h"

#include <bit>
#include <cassert>
#include <vector>

namespace lod {
namespace detail {
size_t PositionHash::operator()(const PositionKey& k) const {
  uint64_t h = (uint64_t(k.x) * 0x9e3779b97f4a7c15ull) ^ (uint64_t(k.y) * 0xc2b2ae3d27d4eb4full);
  h ^= uint64_t(k.z) * 0x165667b19e3779f9ull;
  return size_t(h ^ (h >> 29));
}
}  // namespace detail

namespace {

detail::PositionKey key_of(const float* p) {
  auto bits = [](float v) { return std::bit_cast<uint32_t>(v == 0.0f ? 0.0f : v); };
  return {bits(p[0]), bits(p[1]), bits(p[2])};
}

uint64_t edge_key(uint32_t a, uint32_t b) { return a < b ? (uint64_t(a) << 32 | b) : (uint64_t(b) << 32 | a); }

// Numbers positions (the reference's first, then any new ones) and counts edges.
struct EdgeCount {
  const HlodCutReference* reference = nullptr;
  std::unordered_map<detail::PositionKey, uint32_t, detail::PositionHash> own;
  std::unordered_map<uint64_t, uint32_t> uses;

  uint32_t id(const float* p) {
    const detail::PositionKey k = key_of(p);
    if (reference) {
      if (auto it = reference->ids.find(k); it != reference->ids.end()) return it->second;
    }
    const uint32_t next = uint32_t((reference ? reference->ids.size() : 0) + own.size());
    return own.try_emplace(k, next).first->second;
  }
  void add(const HlodPayload& p, const LodLevel& range) {
    const float* pos = p.positions.data() + 3 * size_t(range.first_vertex);
    for (uint32_t i = 0; i + 2 < range.index_count; i += 3) {
      const uint32_t* f = &p.indices[range.first_index + i];
      const uint32_t a = id(pos + 3 * size_t(f[0])), b = id(pos + 3 * size_t(f[1])), c = id(pos + 3 * size_t(f[2]));
      ++uses[edge_key(a, b)];
      ++uses[edge_key(b, c)];
      ++uses[edge_key(c, a)];
    }
  }
};

}  // namespace

bool validate_hlod_cut(const HlodTree& tree, std::span<const int8_t> cut, std::string* message) {
  auto fail = [&](size_t i, const std::string& why) {
    if (message) *message = "node " + std::to_string(i) + ": " + why;
    return false;
  };
  if (cut.size() != tree.nodes.size())
    return fail(0, "cut has " + std::to_string(cut.size()) + " states for " + std::to_string(tree.nodes.size()) + " nodes");
  for (size_t i = 0; i < tree.nodes.size(); ++i) {
    const HlodNode& n = tree.nodes[i];
    const int8_t s = cut[i];
    const bool in_cut = n.parent < 0 || cut[size_t(n.parent)] == kHlodCutOpened;
    if (in_cut && s == kHlodCutOutside) return fail(i, "not in the cut, but its parent is opened");
    if (!in_cut && s != kHlodCutOutside) return fail(i, "in the cut, but its parent is not opened");
    if (s == kHlodCutOpened && n.leaf()) return fail(i, "a leaf cannot be opened");
    if (s >= 0 && s >= n.layer_count)
      return fail(i, "layer " + std::to_string(s) + " drawn, the node has " + std::to_string(n.layer_count));
    if (s < kHlodCutOutside) return fail(i, "state " + std::to_string(s) + " is not a layer, opened or outside");
  }
  return true;
}

HlodCutReference hlod_cut_reference(const HlodTree& tree, std::span<const HlodPayload* const> payloads) {
  assert(payloads.size() == tree.nodes.size());
  EdgeCount count;
  for (size_t i = 0; i < tree.nodes.size(); ++i) {
    const HlodPayload* p = payloads[i];
    if (!p) continue;
    if (tree.nodes[i].leaf() && !p->layers.empty()) count.add(*p, p->layers[0]);
    count.add(*p, p->boundary);
  }
  HlodCutReference ref;
  ref.ids = std::move(count.own);
  for (const auto& [edge, uses] : count.uses)
    if (uses == 1) ref.open_edges.insert(edge);
  return ref;
}

size_t count_cut_gaps(const HlodTree& tree, std::span<const HlodPayload* const> payloads, std::span<const int8_t> cut,
                      const HlodCutReference& reference) {
  assert(payloads.size() == tree.nodes.size() && cut.size() == tree.nodes.size());
  EdgeCount count;
  count.reference = &reference;
  for (size_t i = 0; i < tree.nodes.size(); ++i) {
    const HlodPayload* p = payloads[i];
    if (!p || cut[i] == kHlodCutOutside) continue;
    if (cut[i] == kHlodCutOpened) count.add(*p, p->boundary);
    else if (size_t(cut[i]) < p->layers.size()) count.add(*p, p->layers[size_t(cut[i])]);
  }
  size_t gaps = 0;
  for (const auto& [edge, uses] : count.uses)
    if (uses == 1 && !reference.open_edges.contains(edge)) ++gaps;
  return gaps;
}

}  // namespace lod
