// Counting sort of a frame's visible entries by (model, drawn level, target level): two passes
// over the frame, no per-frame allocation once the list has grown to the scene's size. Every
// entry is drawn from the frame's own columns (models, transforms), never from a scene.
#include "viewer/draw_list.h"

#include <algorithm>
#include <cmath>

namespace lod::viewer {

namespace {

void clear_totals(DrawList& out) {
  out.batches.clear();
  out.triangles = 0;
  out.indices = 0;
  out.rejected = 0;
  out.vd.clear();
  out.vd_triangles = 0;
  out.vd_level_triangles = 0;
  out.morphing = 0;
  out.morph_triangles = 0;
}

// Keys: per model, level_count^2 (drawn, target) pairs; slot[key + 1] counts the key's instances.
void size_keys(const MeshLayout& layout, DrawList& out) {
  std::vector<uint32_t>& first_key = out.first_key;
  first_key.assign(layout.level_count.size() + 1, 0);
  for (size_t m = 0; m < layout.level_count.size(); ++m)
    first_key[m + 1] = first_key[m] + layout.level_count[m] * layout.level_count[m];
  out.per_batch_slot.assign(size_t(first_key.back()) + 1, 0);
}

// Entries every per-entry column a draw reads has (a torn frame could have columns of
// different lengths), and how many entries some column has beyond them.
size_t drawable_entries(const Frame& f, size_t* longest) {
  const size_t n = std::min({f.models.size(), f.transforms.size(), f.levels.size(), f.morph.size()});
  *longest = std::max({f.models.size(), f.transforms.size(), f.levels.size(), f.morph.size()});
  return n;
}

uint32_t level_triangles(const MeshLayout& layout, uint32_t model, uint32_t level) {
  return layout.ranges[layout.range_of(model, level)].index_count / 3;
}

// A vd entry is drawable when it names a distinct drawable entry (whose object it is, when the
// frame carries objects) and its ranges and local indices stay inside the frame's vd arrays.
bool vd_entry_ok(const Frame& f, const VdObjectFrame& v, size_t n, const std::vector<uint8_t>& is_vd) {
  if (v.entry >= n || is_vd[v.entry]) return false;
  if (v.entry < f.objects.size() && f.objects[v.entry] != v.object) return false;
  if (uint64_t(v.first_vertex) + v.vertex_count > f.vd_positions.size() / 3 ||
      uint64_t(v.first_index) + v.index_count > f.vd_indices.size() || v.index_count % 3 != 0)
    return false;
  for (uint32_t i = 0; i < v.index_count; ++i)
    if (f.vd_indices[v.first_index + i] >= v.vertex_count) return false;
  return true;
}

// A vd object's material runs, when they cover its indices in order within the frame's runs
// and name materials its model has; else none (drawn as one surface).
void add_vd_runs(const Frame& f, const VdObjectFrame& v, uint32_t model, const MeshLayout& layout, DrawList& out,
                 VdDraw& d) {
  if (v.run_count == 0 || uint64_t(v.first_run) + v.run_count > f.vd_runs.size() || model >= layout.first_material.size())
    return;
  const uint32_t first = layout.first_material[model];
  const uint32_t count =
      (model + 1 < layout.first_material.size() ? layout.first_material[model + 1] : layout.material_count) - first;
  uint64_t at = v.first_index;
  for (uint32_t k = v.first_run; k < v.first_run + v.run_count; ++k) {
    const VdRunFrame& r = f.vd_runs[k];
    if (r.first_index != at || r.index_count % 3 != 0) return;
    at += r.index_count;
  }
  if (at != uint64_t(v.first_index) + v.index_count) return;
  d.first_run = static_cast<uint32_t>(out.vd_runs.size());
  d.run_count = v.run_count;
  for (uint32_t k = v.first_run; k < v.first_run + v.run_count; ++k) {
    const VdRunFrame& r = f.vd_runs[k];
    const bool known = r.material >= 0 && uint32_t(r.material) < count;
    out.vd_runs.push_back({r.first_index, r.index_count, known ? int32_t(first + uint32_t(r.material)) : -1});
  }
}

// View-dependent objects: their entry is not an instance; its level's triangles are what
// tris_selected counted for it.
void add_vd_draws(const Frame& f, size_t n, const MeshLayout& layout, DrawList& out) {
  out.is_vd.assign(n, 0);
  out.vd_runs.clear();
  for (const VdObjectFrame& v : f.vd_objects) {
    InstanceData transform;
    if (!vd_entry_ok(f, v, n, out.is_vd) || !instance_of(f.transforms[v.entry], 1.f, 0.f, &transform)) {
      ++out.rejected;
      continue;
    }
    out.is_vd[v.entry] = 1;
    const uint32_t model = f.models[v.entry];
    if (model < layout.level_count.size() && f.levels[v.entry] < layout.level_count[model])
      out.vd_level_triangles += level_triangles(layout, model, f.levels[v.entry]);
    VdDraw d{v.object, v.entry, v.first_vertex, v.vertex_count, v.first_index, v.index_count, transform};
    if (model < layout.level_count.size() && layout.level_count[model] > 0) {
      const float* c = layout.ranges[layout.range_of(model, 0)].center;
      std::copy(c, c + 3, d.center);
    }
    add_vd_runs(f, v, model, layout, out, d);
    out.vd.push_back(d);
    out.vd_triangles += v.index_count / 3;
  }
}

// Where entry i is drawn: its key, how it blends and its attributes; false when the frame
// names a model or level the layout does not have, or a transform that cannot be drawn.
bool place(const Frame& f, size_t i, const MeshLayout& layout, const DrawList& out, uint32_t* key,
           MorphDraw* how, InstanceData* data) {
  const uint32_t model = f.models[i];
  if (model >= layout.level_count.size()) return false;
  const uint32_t levels = layout.level_count[model], to = f.levels[i];
  const bool has_from = f.from_levels.size() > i && layout.morphable[model];
  const uint32_t from = has_from ? f.from_levels[i] : to;
  if (to >= levels || from >= levels) return false;
  *how = morph_draw(from, to, f.morph[i]);
  *key = out.first_key[model] + how->level * levels + how->target;
  return instance_of(f.transforms[i], f.morph[i], how->weight, data);
}

// First pass: instances per key, morph totals, refusals. Returns the instances to draw.
uint32_t count_instances(const Frame& f, size_t n, const MeshLayout& layout, DrawList& out) {
  uint32_t drawn = 0;
  for (size_t i = 0; i < n; ++i) {
    if (out.is_vd[i]) continue;
    uint32_t key;
    MorphDraw how;
    InstanceData data;
    if (!place(f, i, layout, out, &key, &how, &data)) {
      ++out.rejected;
      continue;
    }
    ++out.per_batch_slot[key + 1];
    ++drawn;
    if (how.target != how.level) {
      ++out.morphing;
      out.morph_triangles +=
          level_triangles(layout, f.models[i], how.level) - level_triangles(layout, f.models[i], f.levels[i]);
    }
  }
  return drawn;
}

// Turns the counts into first instances and emits the non-empty batches in key order.
void emit_batches(const MeshLayout& layout, DrawList& out) {
  std::vector<uint32_t>& slot = out.per_batch_slot;
  for (size_t s = 1; s < slot.size(); ++s) slot[s] += slot[s - 1];  // slot[s] = first instance of key s
  for (uint32_t model = 0; model < layout.level_count.size(); ++model) {
    const uint32_t levels = layout.level_count[model];
    for (uint32_t level = 0; level < levels; ++level) {
      for (uint32_t target = level; target < levels; ++target) {
        const uint32_t key = out.first_key[model] + level * levels + target;
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
}

}  // namespace

bool instance_of(const Transform& t, float morph, float weight, InstanceData* out) {
  const float* p = t.position;
  const float* q = t.rotation;
  const bool finite = std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]) &&
                      std::isfinite(q[0]) && std::isfinite(q[1]) && std::isfinite(q[2]) &&
                      std::isfinite(q[3]) && std::isfinite(t.scale);
  // A zero quaternion has no rotation to normalise to; the shader would draw NaNs.
  if (!finite || !(t.scale > 0) || q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] == 0.f) return false;
  *out = {{p[0], p[1], p[2], t.scale}, {q[0], q[1], q[2], q[3]}, morph, weight};
  return true;
}

void build_draw_list(const Frame& frame, const MeshLayout& layout, DrawList& out) {
  clear_totals(out);
  size_keys(layout, out);
  size_t longest = 0;
  const size_t n = drawable_entries(frame, &longest);
  out.rejected += uint32_t(longest - n);  // entries some column lacks: not drawable at all
  add_vd_draws(frame, n, layout, out);
  out.instances.resize(count_instances(frame, n, layout, out));
  emit_batches(layout, out);
  for (size_t i = 0; i < n; ++i) {
    uint32_t key;
    MorphDraw how;
    InstanceData data;
    if (out.is_vd[i] || !place(frame, i, layout, out, &key, &how, &data)) continue;
    out.instances[out.per_batch_slot[key]++] = data;
  }
}

}  // namespace lod::viewer
