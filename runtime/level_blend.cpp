// Level blends: restart, reverse or settle each entry's blend.
#include "runtime/level_blend.h"

#include <algorithm>
#include <cassert>

#include "runtime/geomorph.h"

namespace lod {

BlendTotals advance_level_blends(std::span<float> morph, std::span<uint8_t> from_level,
                                 std::span<const uint32_t> ids, std::span<const uint8_t> level,
                                 std::span<const uint32_t> model, const LevelBlendState& s,
                                 std::span<const uint8_t> model_blends, const ModelTable& models, double now,
                                 float seconds) {
  const size_t n = ids.size();
  assert(morph.size() == n && from_level.size() == n && level.size() == n && model.size() == n);
  BlendTotals totals;
  for (size_t k = 0; k < n; ++k) {
    const uint32_t id = ids[k];
    const uint8_t lv = level[k];
    if (s.was_visible[id] && s.prev_level[id] != lv) {
      const float m = morph_factor(now, s.morph_start[id], seconds);
      const bool reverses = m < 1 && s.morph_from[id] == lv;
      s.morph_start[id] = reverses ? now - double(1 - m) * seconds : now;
      s.morph_from[id] = s.prev_level[id];
    }
    if (!s.was_visible[id]) s.morph_start[id] = -1e300;
    morph[k] = morph_factor(now, s.morph_start[id], seconds);
    const uint32_t m = model[k];
    const uint32_t first = models.first_level[m];
    // Into or out of the culled level (no triangles): no targets to morph to, the object
    // disappears or appears at once.
    const uint8_t from = s.morph_from[id];
    const bool blends = morph[k] < 1 && model_blends[m] && from != lv && from < models.level_count[m] &&
                        models.triangles[first + lv] > 0 && models.triangles[first + from] > 0;
    from_level[k] = blends ? s.morph_from[id] : lv;
    if (blends) {
      ++totals.morphing;
      totals.extra_tris += models.triangles[first + std::min(lv, s.morph_from[id])] - models.triangles[first + lv];
    }
  }
  return totals;
}

BlendTotals fit_blends_to_room(std::span<float> morph, std::span<uint8_t> from_level, std::span<const uint32_t> ids,
                               std::span<const uint8_t> level, std::span<const uint32_t> model,
                               const LevelBlendState& s, const ModelTable& models, uint64_t room) {
  BlendTotals kept;
  for (size_t k = 0; k < ids.size(); ++k) {
    const uint8_t lv = level[k], from = from_level[k];
    if (from == lv) continue;
    const uint32_t first = models.first_level[model[k]];
    const uint64_t extra = models.triangles[first + std::min(lv, from)] - models.triangles[first + lv];
    if (kept.extra_tris + extra <= room) {
      ++kept.morphing;
      kept.extra_tris += extra;
      continue;
    }
    from_level[k] = lv;  // dropped: settled at the new level from now on
    morph[k] = 1;
    s.morph_start[ids[k]] = -1e300;
    s.morph_from[ids[k]] = lv;
  }
  return kept;
}

}  // namespace lod
