// Back-to-front order of blended draws. Alpha BLEND runs are drawn after every opaque and
// masked run, without depth writes; over each other they composite correctly only farthest
// first, so each instance with blended runs gets its own draw, ordered by the view depth of its
// level's bounding sphere centre. Within one object its blended runs keep material order (a
// run's own centre is not known without its vertices; intersecting or nested transparent
// surfaces of one object are not sorted per triangle). Pure CPU, so tests check the order
// without a GL context.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "viewer/draw_list.h"
#include "viewer/mesh_layout.h"

namespace lod::viewer {

// One instance of a batch drawn in the blended pass.
struct BlendDraw {
  uint32_t batch = 0;     // into DrawList::batches
  uint32_t instance = 0;  // into DrawList::instances (inside the batch's range)
  float depth = 0;        // distance along the view direction of its level's centre (larger = farther)
};

// The instances of the batches whose range `blends` (per MeshLayout::ranges, 1 = it has a
// blended run), farthest first under `view` (world -> eye); equal depths keep list order.
void order_blended_draws(const DrawList& list, const MeshLayout& layout, const std::vector<uint8_t>& blends,
                         const glm::mat4& view, std::vector<BlendDraw>& out);

}  // namespace lod::viewer
