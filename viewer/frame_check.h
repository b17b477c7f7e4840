// Whole-frame check: the invariants a published Frame holds when the consumer sees all of
// one frame and nothing of another (what a torn read would break).
#pragma once
#include <string>

#include "jobs/scene.h"
#include "runtime/frame.h"

namespace lod::viewer {

// True when the per-object arrays all have `visible` entries, ids are increasing and in
// range, levels exist, the histogram counts `visible` objects, and the selected levels' triangles
// add up to `tris_selected`, the levels objects morph from exist and their finer levels add
// `tris_morph_extra` over `morphing` objects, and the view-dependent meshes are visible objects in order, packed
// back to back over vd_positions / vd_indices, adding up to `vd_active_tris`. Otherwise false
// with the first broken invariant in `why`.
bool frame_is_whole(const Frame& frame, const Scene& scene, std::string* why);

}  // namespace lod::viewer
