// Derived columns: world_sphere and control_of for each dirty object.
#include "runtime/derived_columns.h"

#include <cassert>

#include "runtime/object_controls.h"
#include "runtime/world_bounds.h"

namespace lod {

size_t refresh_derived_columns(ObjectStore& s, size_t begin, size_t end, const LevelCaps& caps,
                               std::span<const Sphere> model_spheres) {
  assert(end <= s.size());
  size_t refreshed = 0;
  for (size_t i = begin; i < end; ++i) {
    if (!s.dirty[i]) continue;
    const Transform& t = s.transform[i];
    assert(s.model[i] < model_spheres.size());
    const Sphere w = world_sphere(t, model_spheres[s.model[i]]);
    s.cx[i] = w.center[0], s.cy[i] = w.center[1], s.cz[i] = w.center[2], s.radius[i] = w.radius;
    const ObjectControl c = control_of(s.options[i], t.scale, s.model[i], caps);
    s.row[i] = c.row, s.min_level[i] = c.min_level, s.error_scale[i] = c.error_scale;
    s.inv_priority[i] = c.inv_priority, s.never_cull[i] = c.never_cull;
    s.dirty[i] = 0;
    ++refreshed;
  }
  return refreshed;
}

}  // namespace lod
