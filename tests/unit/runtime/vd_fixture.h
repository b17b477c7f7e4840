// A hand-built vertex hierarchy: the unit square as two triangles, border edge 0-1 collapsed
// into node 4 at (0.5, 0, 0).
//
//   3 ---- 2        face 0 = (0, 1, 2)  made by node 4's split, wing 2
//   |  f1 /|        face 1 = (0, 2, 3)  base face, (4, 2, 3) at the base
//   |   /  |
//   |  / f0|        node 4: children 0, 1; dependencies 2, 3; incident faces {1}
//   0 ---- 1
#pragma once
#include "runtime/vertex_tree.h"

namespace lod::test {

inline VertexTree square_tree() {
  VertexTree t;
  t.leaf_count = 4;
  t.face_count = 2;
  t.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5f, 0, 0};
  t.parent = {4, 4, kNoNode, kNoNode, kNoNode};
  t.radius = {0, 0, 0, 0, 0.5f};
  t.cone_axis = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  t.cone_cos = {1, 1, 1, 1, 1};
  t.error = {0, 0, 0, 0, 0.1f};
  // Depth-first leaf order: roots 2, 3, then 4 = {0, 1}.
  t.leaf_lo = {2, 3, 0, 1, 2};
  t.leaf_hi = {3, 4, 1, 2, 4};
  t.leaf_rank = {2, 3, 0, 1};
  t.face_leaves = {0, 1, 2, 0, 2, 3};
  t.face_owner = {4, kNoNode};
  t.children = {0, 1};
  t.split_faces = {0, kNoNode};
  t.wings = {2, kNoNode};
  t.dep_offsets = {0, 2};
  t.deps = {2, 3};
  t.inc_offsets = {0, 1};
  t.inc_faces = {1};
  pack_vertex_bounds(t);
  return t;
}

}  // namespace lod::test
