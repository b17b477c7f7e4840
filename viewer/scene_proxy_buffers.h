// SceneProxyBuffers: every scene HLOD proxy uploaded once (they are small next to the objects
// and always resident): one VBO of positions then normals, one IBO, world space.
#pragma once
#include <cstddef>

#include <epoxy/gl.h>

#include "runtime/scene_hlod_tree.h"
#include "viewer/mesh_buffers.h"

namespace lod::viewer {

class SceneProxyBuffers {
 public:
  SceneProxyBuffers() = default;
  ~SceneProxyBuffers();
  SceneProxyBuffers(const SceneProxyBuffers&) = delete;
  SceneProxyBuffers& operator=(const SceneProxyBuffers&) = delete;

  void upload(const SceneHlodTree& tree);
  GLuint vao() const { return gl_.vao; }
  size_t bytes() const { return bytes_; }

 private:
  StaticMeshGl gl_;
  size_t bytes_ = 0;
};

}  // namespace lod::viewer
