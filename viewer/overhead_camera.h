// Overhead (bird's-eye) camera: straight down onto the whole scene, so the LOD camera's
// frustum, the culled objects and the levels it chose can be seen from outside, as in the
// references' bird's-eye figures.
#pragma once
#include "runtime/object_set.h"
#include "runtime/view.h"

namespace lod::viewer {

// Frames every object's bounding sphere; `lens` gives fov and picture size. North (-z) is up.
View overhead_view(const ObjectSet& objects, const View& lens);

}  // namespace lod::viewer
