// Overhead (bird's-eye) camera: straight down onto the whole scene, so the LOD camera's
// frustum, the culled objects and the levels it chose can be seen from outside, as in the
// references' bird's-eye figures.
#pragma once
#include <glm/glm.hpp>
#include <span>
#include <vector>

#include "runtime/frame.h"
#include "runtime/lod_chain.h"
#include "runtime/object_set.h"
#include "runtime/view.h"

namespace lod::viewer {

// A model's object-space bounding sphere, holding every level of its chain.
struct ModelSphere {
  glm::vec3 center{0};
  float radius = 0;
};
std::vector<ModelSphere> model_spheres(std::span<const LodChain> chains);

// Frames every object's bounding sphere; `lens` gives fov and picture size. North (-z) is up.
View overhead_view(const ObjectSet& objects, const View& lens);

// The same over `placed` (the scene's start placements: objects the frame culled have no entry)
// and every entry of `frame` where the frame puts it (frame.models, frame.transforms, spheres
// from `models`), so objects that moved away from their start stay in the picture.
View overhead_view(const ObjectSet& placed, const Frame& frame, std::span<const ModelSphere> models,
                   const View& lens);

}  // namespace lod::viewer
