// Model HLOD (R1 3.1, Zhou & Tian): an octree over one mesh, built bottom-up into layers.
//
//   subdivide:  a cubic cell holding more than min_verts vertices splits into octants; a
//               triangle whose vertices fall in different octants joins the cell's boundary
//               patch (kept at full detail, so no gap opens between the children).
//   leaf:       layer 0 is its original geometry; layers 1 and 2 halve it twice (QEM).
//   inner node: layer 0 is its children's coarsest layers welded to its patch; then halved
//               twice like a leaf.
//   locks:      in every node, the vertices of every ancestor's patch (and the mesh's own
//               border) never move, so any mix of child layers meets the patches exactly.
//   errors:     each layer is measured against the original surface (Embree closest points,
//               both directions) and made monotonic: never below the layer before it, and an
//               inner node never below any child's coarsest layer.
//
// Nothing here owns threads: independent subtrees run through options.parallel_for, and the
// result is byte-identical whatever it does (in parallel, serially, or absent).
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "preprocess/mesh.h"
#include "preprocess/qem_simplifier.h"  // ParallelFor
#include "runtime/hlod_tree.h"
#include "runtime/status.h"

namespace lod {

// fraction in [0, 1] of the original triangles whose node is finished. Called from whichever
// thread finished a node, possibly from several at once: the callee serialises.
using HlodBuildProgress = std::function<void(float fraction)>;

struct HlodBuildOptions {
  uint32_t min_verts = 1000;  // a cell with more vertices splits (R1 Table I: 500-1000)
  // A layer stops above its half rather than make a collapse whose QEM error exceeds this
  // fraction of the node's cell edge: errors then grow with cell size, as the octree's
  // selection expects. 0 = always halve.
  float max_error_per_cell = 0.01f;
  // Error measurement, per layer. The layer side: every vertex plus the centroids of this
  // fraction of its triangles (evenly spread), against the whole original. The original side:
  // the node's own original vertices (its region of the mesh: its leaves and the patches
  // below it), evenly thinned to at most reference_samples, against the layer.
  float layer_samples_per_triangle = 0.25f;
  uint32_t reference_samples = 1024;
  ParallelFor parallel_for;     // optional; independent subtrees and children in parallel
  HlodBuildProgress progress;   // optional
};

// A built HLOD: the tree (breadth-first, nodes[0] the root) and each node's geometry, by
// node index. Payload offsets in the tree are 0 until the model is written to a file.
struct HlodModel {
  HlodTree tree;
  std::vector<HlodPayload> payloads;
};

struct HlodBuildReport {
  size_t nodes = 0;
  size_t leaves = 0;
  uint32_t depth = 0;                // deepest node
  size_t boundary_triangles = 0;     // over all patches
  size_t dropped_triangles = 0;      // degenerate on entry (repeated vertex)
  size_t oversized_leaves = 0;       // leaves above min_verts (kHlodMaxDepth reached)
  size_t short_layers = 0;           // layers dropped: no fewer triangles than the one before
};

// Builds the HLOD of `mesh` (cleaned: see clean_mesh). Fails on an empty mesh, indices out of
// range, non-finite coordinates, or a mesh with more than 2^32 - 1 vertices; `out` is only
// written on success. tree.name and tree.source_hash are left for the caller.
Status build_hlod(HlodModel& out, const MeshData& mesh, const HlodBuildOptions& options,
                  HlodBuildReport* report = nullptr);

}  // namespace lod
