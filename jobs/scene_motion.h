// SceneMotion: a config's moving instances ([[instances]] motion = "wander" / "orbit") driven
// through the public Service API, as a simulator would: each frame, the new transforms of
// every moving object staged with one set_transforms call (the caller commits).
#pragma once
#include <cstdint>
#include <vector>

#include "jobs/scene_config.h"
#include "lodkit/service.hpp"
#include "runtime/object_set.h"

namespace lod {

class SceneMotion {
 public:
  // `handles[i]` is the handle of `objects` entry i (placed by place_instances from `config`).
  SceneMotion(const SceneConfig& config, const ObjectSet& objects, const std::vector<ObjectHandle>& handles);
  size_t moving() const { return handles_.size(); }
  // Stages every moving object's transform at time t (seconds); returns how many were accepted.
  size_t stage(Service& service, double t);

 private:
  struct Mover {
    MotionSpec motion;
    Transform start;
    float box_min[3], box_max[3];
    uint64_t seed;
  };
  std::vector<Mover> movers_;
  std::vector<ObjectHandle> handles_;
  std::vector<Transform> transforms_;  // reused every frame
};

}  // namespace lod
