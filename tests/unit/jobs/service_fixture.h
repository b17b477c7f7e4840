// A Service over the synthetic chains with no objects, for the dynamic-object tests: the
// camera at (0, 2, 60) looking down -z, objects placed near the origin.
#pragma once
#include <cstring>
#include <memory>

#include "jobs/service.h"
#include "unit/jobs/synthetic_scene.h"

namespace lod::test {

inline Transform placed(float x, float y, float z) {
  Transform t;
  t.position[0] = x, t.position[1] = y, t.position[2] = z;
  return t;
}

inline Camera camera_at(float x, float y, float z, float fx, float fy, float fz) {
  Camera c;
  c.eye[0] = x, c.eye[1] = y, c.eye[2] = z;
  c.forward[0] = fx, c.forward[1] = fy, c.forward[2] = fz;
  return c;
}

// Index of the entry of `h` in `f`, or -1.
inline int entry_of(const Frame& f, ObjectHandle h) {
  for (size_t k = 0; k < f.handles.size(); ++k)
    if (f.handles[k] == h) return static_cast<int>(k);
  return -1;
}

class DynamicService {
 public:
  explicit DynamicService(uint32_t threads = 2, uint64_t budget = UINT64_MAX, double rate_hz = 60) {
    Scene empty;
    empty.chains = synthetic_chains();
    empty.models = build_model_table(empty.chains);
    FrameGraphOptions o;
    o.threads = threads;
    o.grain = 64;
    o.selection.budget = budget;
    service_ = make_service(empty, o, rate_hz);
    service_->set_view(0, camera_at(0, 2, 60, 0, 0, -1));
  }
  Service& service() { return *service_; }

 private:
  std::unique_ptr<Service> service_;
};

}  // namespace lod::test
