// The Embree-traced coarse depth buffer (runtime/occlusion.h, OcclusionTracer): each occluder
// mesh is built into its own BVH once (cached by content) and placed per frame as an instance;
// then one ray per buffer sample, from the eye through the sample's centre, stores the view
// depth of the first hit (+infinity on a miss). Exact at the sample centres (the rasteriser
// stores each triangle's farthest depth instead), so it culls at least as much where both see
// the same occluders, and never what a primary ray through a sample centre sees first.
#pragma once
#include <memory>

#include "runtime/occlusion.h"

namespace lod {

std::unique_ptr<OcclusionTracer> make_embree_occlusion_tracer();

}  // namespace lod
