// HlodDrawList: one published Frame's HLOD cut (Frame::hlod_drawn, hlod_opened) turned into
// draws: one per drawn node layer and one per opened node's boundary patch, each with its
// model's transform and the node's octree depth (the colour of the colour-by-level mode).
// Pure CPU, so tests can count what would be submitted without a GL context.
#pragma once
#include <cstdint>
#include <vector>

#include "jobs/hlod_models.h"
#include "runtime/frame.h"
#include "viewer/draw_list.h"

namespace lod::viewer {

// Which of a node's ranges a draw uses.
inline constexpr uint8_t kHlodBoundary = 0xff;

struct HlodDraw {
  uint32_t model = 0;   // HlodModels index
  uint32_t node = 0;    // HlodTree::nodes index
  uint8_t layer = 0;    // 0 = finest, kHlodBoundary = the node's boundary patch
  uint8_t depth = 0;    // the node's octree depth
  uint32_t triangles = 0;
  float center[3] = {0, 0, 0};  // the node's bounding sphere centre, object space (blend order)
  InstanceData transform;  // the model's, morph = 1
};

struct HlodDrawList {
  std::vector<HlodDraw> draws;  // drawn layers in frame order, then the opened nodes' patches
  uint64_t triangles = 0;       // sum over draws: equals Frame::hlod_tris for a whole frame
  // Entries naming a model, node or layer the trees do not have (a frame from other models).
  uint32_t rejected = 0;
};

// Rebuilds `out` from `frame` against `models` (reusing its capacity). Opened nodes without a
// boundary patch draw nothing.
void build_hlod_draw_list(const Frame& frame, const HlodModels& models, HlodDrawList& out);

}  // namespace lod::viewer
