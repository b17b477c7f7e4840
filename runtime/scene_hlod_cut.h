// Scene HLOD cut for one view: which proxies are drawn and which objects they stand for.
//
// Breadth-first from the root, a node inside the frustum is drawn when its proxy's error
// projects to at most the pixel threshold, with the same convention as the model HLOD cut
// (hlod_select.h): error * focal / d <= pixel_error, d the distance from the eye to the node's
// sphere (the eye inside it: never drawn). Otherwise it is opened: its child nodes are tested
// in turn and its single objects go to the per-object path. A node outside the frustum is
// neither drawn nor opened (its objects are culled on their own). A node with an object that is
// no longer as it was built (`valid` says so) is always opened.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "runtime/scene_hlod_tree.h"
#include "runtime/view.h"

namespace lod {

struct SceneHlodCut {
  std::vector<uint32_t> drawn;  // node ids, breadth-first
  uint64_t triangles = 0;       // of the drawn proxies
  uint32_t objects = 0;         // objects the drawn proxies stand for
  uint32_t stale = 0;           // nodes opened only because an object changed
  std::vector<uint32_t> queue;  // scratch
};

// `object_ok[j]` for tree object j: it is live and as it was built. `bad_prefix` (size
// objects + 1) is its exclusive prefix count of failures, filled by scene_hlod_validity.
void scene_hlod_validity(std::span<uint32_t> bad_prefix, std::span<const uint8_t> object_ok);

void select_scene_hlod_cut(SceneHlodCut& out, const SceneHlodTree& tree, const Frustum& frustum,
                           const glm::vec3& eye, float focal, float pixel_error,
                           std::span<const uint32_t> bad_prefix);

// The projected error of a node's proxy in pixels (+inf when the eye is inside its sphere).
float scene_proxy_pixels(const SceneHlodNode& node, const glm::vec3& eye, float focal);

}  // namespace lod
