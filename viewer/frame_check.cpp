#include "viewer/frame_check.h"

#include <cstdio>

namespace lod::viewer {

bool frame_is_whole(const Frame& f, const Scene& scene, std::string* why) {
  char buf[256];
  auto fail = [&](const char* text) {
    *why = text;
    return false;
  };
  if (f.objects.size() != f.visible || f.levels.size() != f.visible || f.morph.size() != f.visible)
    return fail("per-object arrays do not match the visible count");
  uint64_t histogram = 0;
  for (uint32_t n : f.level_histogram) histogram += n;
  if (histogram != f.visible) return fail("level histogram does not count the visible objects");
  uint64_t tris = 0;
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
    tris += scene.models.triangles[scene.models.first_level[m] + f.levels[i]];
  }
  if (tris != f.tris_selected) {
    std::snprintf(buf, sizeof buf, "tris_selected %llu but the levels add up to %llu",
                  (unsigned long long)f.tris_selected, (unsigned long long)tris);
    return fail(buf);
  }
  return true;
}

}  // namespace lod::viewer
