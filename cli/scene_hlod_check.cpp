#include "cli/scene_hlod_check.h"

#include <algorithm>

namespace lod::cli {

void SceneHlodCheck::load(const SceneHlodTree& tree, std::span<const ObjectHandle> handles) {
  tree_ = &tree;
  handle_.resize(tree.objects.size());
  for (size_t j = 0; j < tree.objects.size(); ++j) {
    const uint32_t i = tree.objects[j].scene_index;
    handle_[j] = i < handles.size() ? handles[i] : 0;
  }
}

bool SceneHlodCheck::check(const Frame& f, std::string* why) {
  if (!tree_ || tree_->empty()) {
    if (f.scene_proxies.empty()) return true;
    *why = "proxies drawn without a scene hlod";
    return false;
  }
  covered_.assign(handle_.size(), 0);
  uint64_t tris = 0, objects = 0;
  for (uint32_t id : f.scene_proxies) {
    if (id >= tree_->nodes.size()) {
      *why = "proxy " + std::to_string(id) + " is not a node of the scene hlod";
      return false;
    }
    const SceneHlodNode& n = tree_->nodes[id];
    for (uint32_t j = n.first_object; j < n.first_object + n.object_count; ++j) {
      if (covered_[j]) {
        *why = "proxy " + std::to_string(id) + " overlaps another drawn proxy (object " + std::to_string(j) + ")";
        return false;
      }
      covered_[j] = 1;
    }
    tris += n.triangles();
    objects += n.object_count;
  }
  if (tris != f.scene_proxy_tris || objects != f.scene_proxy_objects) {
    *why = "scene_proxy_tris / scene_proxy_objects do not add up over the drawn proxies";
    return false;
  }
  drawn_.clear();
  for (size_t k = 0; k < f.handles.size() && k < f.view_masks.size(); ++k)
    if (f.view_masks[k] & 1u) drawn_.push_back(f.handles[k]);
  std::sort(drawn_.begin(), drawn_.end());
  for (size_t j = 0; j < handle_.size(); ++j) {
    if (covered_[j] && std::binary_search(drawn_.begin(), drawn_.end(), handle_[j])) {
      *why = "object " + std::to_string(tree_->objects[j].scene_index) + " is drawn both on its own and in a proxy";
      return false;
    }
  }
  return true;
}

}  // namespace lod::cli
