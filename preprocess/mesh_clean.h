// Input cleaning before simplification: what scanned meshes really contain.
#pragma once
#include <cstddef>

#include "preprocess/mesh.h"

namespace lod {

struct CleanReport {
  size_t degenerate_faces = 0;      // repeated vertex index or zero area
  size_t duplicate_faces = 0;       // same vertex set as an earlier face
  size_t unreferenced_vertices = 0;
  size_t duplicate_vertices = 0;    // bit-identical positions (and uvs, colours) of one material welded together
  size_t material_split_vertices = 0;  // copies made where two materials shared a vertex (kept apart)
  // Welded vertices whose normal differed from the one kept by more than kNormalWeldDegrees
  // (hard edges: copies that differ in normal only); 0 when the mesh has no normals.
  size_t normal_conflicts = 0;
  bool changed() const {
    return degenerate_faces + duplicate_faces + unreferenced_vertices + duplicate_vertices > 0;
  }
};

// Cleans in place; deterministic; keeps the first occurrence of everything. With uvs, vertices
// weld only when position and uv match, so uv seams stay (likewise TEXCOORD_1 and colours:
// a colour seam stays two vertices); with several materials a vertex is
// first split per material and vertices weld only within one, so material boundaries stay seams; a welded vertex keeps its first
// normal (normal seams are not kept: level normals are recomputed from the geometry). Submeshes keep their surviving triangles.
CleanReport clean_mesh(MeshData& mesh);

inline constexpr double kNormalWeldDegrees = 1.0;

}  // namespace lod
