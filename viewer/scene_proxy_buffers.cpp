#include "viewer/scene_proxy_buffers.h"

namespace lod::viewer {

SceneProxyBuffers::~SceneProxyBuffers() { release_static_mesh(gl_); }

void SceneProxyBuffers::upload(const SceneHlodTree& tree) {
  bytes_ = upload_static_mesh(gl_, tree.positions, tree.normals, tree.indices);
}

}  // namespace lod::viewer
