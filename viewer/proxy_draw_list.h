// ProxyDrawList: the scene HLOD proxies a Frame draws (Frame::scene_proxies), as index ranges
// of the proxies' buffers. Pure CPU, so tests can count what would be submitted.
#pragma once
#include <cstdint>
#include <vector>

#include "runtime/frame.h"
#include "runtime/scene_hlod_tree.h"

namespace lod::viewer {

struct ProxyDraw {
  uint32_t node = 0;
  uint8_t depth = 0;  // colour-by-level colours a proxy by its octree depth
  uint32_t first_index = 0, index_count = 0, first_vertex = 0;
};

struct ProxyDrawList {
  std::vector<ProxyDraw> draws;
  uint64_t triangles = 0;  // equals Frame::scene_proxy_tris for a whole frame
  uint32_t rejected = 0;   // ids the tree does not have
};

void build_proxy_draw_list(const Frame& frame, const SceneHlodTree& tree, ProxyDrawList& out);

}  // namespace lod::viewer
