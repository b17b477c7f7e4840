// Materials through the levels. A material boundary is a seam: vertices where materials meet
// are split (one copy per material, same position), so the QEM simplifier moves them only
// along the boundary, both copies together, as it does uv seams; every collapse stays inside
// one material, and each level's triangle keeps
// its material (that of the input vertex its corners descend from). Each level's triangles
// are then grouped by material into LevelSubmesh runs. The aggressive simplifier (vertex
// clustering) runs on each material's triangles alone.
#pragma once
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "preprocess/mesh.h"
#include "preprocess/qem_simplifier.h"
#include "runtime/chain_material.h"
#include "runtime/lod_chain.h"

namespace lod {

// Material per triangle from mesh.submeshes (-1 where no submesh covers a triangle).
std::vector<int32_t> triangle_materials(const MeshView& mesh);

// Gives every vertex used by triangles of several materials one copy per further material
// (same position, normal and uv), so afterwards each vertex belongs to one material. Returns
// the number of copies made.
size_t split_vertices_by_material(MeshData& mesh);

// Material per vertex (-1 for vertices of the default material or unused ones), for a mesh
// whose vertices each belong to one material (after split_vertices_by_material).
std::vector<int32_t> vertex_materials(const MeshView& mesh);

// Number of distinct materials (-1 included) among the used vertices.
size_t distinct_materials(const std::vector<int32_t>& vertex_material);

// Reorders a level's triangles so each material's are contiguous (materials ascending, the
// default -1 first; each material's triangles in their previous order) and appends the runs
// for `level` to `out`. A triangle's material is that of the input vertex its first corner
// descends from: vertex_material[source[indices[3 t]]].
void group_by_material(std::vector<uint32_t>& indices, const std::vector<uint32_t>& source,
                       const std::vector<int32_t>& vertex_material, uint32_t level, std::vector<LevelSubmesh>& out);

// cluster_simplify_chain on each material's triangles alone, each to its share of every
// target; the parts are joined into one level each (source_vertex in input ids). Each cell
// grid is a material's own, so neighbouring materials may no longer meet exactly. Optional
// per-vertex attributes (attribute_count floats per input vertex) are averaged per cell into
// each level's `attributes`.
void cluster_simplify_per_material(ChainLevelOut* levels, const MeshData& mesh, const std::vector<int32_t>& vertex_material,
                                   const size_t* target_triangles, size_t level_count, const float* attributes = nullptr,
                                   size_t attribute_count = 0);

// The mesh's materials as the chain stores them (chain.materials, chain.texture_base = the
// source's folder, absolute) and the images they hold in themselves (chain.images, only those
// a kept material names, each slot naming its copy as "embedded:<k>"). What cannot be kept is
// said in `notes`: embedded images the import left out (not PNG/JPEG, too large), names or URIs
// too long or with control bytes, factors outside [0, 1] (clamped).
void add_chain_materials(const MeshData& mesh, const std::filesystem::path& source, LodChain& chain,
                         std::vector<std::string>& notes);

}  // namespace lod
