// MeshLayout: where every (model, level) of the scene's chains sits once all of them are
// uploaded back to back into one vertex buffer and one index buffer, as offsets + counts
// (zeux/niagara style), so a draw is one range and a base vertex.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "runtime/lod_chain.h"

namespace lod::viewer {

struct LevelRange {
  uint32_t first_index = 0;  // into the shared index buffer, in indices
  uint32_t index_count = 0;
  int32_t base_vertex = 0;   // added to the level-local indices
  uint32_t first_run = 0;    // into MeshLayout::runs: the level's material runs
  uint32_t run_count = 0;    // 0 for a chain without materials
  float center[3] = {0, 0, 0};  // the level's bounding sphere centre (model space): blended draws sort by it
};

// Part of a level drawn with one material: indices into the shared index buffer, and the
// material as a scene-wide index (MeshLayout::first_material of the model + the chain's own
// material index), -1 for the default surface.
struct MaterialRun {
  uint32_t first_index = 0;
  uint32_t index_count = 0;
  int32_t material = -1;
};

struct MeshLayout {
  std::vector<uint32_t> first_range;  // per model: offset into `ranges`
  std::vector<uint32_t> level_count;  // per model
  std::vector<uint8_t> morphable;     // per model: level changes blend (can_morph_levels)
  std::vector<LevelRange> ranges;     // per (model, level), models back to back
  std::vector<uint32_t> first_material;  // per model: its materials' first scene-wide index
  std::vector<MaterialRun> runs;      // per range, back to back
  uint32_t material_count = 0;        // scene-wide
  uint64_t vertex_count = 0;
  uint64_t index_count = 0;

  uint32_t range_of(uint32_t model, uint32_t level) const { return first_range[model] + level; }
};

MeshLayout layout_meshes(std::span<const LodChain> chains);

// Interleaved position + normal (6 floats per vertex) and the shared index buffer, in the
// layout's order. Chains without normals get zeros (the shader falls back to face normals).
void pack_vertices(std::span<const LodChain> chains, std::vector<float>& vertices, std::vector<uint32_t>& indices);

// Texture coordinates, 2 floats per vertex in the same order; chains without uvs get zeros.
void pack_uvs(std::span<const LodChain> chains, std::vector<float>& uvs);

}  // namespace lod::viewer
