// Offsets of every chain level inside the viewer's single VBO/IBO pair.
#include "viewer/mesh_layout.h"

#include <algorithm>

namespace lod::viewer {

namespace {

// The level's material runs that lie inside it (the chain was validated; a run past the
// level's end is still dropped rather than drawn from another level's indices).
void add_runs(const LodChain& chain, uint32_t level, uint32_t first_material, LevelRange& r, MeshLayout& layout) {
  r.first_run = static_cast<uint32_t>(layout.runs.size());
  for (const LevelSubmesh& s : level_submeshes(chain, level)) {
    if (uint64_t(s.first_index) + s.index_count > r.index_count) continue;
    const bool known = s.material >= 0 && size_t(s.material) < chain.materials.size();
    layout.runs.push_back({r.first_index + s.first_index, s.index_count,
                           known ? int32_t(first_material + uint32_t(s.material)) : -1});
  }
  r.run_count = static_cast<uint32_t>(layout.runs.size()) - r.first_run;
}

}  // namespace

MeshLayout layout_meshes(std::span<const LodChain> chains) {
  MeshLayout layout;
  uint64_t vertex_base = 0;
  uint64_t index_base = 0;
  for (const LodChain& chain : chains) {
    layout.first_range.push_back(static_cast<uint32_t>(layout.ranges.size()));
    layout.level_count.push_back(static_cast<uint32_t>(chain.levels.size()));
    layout.morphable.push_back(can_morph_levels(chain) ? 1 : 0);
    layout.first_material.push_back(layout.material_count);
    for (uint32_t k = 0; k < chain.levels.size(); ++k) {
      const LodLevel& level = chain.levels[k];
      LevelRange r;
      r.first_index = static_cast<uint32_t>(index_base + level.first_index);
      r.index_count = level.index_count;
      r.base_vertex = static_cast<int32_t>(vertex_base + level.first_vertex);
      std::copy(level.bounds.center, level.bounds.center + 3, r.center);
      add_runs(chain, k, layout.material_count, r, layout);
      layout.ranges.push_back(r);
    }
    layout.material_count += static_cast<uint32_t>(chain.materials.size());
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

void pack_uvs(std::span<const LodChain> chains, std::vector<float>& uvs) {
  uvs.clear();
  for (const LodChain& chain : chains) {
    const size_t n = chain.positions.size() / 3;
    if (chain.uvs.size() == 2 * n) {
      uvs.insert(uvs.end(), chain.uvs.begin(), chain.uvs.end());
    } else {
      uvs.insert(uvs.end(), 2 * n, 0.f);
    }
  }
}

}  // namespace lod::viewer
