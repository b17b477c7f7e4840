// Model HLOD (precomputed HLOD, Zhou and Tian 3.1): an octree over one mesh, built bottom-up into layers.
//
//   subdivide:  a cubic cell holding more than min_verts vertices splits into octants; a
//               triangle whose vertices fall in different octants joins the cell's boundary
//               patch (kept at full detail, so no gap opens between the children).
//   leaf:       layer 0 is its original geometry; layers 1 and 2 halve it twice (QEM).
//   inner node: layer 0 is its children's coarsest layers welded to its patch; then halved
//               twice like a leaf.
//   locks:      in every node, the vertices of every ancestor's patch (and the mesh's own
//               border) never move, so any mix of child layers meets the patches exactly.
//   attributes: texture coordinates (TEXCOORD_0 and _1) and vertex colours (COLOR_0) ride
//               through QEM as attributes, weighted in its collapse cost (seams kept: copies at
//               one position move only along their seam) and material boundaries are seams, so each
//               layer's triangle keeps the material of the original vertex it descends from;
//               every layer and patch is grouped into material runs (preprocess/material_runs.h).
//   errors:     each layer is measured against the original surface (Embree closest points,
//               both directions) and made monotonic: never below the layer before it, and an
//               inner node never below any child's coarsest layer.
//
// Nothing here owns threads: independent subtrees run through options.parallel_for, and the
// result is byte-identical whatever it does (in parallel, serially, or absent).
//
// Split: every build is the same three steps, so that a distributed build is the
// local one by construction: (a) plan: the top of the octree split down to a frontier of
// subtrees, (b) bake_subtrees: each subtree on its own (whoever bakes it), (c) assemble: the
// levels above, built from the subtrees' roots, and the breadth-first splice. Each node's
// computation never depends on where the frontier is, so neither does the output.
//
// Frontier rule: starting from the root, the frontier's heaviest node (most original
// triangles; ties: first in breadth-first order) is split by the octree's own rule while it
// holds more than total / subtrees triangles (a node the rule keeps as a leaf stays, whatever
// its size). A subtree's cost is estimated by its triangle count.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "preprocess/mesh.h"
#include "preprocess/qem_simplifier.h"  // ParallelFor
#include "runtime/chain_material.h"
#include "runtime/embedded_image.h"
#include "runtime/hlod_subtree.h"
#include "runtime/hlod_tree.h"
#include "runtime/status.h"

namespace lod {

// fraction in [0, 1] of the original triangles whose node is finished. Called from whichever
// thread finished a node, possibly from several at once: the callee serialises.
using HlodBuildProgress = std::function<void(float fraction)>;

// A model's materials as its tree stores them (jobs convert a mesh's with add_chain_materials):
// texture URIs relative to texture_base, the source's folder, as a .lod's.
struct HlodSurfaces {
  std::vector<ChainMaterial> materials;
  std::string texture_base;
  std::vector<EmbeddedImage> images;  // what the materials' "embedded:<k>" slots name
};

struct HlodBuildOptions {
  uint32_t min_verts = 1000;  // a cell with more vertices splits (Zhou and Tian, Table I: 500-1000)
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
  // About how many subtrees the top is split into (see the frontier rule). The output is the
  // same for any value; it only decides the units a distributed build hands out.
  uint32_t subtrees = 16;
  // A distributed build's rank count: where the frontier's depth-first order is cut into this
  // many equal shares, the subtree a cut falls in is split further (see refine_at_cuts), so
  // that a few subtrees per rank split evenly. Like `subtrees`, it never changes the output.
  uint32_t balance_parts = 1;
  // Unequal shares instead (a rank that loads the mesh for its node bakes less): the cuts as
  // fractions of the cost, ascending in (0, 1), balance_parts - 1 of them. Empty: equal shares.
  std::vector<double> balance_cuts;
  // The materials the mesh's submeshes name, copied into the tree. A submesh id at or past their
  // count is drawn with the default material. None: one surface, no runs.
  HlodSurfaces surfaces;
  // Weight of the attribute error (uvs, uv1, colours) in QEM's collapse cost for a mesh with
  // them (BakeSettings::uv_weight, which the .lod bake applies to the same attributes).
  float uv_weight = 0.2f;
  ParallelFor parallel_for;     // optional; independent subtrees and children in parallel
  HlodBuildProgress progress;   // optional
};

// A built HLOD: the tree (breadth-first, nodes[0] the root) and each node's geometry, by
// node index. Payload offsets in the tree are 0 until the model is written to a file.
struct HlodModel {
  HlodTree tree;
  std::vector<HlodPayload> payloads;
};

// The tree assembled from the subtrees' roots (HlodBuilder::assemble_top): model.payloads[i]
// holds node i's geometry when it is a top node and is empty when origin[i].subtree >= 0 (its
// payload is that subtree's payloads[origin[i].local]).
struct HlodAssembly {
  struct Origin {
    int32_t subtree = -1;
    uint32_t local = 0;
  };
  HlodModel model;
  std::vector<Origin> origin;  // by node
};

// One layer of the top to measure against the original (HlodBuilder::build_top), whole: its
// geometry, the original vertex each of its vertices descends from, its node's reference samples.
struct HlodLayerProbe {
  std::vector<float> positions;
  std::vector<uint32_t> indices;
  std::vector<uint32_t> source;
  std::vector<uint32_t> reference;
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

// Builds the HLOD of `mesh` (cleaned: see clean_mesh; its uvs (TEXCOORD_0), second uvs
// (TEXCOORD_1), colours (COLOR_0) and submeshes' materials are kept, its normals are recomputed).
// Fails on an empty mesh, indices out of range, non-finite coordinates, uvs or colours, an
// attribute whose count is not the vertices', or a mesh with more than 2^32 - 1 vertices; `out`
// is only written on success. tree.name and tree.source_hash are left for the caller.
Status build_hlod(HlodModel& out, const MeshData& mesh, const HlodBuildOptions& options,
                  HlodBuildReport* report = nullptr);

// One frontier node: a subtree to bake.
struct HlodSubtreeSpec {
  uint8_t depth = 0;
  float center[3] = {0, 0, 0};  // its octree cell
  float half = 0;
  uint64_t triangles = 0;       // original triangles in it: the estimated cost
  // Hash of its depth, cell, triangles (ids and corners) and which of its vertices ancestors'
  // patches lock: with the mesh and the options, everything its bake depends on.
  uint64_t fingerprint = 0;
  // Its place in depth-first (octant) order of the top: subtrees close in it are close in space.
  uint32_t spatial = 0;
};

// The three steps of build_hlod, for a caller that spreads (b) over processes. `mesh`'s arrays
// (a MeshData's, or memory a node's ranks share) must outlive the builder; the options are
// copied. Not thread-safe itself; bake_subtrees runs its subtrees through options.parallel_for.
class HlodBuilder {
 public:
  HlodBuilder(const MeshView& mesh, const HlodBuildOptions& options);
  ~HlodBuilder();
  HlodBuilder(const HlodBuilder&) = delete;
  HlodBuilder& operator=(const HlodBuilder&) = delete;

  // (a) Checks the mesh (as build_hlod) and splits the top down to the frontier.
  Status plan();
  // Frontier nodes, in breadth-first order of the top.
  const std::vector<HlodSubtreeSpec>& subtrees() const;
  // (b) Bakes the listed subtrees (each at most once per builder); `done` gets each result as
  // it is finished, possibly from several threads at once. Stops at the first failure, whose
  // status names the subtree; `done`'s own failure stops it too.
  using SubtreeDone = std::function<Status(size_t subtree, HlodSubtree&& result)>;
  Status bake_subtrees(const std::vector<size_t>& which, const SubtreeDone& done);
  // (c) The levels above the frontier and the whole tree, from every subtree's result (by
  // subtree index; consumed). tree.name and tree.source_hash are left for the caller.
  Status assemble(std::vector<HlodSubtree>& baked, HlodModel& out, HlodBuildReport* report = nullptr);
  // (c) without the subtrees' payloads: each result needs its nodes and its root's payload
  // only (payloads[0]; more are ignored). The whole tree and the top's payloads, and where each
  // subtree node's payload comes from, for a writer that places those itself. Once per builder
  // (assemble is this plus the payloads moved in).
  Status assemble_top(const std::vector<HlodSubtree>& baked, HlodAssembly& out, HlodBuildReport* report = nullptr);
  // assemble_top in three steps, so that the top's error measurement (most of its work) can be
  // spread like (b): build_top builds the top's layers from the subtrees' roots and lists every
  // layer to measure; measure_probes, on any builder planned over the same mesh, measures the
  // listed ones (errors by position in `which`); finish_top, on the builder that built the top,
  // takes every layer's error (by probe) and makes the tree.
  Status build_top(const std::vector<HlodSubtree>& baked, std::vector<HlodLayerProbe>& probes);
  Status measure_probes(const std::vector<HlodLayerProbe>& probes, const std::vector<size_t>& which,
                        std::vector<float>& errors);
  Status finish_top(const std::vector<HlodSubtree>& baked, const std::vector<float>& errors, HlodAssembly& out,
                    HlodBuildReport* report = nullptr);
  // How the original is queried: each subtree's layers against a BVH of the part of
  // the original near its cell (bake_subtrees), kept for the top's samples in that cell; the
  // top's other samples against a part built near them; and a query a part cannot answer
  // exactly as the whole original would (the nearest found is not provably the nearest)
  // against the whole original's BVH, built on first need only. The bytes are the same either way.
  //
  // A distributed build's region: the subtrees whose cells' top samples this builder measures
  // (measure_probes_part): those it writes, baked or found in the cache. Their parts are listed
  // in the same pass over the original as its bake's. Before bake_subtrees.
  void set_region(const std::vector<size_t>& subtrees);
  // The top's errors split by sample rather than by layer: per probe, the largest distance to
  // the original among its layer samples in the cells of the subtrees this builder baked or has
  // in its region, each answered by that subtree's part (to_max), and which samples those are
  // (answered, one flag per sample); for the probes listed
  // in `reference`, the other side (the node's original samples to the layer; from_max, by
  // position in `reference`). A layer's error is max(to_max over every sample, from_max).
  Status measure_probes_part(const std::vector<HlodLayerProbe>& probes, const std::vector<size_t>& reference,
                             std::vector<float>& to_max, std::vector<std::vector<uint8_t>>& answered,
                             std::vector<float>& from_max);
  // The samples no builder answered (answered: every builder's flags merged), measured against
  // the original near them (the whole original only where that cannot answer); raises to_max.
  Status measure_probes_rest(const std::vector<HlodLayerProbe>& probes,
                             const std::vector<std::vector<uint8_t>>& answered, std::vector<float>& to_max);
  // Thread CPU seconds the original's BVHs took to plan and build (its parts and the whole).
  double surface_cpu_seconds() const;
  // Triangles in the parts of the original built so far (a triangle near several subtrees
  // counts once per part), and whether the whole original's BVH was built.
  size_t part_triangles() const;
  bool whole_surface_built() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lod
