// lod run --validate for the scene HLOD: every drawn proxy is a node of the tree, no two drawn
// proxies overlap (none is an ancestor of another), no object a drawn proxy stands for is also
// drawn for view 0 on its own, and the frame's proxy counts add up.
#pragma once
#include <span>
#include <string>
#include <vector>

#include "lodkit/types.hpp"
#include "runtime/frame.h"
#include "runtime/scene_hlod_tree.h"

namespace lod::cli {

class SceneHlodCheck {
 public:
  // `handles[i]`: scene object i's handle in the service.
  void load(const SceneHlodTree& tree, std::span<const ObjectHandle> handles);
  // False with `why` at the first fault of `f`.
  bool check(const Frame& f, std::string* why);

 private:
  const SceneHlodTree* tree_ = nullptr;
  std::vector<ObjectHandle> handle_;   // per tree object
  std::vector<uint8_t> covered_;       // per tree object: a drawn proxy stands for it (scratch)
  std::vector<ObjectHandle> drawn_;    // view 0's entries this frame, sorted (scratch)
};

}  // namespace lod::cli
