// Terrain mesh check: is a triangulation of a square grid of samples crack-free and
// T-junction-free? Judged from the triangles alone (no ROAM state), so it can back
// `lod run --validate` for any terrain LOD.
#pragma once
#include <cstdint>
#include <span>
#include <string>

namespace lod {

struct TerrainMeshCheck {
  size_t triangles = 0;
  size_t open_edges = 0;        // interior edges used once: a crack or a T-junction
  size_t overshared_edges = 0;  // edges used by more than two triangles, or twice the same way
  size_t flipped = 0;           // triangles not counter-clockwise in grid (x, y), or degenerate
  size_t bad_indices = 0;       // indices outside the grid
  bool covers_grid = false;     // the triangles' areas add up to exactly the grid's
  std::string first_problem;    // empty when ok(); names the edge or triangle
  bool ok() const {
    return open_edges == 0 && overshared_edges == 0 && flipped == 0 && bad_indices == 0 && covers_grid;
  }
};

// indices: 3 sample ids (y * size + x) per triangle. Every edge must be shared by exactly two
// triangles, once each way, except edges on the grid's outer border (used once); together with
// consistent orientation and exact total area this rules out cracks, T-junctions and overlaps.
TerrainMeshCheck check_terrain_mesh(std::span<const uint32_t> indices, uint32_t size);

}  // namespace lod
