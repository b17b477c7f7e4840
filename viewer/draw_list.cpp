// Counting sort of a frame's visible objects by (model, drawn level, target level): two passes
// over the frame, no per-frame allocation once the list has grown to the scene's size.
#include "viewer/draw_list.h"

#include <algorithm>

namespace lod::viewer {

void build_draw_list(const Frame& frame, const ObjectSet& objects, const MeshLayout& layout, DrawList& out) {
  out.batches.clear();
  out.triangles = 0;
  out.indices = 0;
  out.rejected = 0;
  out.vd.clear();
  out.vd_triangles = 0;
  out.vd_level_triangles = 0;
  out.morphing = 0;
  out.morph_triangles = 0;
  // Keys: per model, level_count^2 (drawn, target) pairs.
  std::vector<uint32_t>& first_key = out.first_key;
  first_key.assign(layout.level_count.size() + 1, 0);
  for (size_t m = 0; m < layout.level_count.size(); ++m)
    first_key[m + 1] = first_key[m] + layout.level_count[m] * layout.level_count[m];
  std::vector<uint32_t>& slot = out.per_batch_slot;
  slot.assign(size_t(first_key.back()) + 1, 0);

  // A torn frame could have arrays of different lengths; draw only the common prefix.
  const size_t n = std::min({frame.objects.size(), frame.levels.size(), frame.morph.size()});
  const bool has_from = frame.from_levels.size() >= n;
  auto transform_of = [&](uint32_t id, float morph, float weight) {
    InstanceData d;
    d.position_scale[0] = objects.x[id];
    d.position_scale[1] = objects.y[id];
    d.position_scale[2] = objects.z[id];
    d.position_scale[3] = objects.scale[id];
    d.yaw = objects.yaw[id];
    d.morph = morph;
    d.weight = weight;
    return d;
  };

  // View-dependent objects: both lists are in object order, so one merge marks their entries.
  // Their entry is not an instance; its level's triangles are what tris_selected counted.
  out.is_vd.assign(n, 0);
  size_t k = 0;
  for (const VdObjectFrame& v : frame.vd_objects) {
    while (k < n && frame.objects[k] < v.object) ++k;
    const bool listed = k < n && frame.objects[k] == v.object;
    const bool in_range = uint64_t(v.first_vertex) + v.vertex_count <= frame.vd_positions.size() / 3 &&
                          uint64_t(v.first_index) + v.index_count <= frame.vd_indices.size() &&
                          v.index_count % 3 == 0 && v.object < objects.size();
    bool indices_ok = in_range;
    for (uint32_t i = 0; indices_ok && i < v.index_count; ++i)
      indices_ok = frame.vd_indices[v.first_index + i] < v.vertex_count;
    if (!listed || !indices_ok) {
      ++out.rejected;
      continue;
    }
    out.is_vd[k] = 1;
    const uint32_t model = objects.model[v.object];
    if (model < layout.level_count.size() && frame.levels[k] < layout.level_count[model])
      out.vd_level_triangles += layout.ranges[layout.range_of(model, frame.levels[k])].index_count / 3;
    out.vd.push_back({v.object, v.first_vertex, v.vertex_count, v.first_index, v.index_count,
                      transform_of(v.object, 1.f, 0.f)});
    out.vd_triangles += v.index_count / 3;
  }

  // Where entry i is drawn: its key and how it blends; false for entries out of range.
  auto place = [&](size_t i, uint32_t* key, MorphDraw* how) {
    const uint32_t id = frame.objects[i];
    if (id >= objects.size()) return false;
    const uint32_t model = objects.model[id];
    if (model >= layout.level_count.size()) return false;
    const uint32_t levels = layout.level_count[model], to = frame.levels[i];
    const uint32_t from = has_from && layout.morphable[model] ? frame.from_levels[i] : to;
    if (to >= levels || from >= levels) return false;
    *how = morph_draw(from, to, frame.morph[i]);
    *key = first_key[model] + how->level * levels + how->target;
    return true;
  };

  uint32_t drawn = 0;
  for (size_t i = 0; i < n; ++i) {
    if (out.is_vd[i]) continue;
    uint32_t key;
    MorphDraw how;
    if (place(i, &key, &how)) {
      ++slot[key + 1];
      ++drawn;
      if (how.target != how.level) {
        const uint32_t model = objects.model[frame.objects[i]];
        ++out.morphing;
        out.morph_triangles += layout.ranges[layout.range_of(model, how.level)].index_count / 3 -
                               layout.ranges[layout.range_of(model, frame.levels[i])].index_count / 3;
      }
    } else {
      ++out.rejected;
    }
  }
  for (size_t s = 1; s < slot.size(); ++s) slot[s] += slot[s - 1];  // slot[s] = first instance of key s

  for (uint32_t model = 0; model < layout.level_count.size(); ++model) {
    const uint32_t levels = layout.level_count[model];
    for (uint32_t level = 0; level < levels; ++level) {
      for (uint32_t target = level; target < levels; ++target) {
        const uint32_t key = first_key[model] + level * levels + target;
        const uint32_t count = slot[key + 1] - slot[key];
        if (count == 0) continue;
        const uint32_t r = layout.range_of(model, level);
        out.batches.push_back({r, model, level, target, slot[key], count});
        const uint64_t idx = uint64_t(layout.ranges[r].index_count) * count;
        out.indices += idx;
        out.triangles += idx / 3;
      }
    }
  }

  out.instances.resize(drawn);
  for (size_t i = 0; i < n; ++i) {
    uint32_t key;
    MorphDraw how;
    if (out.is_vd[i] || !place(i, &key, &how)) continue;
    out.instances[slot[key]++] = transform_of(frame.objects[i], frame.morph[i], how.weight);
  }
}

}  // namespace lod::viewer
