// The terrain's share of M by feedback, its ROAM update under it, and its frame mesh.
#include "runtime/terrain_lod.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace lod {
namespace {

inline constexpr double kShareStep = 1.0625;  // both short: the share moves this factor a frame

struct ShareRange {
  uint64_t lo, hi;
};

ShareRange share_range(uint64_t budget, const TerrainModel& m) {
  const uint64_t cap = m.max_triangles;
  const uint64_t lo = std::max<uint64_t>(2, static_cast<uint64_t>(std::llround(double(budget) * m.min_share)));
  const uint64_t hi = std::max<uint64_t>(lo, static_cast<uint64_t>(std::llround(double(budget) * m.max_share)));
  return {std::min(lo, cap), std::min(hi, cap)};
}

// What the terrain should get next, before the range: see the header.
double wanted_share(const TerrainFeedback& f) {
  const double need = double(f.terrain_tris) + double(f.terrain_tris) / 8 + 64;  // met tau: this and room to grow
  if (!f.objects_lowered) {
    if (!f.terrain_bound) return need;
    const uint64_t used = f.share + f.objects_tris;
    const uint64_t room = f.budget > used ? f.budget - used : 0;
    return double(f.share) + double(room) / 2;  // only what the objects left: they keep theirs
  }
  // The objects are short too: balance the worst screen-space errors.
  const double base = f.terrain_bound ? double(f.share) : std::min(double(f.share), need);
  if (f.objects_error <= 0) return base;  // no measure to balance on: hold
  return f.terrain_error > f.objects_error ? base * kShareStep : base / kShareStep;
}

}  // namespace

void terrain_lod_reset(TerrainLod& lod, const TerrainModel& model, float morph_seconds) {
  roam_reset(lod.roam, model.roam);
  terrain_morph_reset(lod.morph, model.roam, morph_seconds);
  lod.last_morph = {};
  lod.share = 0;
  lod.started = 0;
  lod.grid_indices.clear();
  lod.remap.assign(model.roam.positions.size(), UINT32_MAX);
}

uint64_t first_terrain_share(uint64_t budget, const TerrainModel& model) {
  if (budget == 0) return model.max_triangles;
  const ShareRange r = share_range(budget, model);
  return std::clamp<uint64_t>(static_cast<uint64_t>(std::llround(double(budget) * model.initial_share)), r.lo, r.hi);
}

uint64_t next_terrain_share(const TerrainFeedback& last, const TerrainModel& model) {
  if (last.budget == 0) return model.max_triangles;
  ShareRange r = share_range(last.budget, model);
  const uint64_t keep = last.objects_coarsest + last.objects_coarsest / 4 + 64;
  r.hi = std::max(r.lo, last.budget > keep ? std::min(r.hi, last.budget - keep) : r.lo);
  const double want = std::clamp(wanted_share(last), double(r.lo), double(r.hi));
  return static_cast<uint64_t>(want);
}

RoamFrameStats terrain_lod_update(TerrainLod& lod, const TerrainModel& model, const View& view, uint64_t share,
                                  double now, const RoamClock& clock) {
  RoamParams p;
  p.target = model.target;
  p.pixel_error = model.pixel_error;
  p.max_ms = model.max_ms;
  p.clock = clock;
  const uint64_t total = std::clamp<uint64_t>(share, 2, model.max_triangles);
  // Room for merges still lowering, at most an eighth of the share: each merge made for this
  // room lowers too, so an unbounded reserve would feed on itself while the camera moves.
  const uint64_t lowering = std::min<uint64_t>({lod.morph.ghost_wanted, total / 8, total - 2});
  const uint32_t cap = static_cast<uint32_t>(total - lowering);
  p.max_triangles = cap;
  p.triangle_count = cap;
  const RoamFrameStats st = roam_update(lod.roam, model.roam, view, p);
  const uint64_t room = total > lod.roam.triangle_count ? total - lod.roam.triangle_count : 0;
  lod.last_morph = terrain_morph_update(lod.morph, lod.roam, model.roam, now, room);
  return st;
}

float terrain_error_left(const RoamState& state) {
  const std::vector<int32_t>& heap = state.split_queue.heap;
  return heap.empty() ? 0.f : state.priority[heap.front()];
}

size_t terrain_compact_mesh(std::vector<float>& positions, std::vector<uint32_t>& indices,
                            std::vector<uint32_t>& samples, TerrainLod& lod, const RoamTerrain& terrain) {
  assert(lod.remap.size() == terrain.positions.size());
  const size_t tris = roam_triangles_of(lod.grid_indices, lod.morph.shown, terrain);
  positions.clear();
  samples.clear();
  indices.resize(lod.grid_indices.size());
  for (size_t i = 0; i < lod.grid_indices.size(); ++i) {
    const uint32_t s = lod.grid_indices[i];
    uint32_t& local = lod.remap[s];
    if (local == UINT32_MAX) {
      local = static_cast<uint32_t>(samples.size());
      samples.push_back(s);
      const glm::vec3& p = terrain.positions[s];
      positions.insert(positions.end(), {p.x, lod.morph.height[s], p.z});
    }
    indices[i] = local;
  }
  for (uint32_t s : samples) lod.remap[s] = UINT32_MAX;  // ready for the next frame
  return tris;
}

}  // namespace lod
