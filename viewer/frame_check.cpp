// Whole-frame checks from the frame's own columns: an entry's model is frame.models[i], its
// object index frame.objects[i]; the scene only gives the models' level tables.
#include "viewer/frame_check.h"

#include <algorithm>
#include <cstdio>

namespace lod::viewer {

namespace {

bool fail(std::string* why, const char* text) {
  *why = text;
  return false;
}

bool columns_match(const Frame& f, std::string* why) {
  const size_t n = f.visible;
  if (f.handles.size() != n || f.models.size() != n || f.transforms.size() != n || f.view_masks.size() != n ||
      f.objects.size() != n || f.levels.size() != n || f.morph.size() != n || f.from_levels.size() != n)
    return fail(why, "per-object arrays do not match the visible count");
  uint64_t histogram = 0;
  for (uint32_t c : f.level_histogram) histogram += c;
  if (histogram != f.visible) return fail(why, "level histogram does not count the visible objects");
  return true;
}

// Entry i names a live object (in increasing object order, with a handle), a model of the
// scene, and levels that model has.
bool entry_ok(const Frame& f, const ModelTable& models, size_t i, std::string* why) {
  char buf[256];
  const uint32_t id = f.objects[i], m = f.models[i];
  if (id >= f.object_count || (i > 0 && f.objects[i - 1] >= id) || f.handles[i] == 0) {
    std::snprintf(buf, sizeof buf, "entry %zu: object id %u out of order or range", i, id);
    return fail(why, buf);
  }
  if (m >= models.model_count()) {
    std::snprintf(buf, sizeof buf, "object %u: model %u of %zu", id, m, models.model_count());
    return fail(why, buf);
  }
  if (f.levels[i] >= models.level_count[m] || f.from_levels[i] >= models.level_count[m]) {
    std::snprintf(buf, sizeof buf, "object %u: level %u (from %u) of %u", id, unsigned(f.levels[i]),
                  unsigned(f.from_levels[i]), unsigned(models.level_count[m]));
    return fail(why, buf);
  }
  return true;
}

// The selected levels' triangles and the HLOD cuts' add up to tris_selected, the finer levels of morphing
// entries to tris_morph_extra over `morphing` entries.
bool totals_match(const Frame& f, const ModelTable& models, std::string* why) {
  char buf[256];
  uint64_t tris = 0, extra = 0;
  uint32_t morphing = 0;
  for (size_t i = 0; i < f.objects.size(); ++i) {
    if (!entry_ok(f, models, i, why)) return false;
    const uint32_t first = models.first_level[f.models[i]];
    tris += models.triangles[first + f.levels[i]];
    if (f.from_levels[i] != f.levels[i]) {
      ++morphing;
      extra += models.triangles[first + std::min(f.from_levels[i], f.levels[i])] -
               models.triangles[first + f.levels[i]];
    }
  }
  if (morphing != f.morphing || extra != f.tris_morph_extra) {
    std::snprintf(buf, sizeof buf, "%u objects morph adding %llu triangles but the frame says %u adding %llu",
                  morphing, (unsigned long long)extra, f.morphing, (unsigned long long)f.tris_morph_extra);
    return fail(why, buf);
  }
  tris += f.hlod_tris + f.scene_proxy_tris + f.terrain_tris;  // all within the same M
  if (tris != f.tris_selected) {
    std::snprintf(buf, sizeof buf, "tris_selected %llu but the levels, hlod cuts, proxies and terrain add up to %llu",
                  (unsigned long long)f.tris_selected, (unsigned long long)tris);
    return fail(why, buf);
  }
  return true;
}

// View-dependent meshes: each names its own entry (in increasing entry order, so object order),
// packed back to back over vd_positions / vd_indices, adding up to vd_active_tris.
bool vd_meshes_match(const Frame& f, std::string* why) {
  char buf[256];
  uint64_t vertices = 0, indices = 0, vd_tris = 0;
  for (size_t j = 0; j < f.vd_objects.size(); ++j) {
    const VdObjectFrame& v = f.vd_objects[j];
    if (v.entry >= f.objects.size() || f.objects[v.entry] != v.object ||
        (j > 0 && f.vd_objects[j - 1].entry >= v.entry)) {
      std::snprintf(buf, sizeof buf,
                    "vd entry %zu: object %u is not the visible object of entry %u (or out of order)", j,
                    v.object, v.entry);
      return fail(why, buf);
    }
    if (v.first_vertex != vertices || v.first_index != indices || v.index_count % 3 != 0) {
      std::snprintf(buf, sizeof buf, "vd entry %zu (object %u): ranges not packed back to back", j, v.object);
      return fail(why, buf);
    }
    vertices += v.vertex_count;
    indices += v.index_count;
    vd_tris += v.index_count / 3;
  }
  if (3 * vertices != f.vd_positions.size() || indices != f.vd_indices.size())
    return fail(why, "vd positions / indices do not match the vd entries");
  if (vd_tris != f.vd_active_tris) {
    std::snprintf(buf, sizeof buf, "vd_active_tris %llu but the vd meshes add up to %llu",
                  (unsigned long long)f.vd_active_tris, (unsigned long long)vd_tris);
    return fail(why, buf);
  }
  return true;
}

}  // namespace

bool frame_is_whole(const Frame& f, const Scene& scene, std::string* why) {
  return columns_match(f, why) && totals_match(f, scene.models, why) && vd_meshes_match(f, why);
}

}  // namespace lod::viewer
