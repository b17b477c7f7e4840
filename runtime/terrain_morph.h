// Geomorphing of ROAM splits and merges, as view-dependent objects geomorph
// (runtime/geomorph.h): a change of detail moves vertices over `duration` seconds instead of
// popping.
//
// A split diamond's centre vertex rises from the midpoint of its base edge to its true height:
// height = (1 - t) * mid + t * true, t going 0 -> 1 over the duration, where mid is the mean of
// the base ends' *displayed* heights (the base ends are coarser vertices, computed first), so at
// t = 0 the new vertex lies exactly on the edge it splits and nothing moves on the frame of the
// split. A merge is drawn late: ROAM merges at once (its queues and triangle count are exact),
// but the diamond stays drawn split while its centre lowers, t going back to 0, and is removed
// once it is flat and none of its children is still drawn split, so the drawn split flags stay
// closed under parents (no crack, no T-junction: roam_triangles_of()). A diamond split again
// while lowering rises from where it is. Each vertex has one displayed height, whatever triangle
// uses it, so morphed meshes are as watertight as the settled ones.
// Budget: lowering diamonds draw extra triangles; the caller passes the room it has for them
// (share minus ROAM's triangles) and the flattest removable ones finish at once when it is short.
// Pure functions over TerrainMorph: no threads, clocks or logging.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "runtime/roam.h"

namespace lod {

struct TerrainMorph {
  float duration = 0;              // seconds; <= 0: no geomorphing (drawn = ROAM's mesh)
  std::vector<uint8_t> shown;      // per sample: the diamond centred there is drawn split
  std::vector<float> from;         // per sample: morph factor when the current motion started
  std::vector<double> since;       // per sample: when it started, seconds
  std::vector<int8_t> direction;   // per sample: +1 rising (split), -1 lowering (merged), 0 settled
  std::vector<float> factor;       // per sample: t now; 1 = true height
  std::vector<float> height;       // per sample: displayed world height
  std::vector<int32_t> active;     // diamonds moving or lowered but still drawn
  std::vector<uint8_t> in_active;  // per sample
  uint32_t ghost_triangles = 0;    // triangles drawn beyond ROAM's: merged diamonds still lowering
  uint32_t ghost_wanted = 0;       // the same before the room cut some short (what to reserve)
  std::vector<int32_t> scratch;    // removal candidates
};

struct TerrainMorphStats {
  uint32_t morphing = 0;         // vertices not at their true height or still moving
  uint32_t ghost_triangles = 0;  // extra triangles drawn this frame
  uint32_t cut_short = 0;        // lowering diamonds removed early to fit the room
};

// Everything settled at ROAM's coarsest mesh (call after roam_reset); sizes every array once.
void terrain_morph_reset(TerrainMorph& morph, const RoamTerrain& terrain, float duration);

// Morph factor of a motion: from + direction * (now - since) / duration, clamped to [0, 1].
float terrain_morph_factor(const TerrainMorph& morph, int32_t diamond, double now);

// After roam_update: takes state.events at time `now`, advances every motion, removes flat
// lowered diamonds (and, while the extra triangles pass `room`, the flattest removable ones),
// and computes the displayed heights, coarse to fine.
TerrainMorphStats terrain_morph_update(TerrainMorph& morph, const RoamState& state, const RoamTerrain& terrain,
                                       double now, uint64_t room);

}  // namespace lod
