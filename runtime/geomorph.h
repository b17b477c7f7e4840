// Geomorphing (Hoppe 1996/1997): a change of detail blends vertex positions over time,
// v(t) = (1 - t) v_i + t v_f, instead of jumping, so no split, collapse or level change pops.
//
// View-dependent objects: VertexMorph keeps per hierarchy node where its displayed position
// started and ends and when. A split starts both children at the parent's displayed position;
// a deferred collapse (FrontParams::collapse_delay) first moves both children onto the parent,
// and the topological collapse happens when they have arrived, so the parent appears exactly
// where they are. Discrete levels: a level change blends the finer level's vertices between
// their own positions and their morph targets in the coarser level.
#pragma once
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "runtime/vertex_front.h"
#include "runtime/vertex_tree.h"

namespace lod {

// out[i] = (1 - t) * from[i] + t * to[i] for every float; t is clamped to [0, 1], and t = 0
// and t = 1 give `from` and `to` exactly. Sub-ranges give the same result.
void geomorph_lerp(std::span<float> out, std::span<const float> from, std::span<const float> to, float t);

// Morph factor after a change made at `start`: (now - start) / duration clamped to [0, 1];
// 1 when duration <= 0.
float morph_factor(double now, double start, float duration);

// One more per-node attribute travelling with the positions (empty when the tree has none of
// it): per node its `width` start values, then its `width` end values, side by side so that a
// node's morph is one cache line.
struct MorphColumn {
  std::vector<float> ends;
  uint32_t width = 0;
  bool empty() const { return ends.empty(); }
};

struct VertexMorph {
  std::vector<float> from;    // xyz per node
  std::vector<float> to;      // xyz per node
  // uv per node, when the tree has uvs (else empty): they travel with the positions, by the
  // same factor, so a split child's texture coordinate starts at its parent's shown one.
  std::vector<float> from_uv;
  std::vector<float> to_uv;
  // Likewise VertexTree::uvs1, colors and normals, when the tree has them (normals blend
  // linearly here; whoever publishes them renormalises).
  MorphColumn uv1, color, normal;
  std::vector<double> start;  // per node, seconds
  float duration = 0.25f;     // seconds
};

// Every node settled at its own position.
void vertex_morph_init(VertexMorph& morph, const VertexTree& tree, float duration);

// Applies one frame's front events at time `now` (call after front_update with the same time).
void vertex_morph_apply(VertexMorph& morph, const VertexTree& tree, std::span<const FrontEvent> events,
                        double now);

// Displayed position of one node at `now`.
void vertex_morph_position(const VertexMorph& morph, uint32_t node, double now, float out[3]);

// Writes displayed positions of `nodes` at `now` into out (xyz per node id, out sized for
// every node, so the front's triangles index it directly). Returns the number of nodes still
// moving. Sub-ranges of `nodes` give the same result.
size_t vertex_morph_positions(std::span<float> out, const VertexMorph& morph, std::span<const uint32_t> nodes,
                              double now);

// Displayed uvs of `nodes` at `now` into out (uv per node id, sized for every node), by the
// factor their positions use. The tree must have uvs. Sub-ranges give the same result.
void vertex_morph_uvs(std::span<float> out, const VertexMorph& morph, std::span<const uint32_t> nodes, double now);
// The same for one of morph's columns (uv1, color, normal; must not be empty): column.width
// floats per node id.
void vertex_morph_column(std::span<float> out, const VertexMorph& morph, const MorphColumn& column,
                         std::span<const uint32_t> nodes, double now);

// Displayed values of several columns for `nodes` at `now`, written compactly in the order of
// `nodes` (out holds column->width floats per node): what a frame publishes, without a per-node
// copy to compact afterwards. The factor is computed once per node. Sub-ranges give the same
// result.
struct MorphOutput {
  const MorphColumn* column = nullptr;
  std::span<float> out;
};
void vertex_morph_compact(std::span<const MorphOutput> outputs, const VertexMorph& morph,
                          std::span<const uint32_t> nodes, double now);

// ---- discrete levels --------------------------------------------------------------------------

// Morph targets of a finer level in a coarser one: for each fine vertex the coarse vertex it
// merged into, from the simplifier's vertex mapping (the input vertex each output vertex
// descends from). A fine vertex whose source survives in the coarse level maps to that vertex;
// otherwise to the coarse vertex nearest to it. Writes target[fine] (coarse index).
void level_morph_targets(std::span<uint32_t> target, std::span<const float> fine_positions,
                         std::span<const uint32_t> fine_source, std::span<const float> coarse_positions,
                         std::span<const uint32_t> coarse_source);

// level_morph_targets, then made to follow the collapses: a fine vertex whose source did not
// survive merged (through a chain of edge collapses) into a coarse vertex one of its fine
// neighbours also reaches, so among its own target and its neighbours' targets it takes the one
// under which most of its fine triangles land on a coarse triangle or collapse to a line or
// point (ties: the nearest), repeated while that changes anything; then two free corners of a
// triangle still missing try every pair of their candidates together. Where every fine triangle does,
// the finer mesh morphed to t = 1 is the coarser mesh plus degenerate triangles. Returns the
// number of fine triangles that still land on no coarse triangle (0 for clean edge-collapse
// chains; clustering levels may leave some). Indices are level-local, 3 per triangle.
size_t level_morph_targets_by_collapse(std::span<uint32_t> target, std::span<const float> fine_positions,
                                       std::span<const uint32_t> fine_indices,
                                       std::span<const uint32_t> fine_source,
                                       std::span<const float> coarse_positions,
                                       std::span<const uint32_t> coarse_indices,
                                       std::span<const uint32_t> coarse_source);

// Fine triangles that land on neither a coarse triangle (as a vertex set) nor a line or point
// once every vertex moves to its target.
size_t level_morph_misses(std::span<const uint32_t> target, std::span<const uint32_t> fine_indices,
                          std::span<const uint32_t> coarse_indices);

// Positions of the finer level blended towards its targets: out = (1 - t) fine + t coarse[target].
// t = 0 draws the finer level, t = 1 puts every vertex on the coarser level's surface.
void level_morph_positions(std::span<float> out, std::span<const float> fine_positions,
                           std::span<const float> coarse_positions, std::span<const uint32_t> target,
                           float t);

// Any per-vertex attribute of the finer level blended the same way, `components` floats per
// vertex (2 for uvs, 3 for normals): out = (1 - t) fine + t coarse[target], exact at t = 0 and
// 1, so the texture moves with the surface instead of sliding under it.
void level_morph_attributes(std::span<float> out, std::span<const float> fine, std::span<const float> coarse,
                            std::span<const uint32_t> target, size_t components, float t);

// Per object: advance the morph factor towards 1 by dt / duration, restarting it at 0 where the
// level changed since last frame. Returns the number of objects still morphing.
size_t advance_level_morph(std::span<float> morph, std::span<const uint8_t> level,
                           std::span<const uint8_t> prev_level, float dt, float duration);

}  // namespace lod
