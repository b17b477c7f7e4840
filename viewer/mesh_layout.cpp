// Offsets of every chain level inside the viewer's single VBO/IBO pair.
#include "viewer/mesh_layout.h"

#include <algorithm>

namespace lod::viewer {

MeshLayout layout_meshes(std::span<const LodChain> chains) {
  MeshLayout layout;
  uint64_t vertex_base = 0;
  uint64_t index_base = 0;
  for (const LodChain& chain : chains) {
    layout.first_range.push_back(static_cast<uint32_t>(layout.ranges.size()));
    layout.level_count.push_back(static_cast<uint32_t>(chain.levels.size()));
    layout.morphable.push_back(can_morph_levels(chain) ? 1 : 0);
    for (const LodLevel& level : chain.levels) {
      LevelRange r;
      r.first_index = static_cast<uint32_t>(index_base + level.first_index);
      r.index_count = level.index_count;
      r.base_vertex = static_cast<int32_t>(vertex_base + level.first_vertex);
      layout.ranges.push_back(r);
    }
    vertex_base += chain.positions.size() / 3;
    index_base += chain.indices.size();
  }
  layout.vertex_count = vertex_base;
  layout.index_count = index_base;
  return layout;
}

void pack_vertices(std::span<const LodChain> chains, std::vector<float>& vertices, std::vector<uint32_t>& indices) {
  vertices.clear();
  indices.clear();
  for (const LodChain& chain : chains) {
    const size_t n = chain.positions.size() / 3;
    const bool has_normals = chain.normals.size() == chain.positions.size();
    for (size_t v = 0; v < n; ++v) {
      vertices.insert(vertices.end(), &chain.positions[3 * v], &chain.positions[3 * v] + 3);
      if (has_normals) {
        vertices.insert(vertices.end(), &chain.normals[3 * v], &chain.normals[3 * v] + 3);
      } else {
        vertices.insert(vertices.end(), {0.f, 0.f, 0.f});
      }
    }
    // Indices stay level-local: each draw adds its level's base vertex.
    indices.insert(indices.end(), chain.indices.begin(), chain.indices.end());
  }
}

}  // namespace lod::viewer
