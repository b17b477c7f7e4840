// LodChain: one model's discrete levels, baked once and shared by every instance.
// Levels live in one contiguous buffer as offsets + counts (as a GPU would draw them),
// with an object-space error each, so per-frame selection is one comparison per level.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "runtime/vertex_tree.h"

namespace lod {

struct Sphere {
  float center[3] = {0, 0, 0};
  float radius = 0;
};

struct LodLevel {
  uint32_t first_index = 0;   // into LodChain::indices
  uint32_t index_count = 0;   // 3 per triangle
  uint32_t first_vertex = 0;  // into LodChain::positions (in vertices); indices are level-local
  uint32_t vertex_count = 0;
  int32_t level = 0;          // l = round(log2(triangles)), R0's level
  float error = 0;            // measured object-space geometric error vs level 0 (max distance)
  float error_rms = 0;        // measured object-space RMS distance vs level 0
  Sphere bounds;              // object space

  uint32_t triangles() const { return index_count / 3; }
};

struct LodChain {
  std::string name;
  uint64_t source_hash = 0;        // content hash of the mesh bytes and bake settings
  std::vector<LodLevel> levels;    // 0 = full detail, then coarser
  std::vector<float> positions;    // xyz per vertex, all levels back to back
  std::vector<float> normals;      // xyz per vertex, same count as positions
  std::vector<uint32_t> indices;   // level-local vertex indices, all levels back to back
  // Optional vertex hierarchy of level 0 for view-dependent LOD (empty = none); its leaves are
  // level 0's vertices. Stored in the asset's optional VHIE section.
  VertexTree hierarchy;
};

// R0: l = log2(M) rounded to the nearest integer (5,000 triangles -> 12, 2,000 -> 11).
// Zero triangles gives level 0.
int32_t level_of_triangles(uint64_t triangles);

// Checks ranges, index bounds (indices < the level's vertex_count), triangle counts
// non-increasing, errors non-decreasing, l = level_of_triangles, finite values, at most
// kMaxLevels levels. On failure `message` names the element ("level 3 index 812 references
// vertex 90211 of 35947"); callers prefix the file.
bool validate_chain(const LodChain& chain, std::string* message);

}  // namespace lod
