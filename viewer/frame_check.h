// Whole-frame check: the invariants a published Frame holds when the consumer sees all of
// one frame and nothing of another (what a torn read would break).
#pragma once
#include <string>

#include "jobs/scene.h"
#include "runtime/frame.h"

namespace lod::viewer {

// True when every per-entry column (handles, models, transforms, view_masks, objects, levels,
// morph, from_levels) has `visible` entries, object ids are increasing and below object_count,
// each entry's model (frame.models, not a scene's placement) is one of `scene`'s and its levels
// exist, the histogram counts `visible` objects, the selected levels' triangles plus
// `hlod_tris` add up to `tris_selected`, the finer levels of morphing entries add `tris_morph_extra` over `morphing`
// of them, and the view-dependent meshes name their own entries in order, packed back to back
// over vd_positions / vd_indices, adding up to `vd_active_tris`. Otherwise false with the first
// broken invariant in `why`.
bool frame_is_whole(const Frame& frame, const Scene& scene, std::string* why);

}  // namespace lod::viewer
