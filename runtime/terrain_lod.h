// TerrainLod: the terrain ([[terrain]]) as one object of the frame's triangle budget M.
//
// ROAM (runtime/roam.h) refines the terrain for view 0 every frame, capped by the terrain's
// share of M. The share moves by feedback on what the last frame did, as a view-dependent
// front's threshold does (runtime/vd_share.h). While the selection did not have to lower the
// objects: a terrain that met its pixel error gets what it used (plus an eighth + 64 to grow
// into), a terrain the share stopped takes half the room the objects left. When the selection
// lowered levels (or even the coarsest did not fit), the share moves 6 % a frame towards
// whichever of the two is left with the larger screen-space error, so the worst error of
// terrain and objects tends to one value. The discrete selection gets M minus the share, so
// objects + terrain never pass M; the share leaves the objects their coarsest cost and a
// quarter more (objects coming into view), so that the objects' coarsest levels keep fitting.
// State across frames (the ROAM state, the share, scratch) lives in TerrainLod; the functions
// are pure over it: no threads, clocks or logging.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "runtime/roam.h"
#include "runtime/terrain_morph.h"
#include "runtime/view.h"

namespace lod {

// The immutable terrain a frame graph draws, shared by every frame.
struct TerrainModel {
  RoamTerrain roam;                          // positions are world space (placement applied)
  RoamTarget target = RoamTarget::pixel_error;  // pixel_error: the share caps it; triangle_count: = share;
                                                // time_limit: toward the share while max_ms lasts
  float max_ms = 0;                          // ROAM's time limit per frame, any target (0: none)
  float pixel_error = 1;                     // tau, pixels
  uint32_t max_triangles = 1u << 18;         // absolute cap (and the share under levels budgets)
  float initial_share = 0.5f;                // fractions of M
  float min_share = 0.05f, max_share = 0.9f;
};

// What the last frame did, for the next share.
struct TerrainFeedback {
  uint64_t budget = 0;          // M in triangles; 0: not a triangle budget (the share is max_triangles)
  uint64_t share = 0;           // the terrain's share last frame
  uint64_t terrain_tris = 0;
  uint8_t terrain_bound = 0;    // ROAM stopped at the share before reaching its pixel error
  float terrain_error = 0;      // the largest projected error left on the terrain, pixels
  uint64_t objects_tris = 0;    // discrete + HLOD triangles selected
  uint64_t objects_coarsest = 0;  // what the visible objects cost at their coarsest levels
  uint8_t objects_lowered = 0;  // the selection lowered levels to fit M minus the share
  float objects_error = 0;      // the worst screen-space error left on the objects, pixels (0: unknown)
};

struct TerrainLod {
  RoamState roam;
  TerrainMorph morph;                  // geomorphs of ROAM's splits and merges (the drawn mesh)
  TerrainMorphStats last_morph;
  uint64_t share = 0;                  // triangles of M this frame
  uint8_t started = 0;                 // 0 until the first share is set
  std::vector<uint32_t> grid_indices;  // scratch: the mesh in sample ids
  std::vector<uint32_t> remap;         // scratch per sample: UINT32_MAX between calls
};

// The coarsest mesh, share unset; sizes every array once. Splits and merges geomorph over
// morph_seconds (0: none).
void terrain_lod_reset(TerrainLod& lod, const TerrainModel& model, float morph_seconds = 0);

// The share for the first frame, then from each frame's feedback; within
// [min_share, max_share] * M and never above max_triangles.
uint64_t first_terrain_share(uint64_t budget, const TerrainModel& model);
uint64_t next_terrain_share(const TerrainFeedback& last, const TerrainModel& model);

// ROAM for `view` under `share` (pixel_error target: max_triangles = share; triangle_count
// target: the count is the share), then the geomorphs at time `now` (seconds). ROAM gets the
// share minus the triangles last frame's lowering merges drew (at most an eighth of it), and
// this frame's lowering merges are cut to what is left, so the drawn mesh stays within the share.
// `clock` times model.max_ms (without one there is no time limit).
RoamFrameStats terrain_lod_update(TerrainLod& lod, const TerrainModel& model, const View& view, uint64_t share,
                                  double now = 0, const RoamClock& clock = {});

// The largest projected error of a mesh triangle, pixels: the split queue's top.
float terrain_error_left(const RoamState& state);

// The drawn mesh (ROAM's plus merges still lowering, at their geomorphed heights) compacted for
// a renderer: xyz world positions per used sample, 3 local indices per triangle, and per vertex
// its sample id (y * size + x; check_terrain_mesh takes those back); one vertex per sample.
// Uses lod.remap and lod.grid_indices as scratch; returns the triangle count.
size_t terrain_compact_mesh(std::vector<float>& positions, std::vector<uint32_t>& indices,
                            std::vector<uint32_t>& samples, TerrainLod& lod, const RoamTerrain& terrain);

}  // namespace lod
