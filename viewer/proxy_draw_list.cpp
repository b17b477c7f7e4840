#include "viewer/proxy_draw_list.h"

namespace lod::viewer {

void build_proxy_draw_list(const Frame& frame, const SceneHlodTree& tree, ProxyDrawList& out) {
  out.draws.clear();
  out.triangles = 0;
  out.rejected = 0;
  for (uint32_t id : frame.scene_proxies) {
    if (id >= tree.nodes.size()) {
      ++out.rejected;
      continue;
    }
    const SceneHlodNode& n = tree.nodes[id];
    out.draws.push_back({id, n.depth, n.first_index, n.index_count, n.first_vertex});
    out.triangles += n.triangles();
  }
}

}  // namespace lod::viewer
