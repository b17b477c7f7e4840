// HlodTree: one model's hierarchical LOD (R1 3.1): an octree whose every node holds a few
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
#include <cstdint>
#include <string>
#include <vector>

#include "runtime/lod_chain.h"  // Sphere

namespace lod {

inline constexpr uint32_t kHlodMaxLayers = 3;   // R1: the geometry, then two coarser layers
inline constexpr uint32_t kHlodMaxDepth = 24;

struct HlodLayerInfo {
  uint32_t triangles = 0;
  uint32_t vertices = 0;
  // Measured object-space distance to the original surface (max, as LodLevel::error). Never
  // less than any child's error at its coarsest layer, so errors grow monotonically up the tree.
  float error = 0;
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
};

// One node's geometry. Layers are back to back like a LodChain's levels; the boundary patch
// has vertices of its own (originals, never moved).
struct HlodPayload {
  std::vector<LodLevel> layers;          // ranges into the arrays below; level-local indices
  std::vector<float> positions;          // xyz per vertex, all layers then the boundary
  std::vector<float> normals;            // same count as positions
  std::vector<uint32_t> indices;         // all layers then the boundary
  LodLevel boundary;                     // the patch's range (error 0)
};

struct HlodTree {
  std::string name;
  uint64_t source_hash = 0;
  uint32_t min_verts = 1000;             // the build's leaf size (R1 Table I)
  float box_center[3] = {0, 0, 0};       // the root cell
  float box_half = 0;
  uint64_t source_triangles = 0;         // of the original mesh
  std::vector<HlodNode> nodes;           // breadth-first, nodes[0] is the root
};

}  // namespace lod
