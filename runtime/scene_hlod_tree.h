// SceneHlodTree: the scene HLOD (Zhou and Tian 3.2): an octree over a scene's static objects whose every
// cell holding two or more of them carries one merged proxy mesh standing for all of them, so
// that a distant group of many objects is drawn with one mesh in one draw.
//
// Objects are stored in octree order, so the objects under any node are one contiguous range.
// A cell holding one object is not a node: that object is drawn on the per-object path when
// its parent is opened. Proxies are in world space (static objects only: a proxy whose objects
// moved, went away or changed options is never drawn again; see scene_hlod_cut.h).
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "lodkit/types.hpp"
#include "runtime/lod_chain.h"  // Sphere

namespace lod {

inline constexpr uint32_t kSceneHlodMaxDepth = 20;

struct SceneHlodNode {
  uint32_t first_child = 0, child_count = 0;    // child nodes, contiguous (breadth-first)
  uint32_t first_object = 0, object_count = 0;  // every object under the node (>= 2)
  uint8_t depth = 0;
  Sphere bounds;                                // world space, holds every object's sphere
  // World-space distance from the proxy to the objects' full-detail surfaces (an upper bound:
  // the measured simplification error plus the largest error of what it was built from), so
  // errors grow up the tree.
  float error = 0;
  uint32_t first_vertex = 0, vertex_count = 0;  // the proxy, into SceneHlodTree::positions
  uint32_t first_index = 0, index_count = 0;    // into indices; node-local vertex numbers
  uint32_t triangles() const { return index_count / 3; }
};

struct SceneHlodObject {
  uint32_t scene_index = 0;  // the object's place in the scene it was built from
  ObjectHandle handle = 0;   // its handle in the service (bound after the objects are created)
  uint32_t model = 0;
  Sphere sphere;             // world bounding sphere at build time, exactly as the store computes it
};

struct SceneHlodTree {
  std::vector<SceneHlodNode> nodes;     // breadth-first, nodes[0] the root (empty: no proxies)
  std::vector<SceneHlodObject> objects; // octree order
  std::vector<float> positions;         // xyz per vertex, world space, all proxies
  std::vector<float> normals;           // same count
  std::vector<uint32_t> indices;
  uint64_t source_triangles = 0;        // the objects' full-detail triangles
  bool empty() const { return nodes.empty(); }
};

// Sets every tree object's handle: handles[i] is scene object i's (make_service order).
inline void bind_scene_hlod_handles(SceneHlodTree& tree, std::span<const ObjectHandle> handles) {
  for (SceneHlodObject& o : tree.objects) o.handle = o.scene_index < handles.size() ? handles[o.scene_index] : 0;
}

}  // namespace lod
