// VdMeshBuffers: the view-dependent objects' active meshes of one Frame (vd_positions,
// vd_indices, vd_normals, and vd_uvs / vd_colors when the frame has them) streamed into dynamic buffers
// every frame, with a VAO whose per-object transform attributes are constants set per draw (the
// instance renderer's shader; a frame without normals falls back to face normals; without uvs
// the uv is a constant 0, without colours the colour constant white).
#pragma once
#include <cstddef>

#include <epoxy/gl.h>

#include "runtime/frame.h"

namespace lod::viewer {

class VdMeshBuffers {
 public:
  VdMeshBuffers() = default;
  ~VdMeshBuffers();
  VdMeshBuffers(const VdMeshBuffers&) = delete;
  VdMeshBuffers& operator=(const VdMeshBuffers&) = delete;

  void init();
  // Copies the frame's vd positions and indices (object space, already geomorphed); storage
  // is orphaned every frame so the driver never waits for the last frame's draws, and grows
  // by half again when it is too small.
  void upload(const Frame& frame);

  GLuint vao() const { return vao_; }
  size_t vertex_capacity_bytes() const { return vbo_capacity_; }
  size_t index_capacity_bytes() const { return ibo_capacity_; }

 private:
  GLuint vao_ = 0, vbo_ = 0, ibo_ = 0, uv_vbo_ = 0, normal_vbo_ = 0, color_vbo_ = 0;
  size_t vbo_capacity_ = 0, ibo_capacity_ = 0, uv_capacity_ = 0, normal_capacity_ = 0, color_capacity_ = 0;
};

}  // namespace lod::viewer
