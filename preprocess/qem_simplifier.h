// QEM edge-collapse simplifier on flat arrays: one run produces a whole LOD chain.
//
// Garland & Heckbert 1997, "Surface simplification using quadric error metrics": area-weighted
// plane quadrics, boundary constraint planes, optimal placement from the 3x3 system. The pass
// structure (pick every edge's cost, sort once, collapse greedily with both endpoints locked
// for the rest of the pass) follows meshoptimizer's simplifier; the link condition is
// Dey et al. 1999 / Hoppe 1993's legality test.
//
// Style follows meshoptimizer: output first, const inputs with counts, options last, return
// the count written. Scratch memory is allocated once per call; no allocation per collapse.
// Nothing here owns threads: the split/part/merge functions let jobs/ run both halves of one
// big mesh in parallel, and the result does not depend on how (or whether) they ran in parallel.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace lod {

struct QemOptions {
  // Border vertices never move. Otherwise they may only slide along their border edge, held
  // by boundary constraint planes, so open meshes keep their outline either way.
  bool lock_border = false;
  // Stop (level not reached) when the next collapse would exceed this object-space error
  // (square root of the area-weighted mean squared plane distance); 0 = no limit.
  float max_error = 0;
  // Weight of the boundary constraint planes relative to the surface's own planes.
  float border_weight = 10;
  // Weight of the constraint planes along attribute seams (open edges whose twin is another
  // copy's edge), which hold a seam to its line as it is simplified along its length; the
  // surface on both sides is kept by its own planes.
  float seam_weight = 10;
  // Non-manifold vertices (on edges with three or more faces, or with faces of both
  // orientations) move like manifold ones (as in meshoptimizer), also at the open end of a fin;
  // those on exactly one border loop slide along it. Dirty scans (Stanford's decimated ones)
  // otherwise stop far above their targets. Faces such collapses double are dropped. false
  // locks those vertices instead.
  bool move_nonmanifold = true;
  // Optional: nonzero = that input vertex never moves (others may collapse onto it).
  const uint8_t* vertex_lock = nullptr;
  // Optional per-vertex attributes (normals, uv, ...): attribute_count floats per vertex,
  // interpolated along each collapse. Vertices sharing a position with another vertex (uv,
  // normal or material seams: one position, a copy per side) move only along their seam, both
  // copies together, each keeping its own side's attributes (as meshoptimizer's seam
  // collapses), so the seam stays closed and no texture smears across it; where a seam
  // branches, ends or meets a border (three or more copies, or copies whose open edges are
  // not each other's twins) the copies stay put.
  const float* attributes = nullptr;
  size_t attribute_count = 0;
  // Weight of the attribute error in the collapse cost (Hoppe 1999's memory-efficient
  // attribute quadrics, as meshoptimizer's simplifyWithAttributes weights them): per face, the
  // first kAttributeQuadricChannels attributes' linear gradient over the face; a collapse
  // costs its plane error plus weight^2 x the area-weighted squared difference between each
  // face's interpolated attribute and the one the merged vertex carries. Positions are still
  // placed by the plane quadric alone; 0 = attributes do not enter the cost.
  float attribute_weight = 0;
};

// At most this many attributes (the first ones) enter the cost: two uv sets and an RGBA colour.
inline constexpr size_t kAttributeQuadricChannels = 8;

// One simplified level. Its vertices are new (collapses move them to optimal positions);
// source_vertex says which input vertex each descends from.
struct ChainLevelOut {
  size_t target_triangles = 0;
  std::vector<float> positions;         // xyz per vertex, object space
  std::vector<float> attributes;        // attribute_count per vertex, when attributes were given
  std::vector<uint32_t> indices;        // into positions, 3 per triangle
  std::vector<uint32_t> source_vertex;  // input vertex index per output vertex
  // Accumulated error: sqrt of the largest collapse error made so far (object units). A coarser
  // level never reports less than a finer one of the same run.
  float error = 0;
  // false: stopped above target (topology, locked vertices or max_error left nothing legal).
  bool reached = false;

  size_t triangle_count() const { return indices.size() / 3; }
};

// Simplifies to each target_triangles[i] in turn (they must not increase) and snapshots each.
// Returns the number of levels written to `levels` (level_count unless the input is empty).
// Triangles with repeated vertices or out-of-range indices are dropped on entry.
size_t qem_simplify_chain(ChainLevelOut* levels, const float* positions, size_t vertex_count,
                          const uint32_t* indices, size_t index_count, const size_t* target_triangles,
                          size_t level_count, const QemOptions& options);

// ---- both cores on one mesh: split, simplify the parts, merge, continue ----------------------

struct Quadric {
  double a00 = 0, a11 = 0, a22 = 0, a01 = 0, a02 = 0, a12 = 0;  // symmetric A
  double b0 = 0, b1 = 0, b2 = 0, c = 0;                         // error(p) = pAp + 2bp + c
  double w = 0;                                                 // summed area weight
};

// The attribute part of a vertex's error (Hoppe 1999): sum over its faces of w (g.p + d - s)^2
// per channel, s the vertex's attribute, with the p-only terms in a..c; w = weight^2 x face
// area, summed in w. The cross terms (channel k: gradient sum g[k][3], offset sum d[k]) live in
// QemMesh::attribute_gradients, kGradientWords per weighted channel, so a mesh that weights only
// its uvs pays for two channels and one with colours and a second uv set for eight.
struct AttributeQuadric {
  double a00 = 0, a11 = 0, a22 = 0, a01 = 0, a02 = 0, a12 = 0;
  double b0 = 0, b1 = 0, b2 = 0, c = 0;
  double w = 0;
};
inline constexpr size_t kGradientWords = 4;  // g[3], d of one channel

// A mesh being simplified, with its quadrics. Positions are divided by a power-of-two scale of
// the whole input (object = normalised * scale, exactly), so parts of one input share a frame.
struct QemMesh {
  std::vector<float> positions;
  std::vector<float> attributes;
  std::vector<Quadric> quadrics;
  std::vector<AttributeQuadric> attribute_quadrics;  // per vertex, or empty (no weighted attributes)
  std::vector<double> attribute_gradients;  // kGradientWords x attribute_channels per vertex, with them
  size_t attribute_channels = 0;            // weighted channels: min(attribute_count, kAttributeQuadricChannels)
  std::vector<uint32_t> indices;
  std::vector<uint32_t> source_vertex;  // input vertex id
  std::vector<uint8_t> lock;            // kLockUser | kLockSeam | kCopy bits per vertex
  size_t attribute_count = 0;
  size_t input_vertex_count = 0;
  float scale = 1;
  double error = 0;  // largest normalised collapse error so far
  bool border_planes = false;  // boundary constraint planes added (by the first simplification)

  static constexpr uint8_t kLockUser = 1;  // options.vertex_lock; seam branch points (3+ copies)
  static constexpr uint8_t kLockSeam = 2;  // shared between parts of a split; cleared by merge
  // One of several input vertices at one position (an attribute seam). With exactly two it
  // moves only along the seam with its copy, and stays put in a mesh (a part of a split) that
  // holds only one of them; with three or more (the seam branches) it has kLockUser too.
  static constexpr uint8_t kCopy = 4;
  static constexpr uint8_t kLockMask = kLockUser | kLockSeam;
  size_t triangle_count() const { return indices.size() / 3; }
};

// Builds the working mesh (face and point quadrics of the whole input; boundary planes are
// added by the first qem_simplify_mesh, which classifies the vertices anyway).
void qem_prepare(QemMesh& out, const float* positions, size_t vertex_count, const uint32_t* indices,
                 size_t index_count, const QemOptions& options);

// Splits `whole` into two halves at the median triangle centroid along its longest axis.
// Vertices used by both halves are locked (kLockSeam) in both. Returns the number of parts
// written (2, or 1 when the mesh is too small to be worth splitting).
size_t qem_split(QemMesh* parts, const QemMesh& whole);

// Simplifies `mesh` in place to each target in turn, snapshotting each level (as
// qem_simplify_chain). `levels[i].error` continues from mesh.error.
size_t qem_simplify_mesh(ChainLevelOut* levels, QemMesh& mesh, const size_t* target_triangles,
                         size_t level_count, const QemOptions& options);

// Joins parts made by qem_split (after any simplification) back into one mesh; shared
// vertices are welded by source_vertex and unlocked again. Simplify every part at least once
// before merging, so that each has its boundary planes (the merged mesh gets none of its own).
void qem_merge(QemMesh& out, const QemMesh* parts, size_t part_count);

// Joins the same level of several parts into one (shared vertices welded by source_vertex).
void chain_level_merge(ChainLevelOut& out, const ChainLevelOut* parts, size_t part_count);

// Runs body(0..count-1), in parallel or not; supplied by jobs/ (tbb) or a test.
using ParallelFor = std::function<void(size_t count, const std::function<void(size_t)>& body)>;

// qem_simplify_chain on both halves of the mesh at once: the fine levels are simplified per
// half with the shared border locked (while the border is small next to the target), then the
// halves are merged and the remaining levels continue on the whole mesh. Byte-identical
// output whatever parallel_for does.
size_t qem_simplify_chain_split(ChainLevelOut* levels, const float* positions, size_t vertex_count,
                                const uint32_t* indices, size_t index_count,
                                const size_t* target_triangles, size_t level_count,
                                const QemOptions& options, const ParallelFor& parallel_for);

}  // namespace lod
