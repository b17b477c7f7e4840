// MorphStreams: the second vertex stream of blended draws. For a (model, finer level, coarser
// level) pair, each vertex of the finer level gets the position, normal and uv of its morph
// target in the coarser level (targets composed through the levels in between). Made on first use
// and kept: most level changes are one level, so few pairs are ever made. Pure CPU; the
// renderer uploads what grew (MorphBuffers).
#pragma once
#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include "runtime/lod_chain.h"

namespace lod::viewer {

class MorphStreams {
 public:
  // Keeps a view of `chains`: they must outlive this.
  explicit MorphStreams(std::span<const LodChain> chains = {}) : chains_(chains) {}

  // First vertex of the pair's stream in vertices(), composing it on first use; -1 when the
  // model cannot blend (no morph targets) or the pair is not finer < coarser.
  int64_t offset_of(uint32_t model, uint32_t fine, uint32_t coarse);

  // Position, normal and uv (kFloatsPerVertex) per vertex, all streams made so far, back to back;
  // zero normals or uvs where the chain has none.
  static constexpr size_t kFloatsPerVertex = 8;
  const std::vector<float>& vertices() const { return vertices_; }
  size_t stream_count() const { return offsets_.size(); }

 private:
  std::span<const LodChain> chains_;
  std::unordered_map<uint64_t, uint32_t> offsets_;  // (model, fine, coarse) -> first vertex
  std::vector<float> vertices_;
  std::vector<uint32_t> targets_;  // scratch
};

}  // namespace lod::viewer
