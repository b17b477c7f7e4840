// Back-to-front order of blended draws. Alpha BLEND runs are drawn after every opaque and
// masked run (view-dependent objects' included), without depth writes; over each other they
// composite correctly only farthest first, so each instance with blended runs gets its own
// draw, and each view-dependent object with some its own turn, ordered by the view depth of
// its level's bounding sphere centre (a view-dependent object's: its model's level 0). Within
// one object its blended runs keep material order (a run's own centre is not known without its
// vertices; intersecting or nested transparent surfaces of one object are not sorted per
// triangle). Pure CPU, so tests check the order without a GL context.
#pragma once
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "viewer/draw_list.h"
#include "viewer/mesh_layout.h"

namespace lod::viewer {

inline constexpr uint32_t kNotViewDependent = UINT32_MAX;

// One instance of a batch, or one view-dependent object, drawn in the blended pass.
struct BlendDraw {
  uint32_t batch = 0;               // into DrawList::batches (instances)
  uint32_t instance = 0;            // into DrawList::instances (inside the batch's range)
  uint32_t vd = kNotViewDependent;  // else into DrawList::vd (batch and instance unused)
  float depth = 0;  // distance along the view direction of its level's centre (larger = farther)
};

// The instances of the batches whose range `blends` (per MeshLayout::ranges, 1 = it has a
// blended run) and the view-dependent objects whose `vd_blends` entry is 1 (per DrawList::vd),
// farthest first under `view` (world -> eye); equal depths keep list order (instances first).
void order_blended_draws(const DrawList& list, const MeshLayout& layout, const std::vector<uint8_t>& blends,
                         const std::vector<uint8_t>& vd_blends, const glm::mat4& view,
                         std::vector<BlendDraw>& out);

}  // namespace lod::viewer
