// ROAM geomorphs: events -> motions, flat merged diamonds removed fine to coarse, displayed
// heights coarse to fine.
#include "runtime/terrain_morph.h"

#include <algorithm>
#include <array>
#include <cassert>

namespace lod {
namespace detail {

void start_motion(TerrainMorph& M, int32_t d, int8_t direction, double now) {
  M.from[d] = terrain_morph_factor(M, d, now);
  M.since[d] = now;
  M.direction[d] = direction;
  if (!M.in_active[d]) {
    M.in_active[d] = 1;
    M.active.push_back(d);
  }
}

void take_events(TerrainMorph& M, const RoamState& S, double now) {
  for (const int32_t e : S.events) {
    if (e >= 0) {
      if (!M.shown[e]) {  // newly drawn: its centre starts on the base edge
        M.shown[e] = 1;
        M.factor[e] = 0;
        M.direction[e] = 0;
      }
      start_motion(M, e, +1, now);
    } else {
      start_motion(M, ~e, -1, now);  // still drawn while it lowers
    }
  }
}

bool child_shown(const TerrainMorph& M, const RoamTerrain& T, int32_t d) {
  for (int32_t c : T.children[d])
    if (c >= 0 && M.shown[c]) return true;
  return false;
}

bool removable(const TerrainMorph& M, const RoamState& S, const RoamTerrain& T, int32_t d) {
  return M.shown[d] && !S.split[d] && !child_shown(M, T, d);
}

void settle(TerrainMorph& M, const RoamTerrain& T, int32_t d, bool drawn) {
  M.shown[d] = drawn ? 1 : 0;
  M.factor[d] = 1;
  M.direction[d] = 0;
  M.height[d] = T.positions[d].y;
}

// Flattest removable merged diamonds first until the extra triangles fit the room. A pass
// sorts the removable ones once; removing children can free their parents for the next pass.
uint32_t cut_to_room(TerrainMorph& M, const RoamState& S, const RoamTerrain& T, uint64_t room,
                     std::vector<int32_t>& candidates) {
  uint32_t cut = 0;
  while (M.ghost_triangles > room) {
    candidates.clear();
    for (int32_t d : M.active)
      if (removable(M, S, T, d)) candidates.push_back(d);
    if (candidates.empty()) break;
    std::sort(candidates.begin(), candidates.end(),
              [&](int32_t a, int32_t b) { return M.factor[a] < M.factor[b] || (M.factor[a] == M.factor[b] && a < b); });
    for (int32_t d : candidates) {
      if (M.ghost_triangles <= room) break;
      settle(M, T, d, false);
      M.ghost_triangles -= T.triangles[d];
      ++cut;
    }
  }
  return cut;
}

}  // namespace detail

void terrain_morph_reset(TerrainMorph& M, const RoamTerrain& T, float duration) {
  const size_t n = T.positions.size();
  M.duration = duration;
  M.shown.assign(n, 0);
  M.from.assign(n, 1.f);
  M.since.assign(n, 0.0);
  M.direction.assign(n, 0);
  M.factor.assign(n, 1.f);
  M.height.resize(n);
  for (size_t i = 0; i < n; ++i) M.height[i] = T.positions[i].y;
  M.active.clear();
  M.active.reserve(4096);
  M.in_active.assign(n, 0);
  M.ghost_triangles = M.ghost_wanted = 0;
}

float terrain_morph_factor(const TerrainMorph& M, int32_t d, double now) {
  if (M.direction[d] == 0) return M.factor[d];
  if (M.duration <= 0) return M.direction[d] > 0 ? 1.f : 0.f;
  const float t = M.from[d] + float(M.direction[d]) * float((now - M.since[d]) / double(M.duration));
  return std::clamp(t, 0.f, 1.f);
}

TerrainMorphStats terrain_morph_update(TerrainMorph& M, const RoamState& S, const RoamTerrain& T, double now,
                                       uint64_t room) {
  assert(M.shown.size() == S.split.size());
  TerrainMorphStats st;
  detail::take_events(M, S, now);
  for (int32_t d : M.active) M.factor[d] = terrain_morph_factor(M, d, now);
  // Coarse first for heights; the removal pass walks it backwards (children before parents).
  std::sort(M.active.begin(), M.active.end(), [&](int32_t a, int32_t b) {
    const int da = roam_depth(T, a), db = roam_depth(T, b);
    return da < db || (da == db && a < b);
  });
  M.ghost_triangles = 0;
  for (size_t i = M.active.size(); i-- > 0;) {
    const int32_t d = M.active[i];
    if (M.direction[d] > 0 && M.factor[d] >= 1.f) detail::settle(M, T, d, true);
    else if (M.direction[d] < 0 && M.factor[d] <= 0.f && detail::removable(M, S, T, d)) detail::settle(M, T, d, false);
    else if (M.shown[d] && !S.split[d]) M.ghost_triangles += T.triangles[d];
  }
  M.ghost_wanted = M.ghost_triangles;
  st.cut_short = detail::cut_to_room(M, S, T, room, M.scratch);
  // Drop the settled, then place the rest: mid of the base ends' displayed heights.
  size_t kept = 0;
  for (int32_t d : M.active) {
    if (M.direction[d] == 0 && M.factor[d] >= 1.f) {
      M.in_active[d] = 0;
      continue;
    }
    M.active[kept++] = d;
    const std::array<int32_t, 2> ends = roam_base_ends(T, d);
    const float mid = 0.5f * (M.height[ends[0]] + M.height[ends[1]]);
    const float t = M.factor[d];
    M.height[d] = t >= 1.f ? T.positions[d].y : (1.f - t) * mid + t * T.positions[d].y;
  }
  M.active.resize(kept);
  st.morphing = uint32_t(kept);
  st.ghost_triangles = M.ghost_triangles;
  return st;
}

}  // namespace lod
