// Scene HLOD build (Zhou and Tian 3.2): an octree over a scene's static objects (a cell with fewer than
// `min_objects` objects is not split further and is not a node), then, bottom-up, every node's
// proxy: its child nodes' proxies and its single objects' coarsest drawn levels, placed in
// world space and merged without boundaries (the objects are separate surfaces), simplified
// to `reduction` of their triangles by QEM. A proxy's error is its measured distance to what
// it was built from (Embree) plus the largest error of those inputs (their chain level's error
// times the object's scale, or the child proxy's error), so it bounds the distance to the
// objects' full-detail surfaces and never decreases up the tree.
//
// Deterministic: the same objects give the same tree at any thread count.
#pragma once
#include <cstdint>
#include <functional>
#include <span>
#include <string>

#include "lodkit/types.hpp"
#include "preprocess/qem_simplifier.h"  // ParallelFor
#include "runtime/lod_chain.h"
#include "runtime/scene_hlod_tree.h"
#include "runtime/status.h"

namespace lod {

struct SceneHlodObjectsIn {
  std::span<const LodChain> chains;       // per model
  std::span<const uint32_t> model;        // per object
  std::span<const Transform> transform;   // per object
  std::span<const Sphere> sphere;         // per object: world sphere (world_sphere of chain_sphere)
  std::span<const uint32_t> scene_index;  // per object: its index in the scene
};

struct SceneHlodSettings {
  uint32_t min_objects = 2;   // Zhou and Tian: stop when a cell holds fewer than 2 models
  float reduction = 0.5f;     // a proxy keeps this fraction of its inputs' triangles ...
  // ... unless a collapse would move the surface more than this fraction of the node's bounding
  // radius (QEM's max_error): a proxy of a small group stays close to its objects, one of a
  // quarter of the city may be as coarse as its size allows, so errors grow with the cells.
  float cell_error = 0.01f;
  uint32_t error_samples = 4000;  // input vertices measured to the proxy (every proxy vertex is, to the input)
};

// `progress(done, total)` is called as nodes finish (from the caller's thread or workers).
Status build_scene_hlod(const SceneHlodObjectsIn& in, const SceneHlodSettings& settings, const ParallelFor& parallel_for,
                        const std::function<void(size_t, size_t)>& progress, SceneHlodTree& out);

}  // namespace lod
