// Aggressive simplifier for meshes with very many triangles: vertex clustering on a uniform
// grid (Rossignac & Borrel 1993) with each cell's vertex placed by its summed face quadrics
// (Lindstrom 2000, "Out-of-core simplification of large polygonal models"). The grid size is
// searched so the result lands on a target triangle count. A cell's vertices that face away
// from its first vertex form a second cluster, so parts thinner than a cell (tubes, sheets)
// keep both sides instead of vanishing with the faces between them. Topology may change
// (small parts vanish, holes close, nearby parts merge); every output face is non-degenerate
// and unique.
//
// Style follows meshoptimizer: output first, const inputs with counts, options last, return
// the count written; scratch memory is owned by the call.
#pragma once
#include <cstddef>
#include <cstdint>

#include "preprocess/qem_simplifier.h"

namespace lod {

struct ClusterOptions {
  // Accept a grid whose face count is within this fraction of the target.
  float tolerance = 0.04f;
  // Grid searches per call (each one pass over vertices and faces).
  int max_probes = 24;
  // Optional per-vertex attributes, averaged over each cell (as QemOptions).
  const float* attributes = nullptr;
  size_t attribute_count = 0;
};

struct ClusterResult {
  size_t triangles = 0;
  size_t vertices = 0;
  float cell_size = 0;  // object units; 0 when the input came back unchanged
  float error = 0;      // sqrt of the largest area-weighted mean squared plane distance of a cell
};

// Simplifies to about target_triangles faces. destination_indices needs room for index_count
// entries and destination_positions for 3 * vertex_count floats (fewer are used). Returns the
// number of triangles written; `result` (optional) gets the details.
size_t cluster_simplify(uint32_t* destination_indices, float* destination_positions, const float* positions,
                        size_t vertex_count, const uint32_t* indices, size_t index_count, size_t target_triangles,
                        const ClusterOptions& options, ClusterResult* result);

// One level per target (independent grids, shared set-up), in ChainLevelOut form; each level's
// error is the running maximum so a coarser level never reports less. Returns level_count.
size_t cluster_simplify_chain(ChainLevelOut* levels, const float* positions, size_t vertex_count,
                              const uint32_t* indices, size_t index_count, const size_t* target_triangles,
                              size_t level_count, const ClusterOptions& options);

}  // namespace lod
