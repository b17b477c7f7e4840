// Per-vertex tangents for normal mapping, as glTF's TANGENT attribute holds them: the
// per-triangle accumulation of Lengyel ("Computing Tangent Space Basis Vectors for an
// Arbitrary Mesh", 2001): each triangle adds its dP/du and dP/dv to its corners, then each
// vertex's sum is Gram-Schmidt orthogonalised against its normal and normalised; w (+1 or -1)
// is the handedness, so that bitangent = cross(normal, tangent) * w points up the image (glTF:
// +Y of a normal texture is up, uv origin top left). Not MikkTSpace: equal on smooth,
// non-mirrored charts, unlike it where a vertex is shared by triangles of opposite winding in uv.
#pragma once
#include <cstddef>
#include <cstdint>

namespace lod {

// out: 4 floats per vertex, each xyz unit length and perpendicular to the (normalised) normal,
// w = +1 or -1. A vertex no triangle gives a usable direction (zero-area uv triangles only) gets
// a unit vector perpendicular to its normal; a zero or non-finite normal is taken as +z.
void compute_tangents(float* out, const float* positions, const float* normals, const float* uvs,
                      size_t vertex_count, const uint32_t* indices, size_t index_count);

}  // namespace lod
