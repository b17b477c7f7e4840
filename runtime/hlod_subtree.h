// HlodSubtree: one baked subtree of a model HLOD, the unit a build is split into.
//
// A build is (a) the top of the octree down to a frontier, (b) one independent bake per
// frontier node (this struct), (c) the levels above, built from each subtree's root: its
// coarsest layer (with the original vertex each of its vertices descends from), the original
// vertices sampling its region and its bounds. A local build and a distributed one splice the
// same subtrees into the same breadth-first tree, so their files are the same bytes.
#pragma once
#include <cstdint>
#include <vector>

#include "runtime/hlod_tree.h"

namespace lod {

struct HlodSubtree {
  // Breadth-first from the subtree's root (nodes[0]); parent and first_child index this list
  // (-1 at its root); depth and cells are the whole tree's. Payload offsets are 0.
  std::vector<HlodNode> nodes;
  std::vector<HlodPayload> payloads;  // by node
  // What the levels above need of the root besides its payload:
  std::vector<uint32_t> root_source;     // per vertex of the root's coarsest layer: the original vertex
  std::vector<uint32_t> root_reference;  // original vertices sampling the root's region
  uint32_t material_count = 0;           // the bound its runs' material ids are checked against
  // The build's report, counted inside this subtree.
  uint64_t short_layers = 0;
  uint64_t oversized_leaves = 0;
};

}  // namespace lod
