// HlodTree: one model's hierarchical LOD (Zhou and Tian 3.1): an octree whose every node holds a few
// layers of its own geometry, finest first, and the boundary patch that joins its children.
//
// The tree (this struct) is small and always resident; the nodes' geometry (HlodPayload) is
// what streaming loads and evicts, one node at a time, from the offset each node records.
//
// Drawing a cut: every node of the cut is either *drawn* (one of its layers) or *opened*
// (replaced by its children). An opened node draws its boundary triangles, which join its
// children's geometry without a gap: boundary vertices are locked in every layer below the
// node that owns the patch, so any mix of child layers meets it exactly.
#pragma once
#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "runtime/chain_material.h"
#include "runtime/embedded_image.h"
#include "runtime/lod_chain.h"  // Sphere

namespace lod {

inline constexpr uint32_t kHlodMaxLayers = 3;   // Zhou and Tian: the geometry, then two coarser layers
inline constexpr uint32_t kHlodMaxDepth = 24;

struct HlodLayerInfo {
  uint32_t triangles = 0;
  uint32_t vertices = 0;
  // Measured object-space distance to the original surface (max, as LodLevel::error). Never
  // less than any child's error at its coarsest layer, so errors grow monotonically up the tree.
  float error = 0;
  // How far a vertex's uv slid from the original vertex it descends from, at most (texture
  // units, as the .lod's TEX0 errors); 0 without texture coordinates. A report, not monotonic.
  float uv_error = 0;
  // The same for TEXCOORD_1 (texture units) and COLOR_0 (distance in linear RGBA, as the .lod's
  // COL0 errors); 0 without them.
  float uv1_error = 0;
  float color_error = 0;
};

struct HlodNode {
  int32_t parent = -1;        // -1 at the root
  uint32_t first_child = 0;   // children are contiguous in breadth-first order
  uint8_t child_count = 0;    // 0 at a leaf
  uint8_t child_mask = 0;     // OctreeCode: bit i = octant i is non-empty (x + 2y + 4z)
  uint8_t depth = 0;          // 0 at the root
  uint8_t layer_count = 0;    // 1..kHlodMaxLayers
  bool leaf() const { return child_count == 0; }

  float box_center[3] = {0, 0, 0};   // the octree cell, object space
  float box_half = 0;                // half its edge (cells are cubes)
  Sphere bounds;                     // of everything the node or its subtree draws
  uint32_t boundary_triangles = 0;   // patch between the children (0 at a leaf)
  uint32_t boundary_vertices = 0;    // the patch's own vertices (originals, never moved)
  HlodLayerInfo layers[kHlodMaxLayers];

  // Where the node's payload is in its .hlod file, and its size in memory once loaded
  // (the stream budget counts resident_bytes).
  uint64_t payload_offset = 0;
  uint64_t payload_size = 0;
  uint64_t resident_bytes = 0;

  // Attributes (all nodes of a tree alike for uvs, uvs1 and colors): the payload has texture
  // coordinates (TEXCOORD_0), a second uv set (TEXCOORD_1), vertex colours (COLOR_0), and this
  // many material runs over its layers and patch (0 in a tree without materials).
  bool uvs = false;
  bool uvs1 = false;
  bool colors = false;
  uint32_t material_runs = 0;
};

// One node's geometry. Layers are back to back like a LodChain's levels; the boundary patch
// has vertices of its own (originals, never moved).
struct HlodPayload {
  std::vector<LodLevel> layers;          // ranges into the arrays below; level-local indices
  std::vector<float> positions;          // xyz per vertex, all layers then the boundary
  std::vector<float> normals;            // same count as positions
  std::vector<uint32_t> indices;         // all layers then the boundary
  LodLevel boundary;                     // the patch's range (error 0)
  std::vector<float> uvs;                // uv per vertex (TEXCOORD_0), or empty
  std::vector<float> uvs1;               // second uv per vertex (TEXCOORD_1), or empty
  std::vector<float> colors;             // linear RGBA per vertex (COLOR_0), or empty
  // Each range's triangles grouped by material (as a .lod level's): runs sorted by range, a
  // range's runs covering its indices in order; `level` is the layer index, or layers.size()
  // for the boundary; first_index is range-local. Empty in a tree without materials.
  std::vector<LevelSubmesh> runs;
};

// The runs of one range of `p` (a layer index, or p.layers.size() for the boundary).
inline std::span<const LevelSubmesh> hlod_range_runs(const HlodPayload& p, uint32_t range) {
  const auto lo = std::lower_bound(p.runs.begin(), p.runs.end(), range,
                                   [](const LevelSubmesh& s, uint32_t r) { return s.level < r; });
  auto hi = lo;
  while (hi != p.runs.end() && hi->level == range) ++hi;
  return {lo, hi};
}

struct HlodTree {
  std::string name;
  uint64_t source_hash = 0;
  uint32_t min_verts = 1000;             // the build's leaf size (Zhou and Tian, Table I)
  float box_center[3] = {0, 0, 0};       // the root cell
  float box_half = 0;
  uint64_t source_triangles = 0;         // of the original mesh
  // Materials (Zhou and Tian's header has them): run material ids are below material_count. `materials`
  // holds them (texture URIs relative to texture_base, the source's folder, as a .lod's) or is
  // empty where only the count travels (a subtree entry of the distributed bake).
  uint32_t material_count = 0;
  std::vector<ChainMaterial> materials;
  std::string texture_base;
  // The images the materials embed ("embedded:<k>" names images[k]), as LodChain::images; empty
  // with the materials in a subtree entry.
  std::vector<EmbeddedImage> images;
  bool uvs = false;                      // the payloads have texture coordinates
  bool uvs1 = false;                     // ... a second uv set
  bool colors = false;                   // ... vertex colours
  std::vector<HlodNode> nodes;           // breadth-first, nodes[0] is the root
};

}  // namespace lod
