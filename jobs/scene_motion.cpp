// SceneMotion: closed-form motion paths staged through Service::set_transforms.
#include "jobs/scene_motion.h"

#include "jobs/scene.h"
#include "runtime/motion_path.h"

namespace lod {

SceneMotion::SceneMotion(const SceneConfig& config, const ObjectSet& objects,
                         const std::vector<ObjectHandle>& handles) {
  size_t o = 0;
  for (const InstanceConfig& inst : config.instances) {
    for (uint32_t i = 0; i < inst.count && o < objects.size() && o < handles.size(); ++i, ++o) {
      if (inst.motion.kind == MotionKind::none) continue;
      Mover m;
      m.motion = inst.motion;
      m.start = transform_of(objects, o);
      for (int a = 0; a < 3; ++a) m.box_min[a] = inst.box_min[a], m.box_max[a] = inst.box_max[a];
      m.seed = inst.seed * 0x100000001b3ull + i;
      movers_.push_back(m);
      handles_.push_back(handles[o]);
    }
  }
  transforms_.resize(movers_.size());
}

size_t SceneMotion::stage(Service& service, double t) {
  for (size_t k = 0; k < movers_.size(); ++k) {
    const Mover& m = movers_[k];
    transforms_[k] = motion_at(m.motion, m.start, m.box_min, m.box_max, m.seed, t);
  }
  return service.set_transforms(handles_, transforms_);
}

}  // namespace lod
