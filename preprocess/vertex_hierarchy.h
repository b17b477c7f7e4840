// Vertex hierarchy builder for view-dependent LOD.
//
// Berkey and Song: a merge forest from repeated legal edge collapses, each pass collapsing
// an independent set (the region of influence of every collapse, both endpoints' one-rings,
// is marked until the pass ends) so the forest stays balanced, O(log n) deep. Edges are taken
// in quadric order (Garland & Heckbert 1997) or, as Berkey and Song do, shortest first. The legality test
// (link condition, Dey et al. 1999; no pinch of two borders through an interior edge; no
// fold-over; wings keep a proper fan) keeps every intermediate mesh a manifold, so a front of
// the forest with El-Sana & Varshney's dependencies is one too. Unlike Berkey and Song's own build, open
// meshes (border planes hold the outline) and several components work; a component is never
// collapsed below one triangle. Non-manifold vertices are kept as they are (never collapsed).
#pragma once
#include <cstddef>
#include <cstdint>

#include "preprocess/mesh.h"
#include "runtime/status.h"
#include "runtime/vertex_tree.h"

namespace lod {

enum class CollapseOrder : uint8_t {
  quadric,   // QEM cost, optimal placement (fallbacks: endpoints, midpoint)
  shortest,  // Berkey and Song: shortest edge first, parent at the midpoint
};

struct HierarchyOptions {
  CollapseOrder order = CollapseOrder::quadric;
  // Weight of border constraint planes relative to the surface's own planes (quadric order).
  float border_weight = 10;
  // A collapse is refused when a remaining face's normal would turn by more than this
  // (cosine of the angle; -1 refuses nothing but faces that would become degenerate).
  float min_normal_cos = 0.2f;
  // > 1: the faces are cut into this many spatial parts (median splits of face centres along
  // the longest axis) and the vertices the parts share are never collapsed. Then no collapse,
  // dependency or face crosses a part, so the parts' fronts can be updated on separate threads
  // (vertex_tree_regions); the price is the seam kept at full resolution.
  uint32_t parts = 1;
};

// Builds the hierarchy of `mesh` (positions, indices, submeshes, and the per-vertex attributes
// it has: uvs, uvs1, colors, normals). Faces with a repeated corner are dropped first; face ids
// in `out` count the faces kept, in input order. Attribute seams are pinned
// (VertexTree::seams_pinned: vertices sharing a position, so every copy made by a uv, uv1,
// colour or normal split; vertices between two materials' faces), and each node carries every
// attribute the mesh has (VertexTree::uvs, uvs1, colors, normals): leaves the input's (normals
// normalised where not unit), parents interpolated along the collapse (normals renormalised).
// Fails (out untouched) when an index is out of range, a position or attribute is not finite,
// an attribute has not its count per vertex (2, 2, 4, 3) or a submesh runs past the triangles;
// the message names mesh.source and the element.
Status build_vertex_hierarchy(VertexTree& out, const MeshData& mesh, const HierarchyOptions& options = {});

}  // namespace lod
