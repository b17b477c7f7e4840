// Scene: the baked models and the placed objects a frame graph runs over.
#pragma once
#include <vector>

#include "jobs/scene_config.h"
#include "lodkit/types.hpp"
#include "runtime/lod_chain.h"
#include "runtime/model_table.h"
#include "runtime/object_set.h"

namespace lod {

struct Scene {
  std::vector<LodChain> chains;   // one per model, index = ModelConfig order
  ModelTable models;
  ObjectSet objects;
};

// One object of an [[instances]] block: where it stands, turned about y, scaled.
struct Placement {
  float position[3] = {0, 0, 0};
  float yaw = 0;
  float scale = 1;
};
// The block's objects in order (seeded random in its box, or a grid filling it). Deterministic.
std::vector<Placement> place_block(const InstanceConfig& inst);
Transform transform_of(const Placement& p);  // as transform_of(ObjectSet) gives it

// Places every [[instances]] block (seeded random in its box, or a grid filling it) and
// fills the world bounding spheres from each chain's level-0 sphere. Deterministic.
ObjectSet place_instances(const SceneConfig& config, const std::vector<LodChain>& chains);

// Builds models + objects from already baked chains (in config model order).
Scene make_scene(const SceneConfig& config, std::vector<LodChain> chains);

}  // namespace lod
