// Smooth vertex normals of an indexed triangle mesh: each vertex's normal is the normalised sum
// of its faces' (unnormalised) cross products, so larger faces weigh more. The view-dependent
// mesh is shaded with them (jobs/frame_graph's vd_mesh stage): they are computed from the shown,
// geomorphed front, so they morph with the positions, and a hard edge stays hard because its
// vertices are separate copies per side (the hierarchy pins them; runtime/vertex_tree.h).
#pragma once
#include <cstdint>
#include <span>

namespace lod {

// normals: xyz per vertex (sized like positions), overwritten. indices: 3 per triangle, each
// below positions.size() / 3. A vertex whose faces are all degenerate (or that no face uses)
// gets (0, 0, 0), which renderers take as "use the face normal". Returns the number of vertices
// given a unit normal. Not sub-range safe over triangles (sums); one call per mesh.
uint32_t area_weighted_normals(std::span<float> normals, std::span<const float> positions,
                               std::span<const uint32_t> indices);

// Normalises every xyz triple of `normals` in place (geomorphed authored normals: a linear blend
// of two unit normals is shorter); a zero or non-finite one becomes (0, 0, 0). Returns the
// number made unit. Sub-ranges give the same result.
uint32_t renormalise(std::span<float> normals);

}  // namespace lod
