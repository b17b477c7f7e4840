// VertexTree: a vertex hierarchy (Berkey and Song's merge forest, Hoppe 1997's vertex hierarchy) for
// view-dependent LOD, as flat arrays shared by every instance of a model.
//
// Nodes 0..leaf_count-1 are the input vertices (leaves); nodes from leaf_count on are parents
// made by edge collapses, numbered in an order the build could have collapsed them in (pass by
// pass; within a pass, whose collapses are independent, along a Morton curve so that nodes
// near in space are near in memory). So a parent, and every node depending on another, has
// the larger id. Roots (parent == kNoNode) are the base mesh's vertices.
// Faces are the input triangles; a face is created by the split of its `owner` node (or is a
// base face) and its corners at any front are the active ancestors of its three leaf corners.
//
// Per interior node (index i = node - leaf_count): two children, the one or two faces its split
// creates with their wing vertices (Berkey and Song's tv1/tv2), the dependency set (its neighbours when it
// was made by the collapse; Berkey and Song; El-Sana & Varshney 1999) and the faces incident to it right
// after the collapse (a superset of its faces at any front on which it is active). Per node:
// position, a bounding-sphere radius covering its children's, a normal cone and an error.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "runtime/huge_page_allocator.h"

namespace lod {

inline constexpr uint32_t kNoNode = 0xffffffffu;

// What the front's per-node test reads, packed in one 32-byte record (one cache line fetch
// instead of five): derived from the arrays by pack_vertex_bounds, never stored.
struct VertexBounds {
  float x, y, z, radius;
  float error;
  int16_t axis[3];   // cone axis * 32767
  int16_t cone_cos;  // * 32767, rounded down (a wider cone: never wrongly back-facing)
  uint32_t parent;
};
static_assert(sizeof(VertexBounds) == 32);

struct VertexTree {
  uint32_t leaf_count = 0;
  uint32_t face_count = 0;

  // Per node (leaf_count + interior count).
  std::vector<float> positions;   // xyz; leaves are the input positions bit for bit
  std::vector<uint32_t> parent;   // kNoNode for roots
  std::vector<float> radius;      // sphere at the node's position bounding all leaves below
  std::vector<float> cone_axis;   // xyz unit normal-cone axis (zero when unknown)
  std::vector<float> cone_cos;    // cos of the cone half-angle; <= 0: never back-facing
  std::vector<float> error;       // object-space error, never less than a child's
  std::vector<uint32_t> leaf_lo;  // leaves below are leaf_order[leaf_lo, leaf_hi)
  std::vector<uint32_t> leaf_hi;

  // Optional texture coordinates (empty = none): uv per node, leaves the input's bit for bit, a
  // parent's interpolated along its collapse (edge_parameter) and so inside its children's
  // range. Stored in the asset's optional VHAT section.
  std::vector<float> uvs;
  // Optional, likewise per node (empty = none): the second uv set (glTF TEXCOORD_1, 2 each) and
  // vertex colours (glTF COLOR_0, linear RGBA, 4 each), leaves the input's bit for bit, a
  // parent's interpolated along its collapse and clamped to its children's range as uvs are;
  // and authored normals (3 each): leaves the input's (bit for bit when unit or zero; others
  // normalised), a parent's the normalised interpolation of its children's (their cone axis,
  // else a non-zero child's, when that cancels out); every one unit or zero. Stored in VHAT
  // (layout 2).
  std::vector<float> uvs1;
  std::vector<float> colors;
  std::vector<float> normals;
  // Built with attribute seams pinned: every vertex that shares its position with another (one
  // copy per side of a uv, normal or material seam) and every vertex between faces of two
  // materials is a root, never collapsed, so no collapse smears a texture across a seam or
  // moves a material boundary, and the copies stay together (no crack). Builds from before
  // this rule collapsed each side alone; the bake rebuilds such a tree (VHAT section flag).
  bool seams_pinned = false;

  // Per leaf: its rank in the depth-first leaf order.
  std::vector<uint32_t> leaf_rank;

  // Per face.
  std::vector<uint32_t> face_leaves;  // 3 leaf ids per face, input orientation
  std::vector<uint32_t> face_owner;   // node whose split creates it, kNoNode for base faces

  // Per interior node i.
  std::vector<uint32_t> children;     // 2 per interior node
  std::vector<uint32_t> split_faces;  // 2 per interior node, kNoNode when on a border
  std::vector<uint32_t> wings;        // 2 per interior node: third corner of each split face
  std::vector<uint32_t> dep_offsets;  // interior count + 1
  std::vector<uint32_t> deps;         // neighbours at collapse time (node ids)
  std::vector<uint32_t> inc_offsets;  // interior count + 1
  std::vector<uint32_t> inc_faces;    // faces incident right after the collapse

  // Derived (pack_vertex_bounds): per node, what refinement tests read; per face corner, the
  // leaf's depth-first rank (so a split finds a corner's child without a leaf lookup).
  std::vector<VertexBounds, HugePageAllocator<VertexBounds>> bounds;
  std::vector<uint32_t> face_ranks;
  // Per incidence entry (inc_faces[k]): the leaf rank of the face's corner below its node,
  // times 4, plus that corner's index (0..2): a split or collapse touches only that corner.
  std::vector<uint32_t> inc_corner;

  uint32_t node_count() const { return static_cast<uint32_t>(parent.size()); }
  uint32_t interior_count() const { return node_count() - leaf_count; }
  bool is_leaf(uint32_t node) const { return node < leaf_count; }
  // True when `leaf` lies below (or is) `node`.
  bool covers(uint32_t node, uint32_t leaf) const {
    const uint32_t r = leaf_rank[leaf];
    return r >= leaf_lo[node] && r < leaf_hi[node];
  }
  bool empty() const { return parent.empty(); }
};

// Largest magnitude of a node position, radius or error a tree may hold (the front sums and
// squares them in float and double and must stay finite).
inline constexpr float kMaxTreeMagnitude = 1e18f;

// Checks sizes, id ranges, parent/child agreement, ids increasing towards the roots, leaf
// intervals (ranks a permutation), split faces owned by their node, finite values within
// kMaxTreeMagnitude, and replays the collapses in node order: split faces, wings, incident
// faces and dependencies must be exactly what each collapse makes (what front_update and its
// forced splits rely on). With uvs: two per node, finite, each parent's within the box of its
// children's; the other attributes as validate_vertex_tree_attributes says. Linear in the
// arrays. On failure `message` names the element ("node 812 child 90211 of 35947"); callers
// prefix the file.
bool validate_vertex_tree(const VertexTree& tree, std::string* message);
// The uv part of it alone, for a tree whose other arrays passed (asset readers name the two
// sections apart).
bool validate_vertex_tree_uvs(const VertexTree& tree, std::string* message);
// Every optional per-node attribute the tree has (uvs, uvs1, colors, normals), for a tree whose
// other arrays passed: uvs1 and colours like uvs (2 and 4 per node, finite, a parent's inside
// its children's box), normals 3 per node, finite, each of length 1 (within
// kTreeNormalTolerance) or exactly 0. validate_vertex_tree checks them too.
bool validate_vertex_tree_attributes(const VertexTree& tree, std::string* message);
inline constexpr float kTreeNormalTolerance = 1e-3f;

// Fills tree.bounds from the per-node arrays. Builders and readers call it; fronts need it.
void pack_vertex_bounds(VertexTree& tree);

// Leaves that are roots never split or merge; they sit in every region.
inline constexpr uint8_t kSharedRegion = 0xff;

// Cuts the tree into at most max_regions (1..254) regions whose fronts never touch each
// other's nodes or faces: nodes linked by a parent, a dependency or a face (through their
// leaves) share a region; fixed leaves (roots) are kSharedRegion. Components are dealt to the
// least loaded region by leaf count, largest first, so the cut is deterministic. A hierarchy
// built with HierarchyOptions::parts > 1 has at least that many components; any other has
// one per mesh component. Writes region per node; returns the number of regions used (>= 1).
// Allocates: call once per tree, not per frame.
uint32_t vertex_tree_regions(std::vector<uint8_t>& region, const VertexTree& tree, uint32_t max_regions);

// Region of a face: that of its first corner leaf outside kSharedRegion; 0 when all are fixed.
uint8_t face_region(const VertexTree& tree, std::span<const uint8_t> region, uint32_t face);

// Region-local ids for the fronts of a tree's regions, so that each keeps per-node and per-face
// state for its own region only, not for the whole tree (8 regions of the 1.1M-triangle mesh held
// about 0.7 GB). In every region the fixed leaves come first (the same ids everywhere), then the
// region's leaves, then its interior nodes, each in tree order: so leaves still precede their
// parents, and a node's local interior index is local - leaves[region]. Faces are numbered
// within their face_region. Built once per tree, shared by its fronts.
struct RegionNumbering {
  std::vector<uint8_t> region;       // per node, as vertex_tree_regions wrote it
  std::vector<uint32_t> local;       // per node
  std::vector<uint32_t> local_face;  // per face
  uint32_t shared = 0;               // fixed leaves: ids [0, shared) in every region
  // Per region: leaves (fixed ones included), nodes (the same) and faces.
  std::vector<uint32_t> leaves, nodes, faces;
};
// `region` and `count` as vertex_tree_regions returned them; the result keeps `region`.
RegionNumbering number_regions(const VertexTree& tree, std::vector<uint8_t> region, uint32_t count);

}  // namespace lod
