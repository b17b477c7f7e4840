#include "viewer/vd_mesh_buffers.h"

#include "viewer/mesh_buffers.h"

namespace lod::viewer {

namespace {

// Orphans `target`'s storage (growing it geometrically when `bytes` do not fit) and copies in.
void stream(GLenum target, size_t bytes, const void* data, size_t& capacity) {
  if (bytes > capacity) capacity = bytes + bytes / 2;
  if (capacity == 0) return;
  glBufferData(target, GLsizeiptr(capacity), nullptr, GL_STREAM_DRAW);
  if (bytes) glBufferSubData(target, 0, GLsizeiptr(bytes), data);
}

}  // namespace

VdMeshBuffers::~VdMeshBuffers() {
  if (ibo_) glDeleteBuffers(1, &ibo_);
  if (uv_vbo_) glDeleteBuffers(1, &uv_vbo_);
  if (normal_vbo_) glDeleteBuffers(1, &normal_vbo_);
  if (color_vbo_) glDeleteBuffers(1, &color_vbo_);
  if (vbo_) glDeleteBuffers(1, &vbo_);
  if (vao_) glDeleteVertexArrays(1, &vao_);
}

void VdMeshBuffers::init() {
  glGenVertexArrays(1, &vao_);
  glGenBuffers(1, &vbo_);
  glGenBuffers(1, &ibo_);
  glGenBuffers(1, &uv_vbo_);
  glGenBuffers(1, &normal_vbo_);
  glGenBuffers(1, &color_vbo_);
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glEnableVertexAttribArray(kAttribPosition);
  glVertexAttribPointer(kAttribPosition, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  // Per-object attributes stay disabled: their current (constant) values are used.
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo_);
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}

void VdMeshBuffers::upload(const Frame& frame) {
  if (frame.vd_objects.empty()) return;  // nothing drawn from the buffers this frame
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  stream(GL_ARRAY_BUFFER, frame.vd_positions.size() * sizeof(float), frame.vd_positions.data(), vbo_capacity_);
  stream(GL_ELEMENT_ARRAY_BUFFER, frame.vd_indices.size() * sizeof(uint32_t), frame.vd_indices.data(),
         ibo_capacity_);
  // Normals likewise; without them the renderer's constant zero normal means face normals.
  if (frame.vd_normals.size() == frame.vd_positions.size()) {
    glBindBuffer(GL_ARRAY_BUFFER, normal_vbo_);
    stream(GL_ARRAY_BUFFER, frame.vd_normals.size() * sizeof(float), frame.vd_normals.data(), normal_capacity_);
    glEnableVertexAttribArray(kAttribNormal);
    glVertexAttribPointer(kAttribNormal, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  } else {
    glDisableVertexAttribArray(kAttribNormal);
  }
  // Uvs only when the frame has one per vertex; otherwise the constant uv the renderer sets.
  if (!frame.vd_uvs.empty() && 3 * frame.vd_uvs.size() == 2 * frame.vd_positions.size()) {
    glBindBuffer(GL_ARRAY_BUFFER, uv_vbo_);
    stream(GL_ARRAY_BUFFER, frame.vd_uvs.size() * sizeof(float), frame.vd_uvs.data(), uv_capacity_);
    glEnableVertexAttribArray(kAttribUv);
    glVertexAttribPointer(kAttribUv, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), nullptr);
  } else {
    glDisableVertexAttribArray(kAttribUv);
  }
  // Colours likewise (objects without them were given white by the frame).
  if (!frame.vd_colors.empty() && 3 * frame.vd_colors.size() == 4 * frame.vd_positions.size()) {
    glBindBuffer(GL_ARRAY_BUFFER, color_vbo_);
    stream(GL_ARRAY_BUFFER, frame.vd_colors.size() * sizeof(float), frame.vd_colors.data(), color_capacity_);
    glEnableVertexAttribArray(kAttribColor);
    glVertexAttribPointer(kAttribColor, 4, GL_FLOAT, GL_FALSE, 4 * sizeof(float), nullptr);
  } else {
    glDisableVertexAttribArray(kAttribColor);
  }
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}

}  // namespace lod::viewer
