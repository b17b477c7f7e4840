// Back-to-front order of blended draws. Alpha BLEND runs are drawn after every opaque and
// masked run (view-dependent objects', HLOD nodes', proxies' and the terrain's included), with
// depth test on and depth writes off; over each other they composite correctly only farthest
// first, so each instance with blended runs gets its own draw, and each view-dependent object
// and each HLOD node draw (a layer or a boundary patch) with some its own turn, ordered by the
// view depth of its bounding sphere centre (a level's; a view-dependent object's: its model's
// level 0; an HLOD node's: its subtree's). Within one draw its blended runs keep material order
// (a run's own centre is not known without its vertices; intersecting or nested transparent
// surfaces of one object are not sorted per triangle). Pure CPU, so tests check the order
// without a GL context.
#pragma once
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "viewer/draw_list.h"
#include "viewer/hlod_draw_list.h"
#include "viewer/mesh_layout.h"

namespace lod::viewer {

inline constexpr uint32_t kNotViewDependent = UINT32_MAX;
inline constexpr uint32_t kNotHlod = UINT32_MAX;

// One instance of a batch, one view-dependent object or one HLOD node draw, drawn in the
// blended pass.
struct BlendDraw {
  uint32_t batch = 0;               // into DrawList::batches (instances)
  uint32_t instance = 0;            // into DrawList::instances (inside the batch's range)
  uint32_t vd = kNotViewDependent;  // else into DrawList::vd (batch and instance unused)
  uint32_t hlod = kNotHlod;         // else into HlodDrawList::draws (batch and instance unused)
  float depth = 0;  // distance along the view direction of its centre (larger = farther)
};

// The instances of the batches whose range `blends` (per MeshLayout::ranges, 1 = it has a
// blended run) and the view-dependent objects whose `vd_blends` entry is 1 (per DrawList::vd),
// farthest first under `view` (world -> eye); equal depths keep list order (instances first).
void order_blended_draws(const DrawList& list, const MeshLayout& layout, const std::vector<uint8_t>& blends,
                         const std::vector<uint8_t>& vd_blends, const glm::mat4& view,
                         std::vector<BlendDraw>& out);
// The same with the HLOD cut's draws whose `hlod_blends` entry is 1 (per HlodDrawList::draws)
// sorted in among them (equal depths: instances, view-dependent objects, then HLOD draws).
void order_blended_draws(const DrawList& list, const MeshLayout& layout, const std::vector<uint8_t>& blends,
                         const std::vector<uint8_t>& vd_blends, const HlodDrawList& hlod,
                         const std::vector<uint8_t>& hlod_blends, const glm::mat4& view, std::vector<BlendDraw>& out);

}  // namespace lod::viewer
