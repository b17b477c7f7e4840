// Column resizing for the object structs of arrays.
#include "runtime/object_set.h"

#include <cmath>

namespace lod {

void ObjectSet::resize(size_t n) {
  model.resize(n, 0);
  x.resize(n, 0.f);
  y.resize(n, 0.f);
  z.resize(n, 0.f);
  scale.resize(n, 1.f);
  yaw.resize(n, 0.f);
  cx.resize(n, 0.f);
  cy.resize(n, 0.f);
  cz.resize(n, 0.f);
  radius.resize(n, 0.f);
}

void ObjectState::resize(size_t n) {
  visible.resize(n, 0);
  distance.resize(n, 0.f);
  area.resize(n, 0.f);
  weight.resize(n, 0.f);
  level.resize(n, 0);
  prev_level.resize(n, 0);
  was_visible.resize(n, 0);
}

Transform transform_of(const ObjectSet& objects, size_t i) {
  Transform t;
  t.position[0] = objects.x[i];
  t.position[1] = objects.y[i];
  t.position[2] = objects.z[i];
  t.rotation[1] = std::sin(0.5f * objects.yaw[i]);
  t.rotation[3] = std::cos(0.5f * objects.yaw[i]);
  t.scale = objects.scale[i];
  return t;
}

}  // namespace lod
