// DrawList: one published Frame turned into GPU work: instances grouped by (model, drawn level,
// target level), so the renderer issues exactly one instanced draw per group. An object blending
// between two levels (Frame::from_levels) is drawn at the finer one with its vertices pulled
// towards their morph targets in the coarser one by a per-instance weight. Pure CPU, so tests
// can count what would be submitted without a GL context.
#pragma once
#include <cstdint>
#include <vector>

#include "runtime/frame.h"
#include "viewer/mesh_layout.h"

namespace lod::viewer {

// Per-instance vertex attributes (divisor 1). Layout shared with instance_renderer's shader.
// The transform is the frame's own (lod::Transform): world = position + scale * rotate(q, p).
struct InstanceData {
  float position_scale[4];  // world position of the model origin, uniform scale
  float rotation[4];        // quaternion x y z w exactly as the frame gives it (the shader normalises)
  float morph = 1;          // geomorph factor towards the selected level (1 = settled)
  // Position = mix(own, morph target in the batch's target level, weight): 0 draws the batch's
  // level as it is, 1 puts every vertex on the target level's surface.
  float weight = 0;
};
static_assert(sizeof(InstanceData) == 40, "instance attributes are tightly packed");

// The instance attributes of one frame transform (finite, scale > 0, non-zero quaternion), or
// false for a transform no renderer can draw.
bool instance_of(const Transform& t, float morph, float weight, InstanceData* out);

// How an object with level `to`, morphing from `from` with factor `morph`, is drawn: the finer
// level, blended towards the coarser by `weight` (morph when coarsening, 1 - morph when refining).
struct MorphDraw {
  uint32_t level = 0;   // drawn (the finer of from, to)
  uint32_t target = 0;  // the coarser; == level when nothing blends
  float weight = 0;
};
inline MorphDraw morph_draw(uint32_t from, uint32_t to, float morph) {
  if (from == to || !(morph < 1)) return {to, to, 0.f};
  if (from < to) return {from, to, morph};
  return {to, from, 1.f - morph};
}

struct DrawBatch {
  uint32_t range = 0;           // index into MeshLayout::ranges
  uint32_t model = 0;
  uint32_t level = 0;           // chain level index drawn (0 = full detail)
  uint32_t target_level = 0;    // level the vertices blend towards; == level when none blends
  uint32_t first_instance = 0;  // into DrawList::instances
  uint32_t instance_count = 0;
};

// One view-dependent object's active mesh (Frame::vd_objects): drawn from the frame's own
// vd_positions / vd_indices with the object's transform, never at its discrete level.
// A material run of a vd object (Frame::vd_runs), its material scene-wide (MeshLayout).
struct VdRunDraw {
  uint32_t first_index = 0;  // into Frame::vd_indices
  uint32_t index_count = 0;
  int32_t material = -1;     // scene-wide material index, -1 = the default surface
};

struct VdDraw {
  uint32_t object = 0;        // Frame::objects value
  uint32_t entry = 0;         // its frame entry (transform, model)
  uint32_t first_vertex = 0;  // into Frame::vd_positions, in vertices
  uint32_t vertex_count = 0;
  uint32_t first_index = 0;   // into Frame::vd_indices; local to this object's vertices
  uint32_t index_count = 0;
  InstanceData transform;     // the same per-object transform the instances use, morph = 1
  uint32_t first_run = 0;     // into DrawList::vd_runs; 0 runs: drawn as one surface
  uint32_t run_count = 0;
  float center[3] = {0, 0, 0};  // model space: its model's level 0 centre, which blended draws sort by
};

struct DrawList {
  std::vector<DrawBatch> batches;         // non-empty groups, in (model, level, target level) order
  std::vector<InstanceData> instances;    // grouped by batch
  uint64_t triangles = 0;                 // sum of index_count / 3 * instance_count (instanced only)
  uint64_t indices = 0;                   // indices submitted (instanced only)
  uint32_t morphing = 0;                  // instances blending two levels
  uint64_t morph_triangles = 0;           // what drawing their finer level adds (vs their frame level)
  // Frame entries not drawn: past the shortest per-entry column (a torn frame), an unknown
  // model or level, a transform that is not finite; vd meshes out of range (drawn at their level).
  uint32_t rejected = 0;
  std::vector<VdDraw> vd;                 // view-dependent objects, in frame order
  std::vector<VdRunDraw> vd_runs;         // their material runs (objects whose runs check out)
  uint64_t vd_triangles = 0;              // sum of vd index_count / 3
  uint64_t vd_level_triangles = 0;        // what Frame::tris_selected counts for those objects (their level)
  std::vector<uint32_t> per_batch_slot;   // scratch: instances per (model, level, target) (counting sort)
  std::vector<uint32_t> first_key;        // scratch: per model, its first key (level_count^2 each)
  std::vector<uint8_t> is_vd;             // scratch: per frame entry, drawn from its active mesh
};

// Rebuilds `out` from `frame` alone (reusing its capacity): entry i is model frame.models[i]
// at frame.transforms[i], drawn at its level (blending from frame.from_levels[i]). Entries are
// refused one by one and counted in `rejected`: those past the shortest of models, transforms,
// levels and morph (a torn frame draws the common prefix), with a model or level the layout
// does not have, or with a transform that is not drawable. A well-formed frame has none. A
// frame without from_levels (hand-built) is settled; models without morph targets never blend.
// Entries listed in frame.vd_objects (by VdObjectFrame::entry) are drawn from their active mesh
// (out.vd) instead of an instance; a vd entry whose entry, ranges or indices fall outside the
// frame's arrays is rejected and its object drawn at its level.
void build_draw_list(const Frame& frame, const MeshLayout& layout, DrawList& out);

// The frame's selected triangles as a renderer draws them: Frame::tris_selected counts a
// view-dependent object at its discrete level, but what is drawn is its active mesh.
inline uint64_t selected_as_drawn(const Frame& frame, const DrawList& list) {
  return frame.tris_selected - list.vd_level_triangles + frame.vd_active_tris;
}

}  // namespace lod::viewer
