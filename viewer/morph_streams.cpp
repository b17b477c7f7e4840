// Composed morph-target streams, made once per (model, finer, coarser) pair.
#include "viewer/morph_streams.h"

namespace lod::viewer {

int64_t MorphStreams::offset_of(uint32_t model, uint32_t fine, uint32_t coarse) {
  if (model >= chains_.size() || fine >= coarse) return -1;
  const LodChain& chain = chains_[model];
  if (coarse >= drawn_levels(chain) || !can_morph_levels(chain)) return -1;  // none into the culled level
  const uint64_t key = uint64_t(model) << 16 | uint64_t(fine) << 8 | coarse;  // levels < kMaxLevels
  if (auto it = offsets_.find(key); it != offsets_.end()) return it->second;
  const LodLevel& f = chain.levels[fine];
  const LodLevel& c = chain.levels[coarse];
  targets_.resize(f.vertex_count);
  compose_morph_targets(targets_, chain, fine, coarse);
  const uint32_t first = uint32_t(vertices_.size() / kFloatsPerVertex);
  const bool has_normals = chain.normals.size() == chain.positions.size();
  const bool has_uvs = 2 * chain.positions.size() == 3 * chain.uvs.size();
  vertices_.reserve(vertices_.size() + kFloatsPerVertex * size_t(f.vertex_count));
  for (uint32_t t : targets_) {
    const size_t at = 3 * (size_t(c.first_vertex) + t);
    vertices_.insert(vertices_.end(), &chain.positions[at], &chain.positions[at] + 3);
    if (has_normals) {
      vertices_.insert(vertices_.end(), &chain.normals[at], &chain.normals[at] + 3);
    } else {
      vertices_.insert(vertices_.end(), {0.f, 0.f, 0.f});
    }
    // The uv blends with the position, so the texture stays on the surface while it moves.
    const size_t uv = 2 * (size_t(c.first_vertex) + t);
    if (has_uvs) {
      vertices_.insert(vertices_.end(), &chain.uvs[uv], &chain.uvs[uv] + 2);
    } else {
      vertices_.insert(vertices_.end(), {0.f, 0.f});
    }
  }
  offsets_.emplace(key, first);
  return first;
}

}  // namespace lod::viewer
