// DrawList: one published Frame turned into GPU work: instances grouped by (model, level), so
// the renderer issues exactly one instanced draw per group. Pure CPU, so tests can count what
// would be submitted without a GL context.
#pragma once
#include <cstdint>
#include <vector>

#include "runtime/frame.h"
#include "runtime/object_set.h"
#include "viewer/mesh_layout.h"

namespace lod::viewer {

// Per-instance vertex attributes (divisor 1). Layout shared with instance_renderer's shader.
struct InstanceData {
  float position_scale[4];  // world position of the model origin, uniform scale
  float yaw = 0;            // radians about +y
  float morph = 1;          // geomorph factor towards the selected level (1 = settled)
};
static_assert(sizeof(InstanceData) == 24, "instance attributes are tightly packed");

struct DrawBatch {
  uint32_t range = 0;           // index into MeshLayout::ranges
  uint32_t model = 0;
  uint32_t level = 0;           // chain level index (0 = full detail)
  uint32_t first_instance = 0;  // into DrawList::instances
  uint32_t instance_count = 0;
};

struct DrawList {
  std::vector<DrawBatch> batches;         // non-empty groups, in (model, level) order
  std::vector<InstanceData> instances;    // grouped by batch
  uint64_t triangles = 0;                 // sum of index_count / 3 * instance_count
  uint64_t indices = 0;                   // indices submitted
  uint32_t rejected = 0;                  // frame entries naming an unknown object or level
  std::vector<uint32_t> per_batch_slot;   // scratch: instances per range (counting sort)
};

// Rebuilds `out` from `frame` (reusing its capacity). Entries whose object id or level is out
// of range are not drawn and are counted in `rejected`: a well-formed frame has none.
void build_draw_list(const Frame& frame, const ObjectSet& objects, const MeshLayout& layout, DrawList& out);

}  // namespace lod::viewer
