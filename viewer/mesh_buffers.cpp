#include "viewer/mesh_buffers.h"

#include <vector>

namespace lod::viewer {

size_t upload_static_mesh(StaticMeshGl& gl, std::span<const float> positions, std::span<const float> normals,
                          std::span<const uint32_t> indices) {
  const size_t pos_bytes = positions.size() * sizeof(float);
  const size_t nrm_bytes = normals.size() == positions.size() ? pos_bytes : 0;
  const size_t idx_bytes = indices.size() * sizeof(uint32_t);
  glGenVertexArrays(1, &gl.vao);
  glGenBuffers(1, &gl.vbo);
  glGenBuffers(1, &gl.ibo);
  glBindVertexArray(gl.vao);
  glBindBuffer(GL_ARRAY_BUFFER, gl.vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(pos_bytes + nrm_bytes), nullptr, GL_STATIC_DRAW);
  glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(pos_bytes), positions.data());
  glEnableVertexAttribArray(kAttribPosition);
  glVertexAttribPointer(kAttribPosition, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  if (nrm_bytes) {
    glBufferSubData(GL_ARRAY_BUFFER, GLintptr(pos_bytes), GLsizeiptr(nrm_bytes), normals.data());
    glEnableVertexAttribArray(kAttribNormal);
    glVertexAttribPointer(kAttribNormal, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float),
                          reinterpret_cast<const void*>(pos_bytes));
  }
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, gl.ibo);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(idx_bytes), indices.data(), GL_STATIC_DRAW);
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  return pos_bytes + nrm_bytes + idx_bytes;
}

void release_static_mesh(StaticMeshGl& gl) {
  if (gl.ibo) glDeleteBuffers(1, &gl.ibo);
  if (gl.vbo) glDeleteBuffers(1, &gl.vbo);
  if (gl.vao) glDeleteVertexArrays(1, &gl.vao);
  gl = StaticMeshGl{};
}

MeshBuffers::~MeshBuffers() {
  if (ibo_) glDeleteBuffers(1, &ibo_);
  if (vbo_) glDeleteBuffers(1, &vbo_);
  if (uv_vbo_) glDeleteBuffers(1, &uv_vbo_);
  if (vao_) glDeleteVertexArrays(1, &vao_);
}

void MeshBuffers::upload(std::span<const LodChain> chains) {
  layout_ = layout_meshes(chains);
  std::vector<float> vertices;
  std::vector<uint32_t> indices;
  pack_vertices(chains, vertices, indices);
  std::vector<float> uvs;
  pack_uvs(chains, uvs);

  glGenVertexArrays(1, &vao_);
  glGenBuffers(1, &vbo_);
  glGenBuffers(1, &ibo_);
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(vertices.size() * sizeof(float)), vertices.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(kAttribPosition);
  glVertexAttribPointer(kAttribPosition, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
  glEnableVertexAttribArray(kAttribNormal);
  glVertexAttribPointer(kAttribNormal, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                        reinterpret_cast<const void*>(3 * sizeof(float)));
  glGenBuffers(1, &uv_vbo_);
  glBindBuffer(GL_ARRAY_BUFFER, uv_vbo_);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(uvs.size() * sizeof(float)), uvs.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(kAttribUv);
  glVertexAttribPointer(kAttribUv, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), nullptr);
  // The element buffer binding is VAO state: bound while the VAO is.
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo_);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices.size() * sizeof(uint32_t)), indices.data(),
               GL_STATIC_DRAW);
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  materials_.upload(chains);
  bytes_ = (vertices.size() + uvs.size()) * sizeof(float) + indices.size() * sizeof(uint32_t) + materials_.bytes();
}

}  // namespace lod::viewer
