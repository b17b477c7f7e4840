#include "viewer/frame_check.h"

#include <algorithm>
#include <cstdio>

namespace lod::viewer {

bool frame_is_whole(const Frame& f, const Scene& scene, std::string* why) {
  char buf[256];
  auto fail = [&](const char* text) {
    *why = text;
    return false;
  };
  if (f.objects.size() != f.visible || f.levels.size() != f.visible || f.morph.size() != f.visible ||
      f.from_levels.size() != f.visible)
    return fail("per-object arrays do not match the visible count");
  uint64_t histogram = 0;
  for (uint32_t n : f.level_histogram) histogram += n;
  if (histogram != f.visible) return fail("level histogram does not count the visible objects");
  uint64_t tris = 0, extra = 0;
  uint32_t morphing = 0;
  for (size_t i = 0; i < f.objects.size(); ++i) {
    const uint32_t id = f.objects[i];
    if (id >= scene.objects.size() || (i > 0 && f.objects[i - 1] >= id)) {
      std::snprintf(buf, sizeof buf, "entry %zu: object id %u out of order or range", i, id);
      return fail(buf);
    }
    const uint32_t m = scene.objects.model[id];
    if (f.levels[i] >= scene.models.level_count[m]) {
      std::snprintf(buf, sizeof buf, "object %u: level %u of %u", id, unsigned(f.levels[i]),
                    unsigned(scene.models.level_count[m]));
      return fail(buf);
    }
    if (f.from_levels[i] >= scene.models.level_count[m]) {
      std::snprintf(buf, sizeof buf, "object %u: morphs from level %u of %u", id, unsigned(f.from_levels[i]),
                    unsigned(scene.models.level_count[m]));
      return fail(buf);
    }
    const uint32_t first = scene.models.first_level[m];
    tris += scene.models.triangles[first + f.levels[i]];
    if (f.from_levels[i] != f.levels[i]) {
      ++morphing;
      extra += scene.models.triangles[first + std::min(f.from_levels[i], f.levels[i])] -
               scene.models.triangles[first + f.levels[i]];
    }
  }
  if (morphing != f.morphing || extra != f.tris_morph_extra) {
    std::snprintf(buf, sizeof buf, "%u objects morph adding %llu triangles but the frame says %u adding %llu",
                  morphing, (unsigned long long)extra, f.morphing, (unsigned long long)f.tris_morph_extra);
    return fail(buf);
  }
  if (tris != f.tris_selected) {
    std::snprintf(buf, sizeof buf, "tris_selected %llu but the levels add up to %llu",
                  (unsigned long long)f.tris_selected, (unsigned long long)tris);
    return fail(buf);
  }
  // View-dependent meshes: in object order, each a visible object, packed back to back.
  uint64_t vertices = 0, indices = 0, vd_tris = 0;
  size_t k = 0;
  for (size_t j = 0; j < f.vd_objects.size(); ++j) {
    const VdObjectFrame& v = f.vd_objects[j];
    while (k < f.objects.size() && f.objects[k] < v.object) ++k;
    if (k == f.objects.size() || f.objects[k] != v.object) {
      std::snprintf(buf, sizeof buf, "vd entry %zu: object %u is not a visible object (or out of order)", j,
                    v.object);
      return fail(buf);
    }
    if (v.first_vertex != vertices || v.first_index != indices || v.index_count % 3 != 0) {
      std::snprintf(buf, sizeof buf, "vd entry %zu (object %u): ranges not packed back to back", j, v.object);
      return fail(buf);
    }
    vertices += v.vertex_count;
    indices += v.index_count;
    vd_tris += v.index_count / 3;
  }
  if (3 * vertices != f.vd_positions.size() || indices != f.vd_indices.size())
    return fail("vd positions / indices do not match the vd entries");
  if (vd_tris != f.vd_active_tris) {
    std::snprintf(buf, sizeof buf, "vd_active_tris %llu but the vd meshes add up to %llu",
                  (unsigned long long)f.vd_active_tris, (unsigned long long)vd_tris);
    return fail(buf);
  }
  return true;
}

}  // namespace lod::viewer
