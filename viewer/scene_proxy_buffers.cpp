#include "viewer/scene_proxy_buffers.h"

#include "viewer/mesh_buffers.h"

namespace lod::viewer {

SceneProxyBuffers::~SceneProxyBuffers() {
  if (ibo_) glDeleteBuffers(1, &ibo_);
  if (vbo_) glDeleteBuffers(1, &vbo_);
  if (vao_) glDeleteVertexArrays(1, &vao_);
}

void SceneProxyBuffers::upload(const SceneHlodTree& tree) {
  const size_t pos = tree.positions.size() * sizeof(float);
  const size_t nrm = tree.normals.size() == tree.positions.size() ? pos : 0;
  const size_t idx = tree.indices.size() * sizeof(uint32_t);
  glGenVertexArrays(1, &vao_);
  glGenBuffers(1, &vbo_);
  glGenBuffers(1, &ibo_);
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(pos + nrm), nullptr, GL_STATIC_DRAW);
  glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(pos), tree.positions.data());
  glEnableVertexAttribArray(kAttribPosition);
  glVertexAttribPointer(kAttribPosition, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  if (nrm) {
    glBufferSubData(GL_ARRAY_BUFFER, GLintptr(pos), GLsizeiptr(nrm), tree.normals.data());
    glEnableVertexAttribArray(kAttribNormal);
    glVertexAttribPointer(kAttribNormal, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), reinterpret_cast<const void*>(pos));
  }
  // Per-object attributes stay disabled: the renderer sets the identity transform as constants.
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo_);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(idx), tree.indices.data(), GL_STATIC_DRAW);
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  bytes_ = pos + nrm + idx;
}

}  // namespace lod::viewer
