// The terrain's frame mesh checked from its arrays alone.
#include "cli/terrain_check.h"

#include "runtime/terrain_mesh_check.h"

namespace lod::cli {
namespace {

bool fail(std::string* why, std::string text) {
  *why = "terrain: " + std::move(text);
  return false;
}

}  // namespace

bool TerrainCheck::check(const Frame& f, std::string* why) {
  if (f.terrain_grid == 0)
    return f.terrain_tris == 0 && f.terrain_indices.empty() ? true : fail(why, "triangles without a grid");
  const size_t vertices = f.terrain_samples.size();
  if (f.terrain_positions.size() != 3 * vertices) return fail(why, "positions and samples differ in count");
  if (f.terrain_indices.size() != 3 * f.terrain_tris) return fail(why, "terrain_tris does not match the indices");
  if (f.terrain_share > 0 && f.terrain_tris > f.terrain_share)
    return fail(why, std::to_string(f.terrain_tris) + " triangles over the share of " + std::to_string(f.terrain_share));
  const uint64_t samples = uint64_t(f.terrain_grid) * f.terrain_grid;
  grid_indices_.resize(f.terrain_indices.size());
  for (size_t i = 0; i < f.terrain_indices.size(); ++i) {
    const uint32_t local = f.terrain_indices[i];
    if (local >= vertices || f.terrain_samples[local] >= samples)
      return fail(why, "index " + std::to_string(i) + " outside the vertices or the grid");
    grid_indices_[i] = f.terrain_samples[local];
  }
  // One vertex per sample: a geomorphing vertex has one displayed height for every triangle
  // using it, so the topological check below is also a geometric one.
  seen_.assign(samples, 0);
  for (uint32_t s : f.terrain_samples)
    if (s >= samples || seen_[s]++) return fail(why, "sample " + std::to_string(s) + " drawn as two vertices");
  const TerrainMeshCheck c = check_terrain_mesh(grid_indices_, f.terrain_grid);
  if (!c.ok())
    return fail(why, std::to_string(c.open_edges) + " open edges (cracks or T-junctions), " +
                         std::to_string(c.overshared_edges) + " overshared, " + std::to_string(c.flipped) +
                         " flipped" + (c.covers_grid ? "" : ", grid not covered") + ": " + c.first_problem);
  return true;
}

}  // namespace lod::cli
