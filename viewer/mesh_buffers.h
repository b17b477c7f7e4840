// MeshBuffers: every level of every model uploaded once into one VBO (position + normal), a
// second VBO of texture coordinates and one IBO, with a VAO whose instance attributes the
// instance renderer fills per draw; and the chains' materials with their textures.
#pragma once
#include <span>

#include <epoxy/gl.h>

#include "runtime/lod_chain.h"
#include "viewer/material_textures.h"
#include "viewer/mesh_layout.h"

namespace lod::viewer {

// Vertex attribute locations shared with the shaders.
inline constexpr GLuint kAttribPosition = 0;
inline constexpr GLuint kAttribNormal = 1;
inline constexpr GLuint kAttribInstancePositionScale = 2;  // InstanceData::position_scale
inline constexpr GLuint kAttribInstanceRotation = 3;       // InstanceData::rotation (quaternion x y z w)
inline constexpr GLuint kAttribInstanceMorph = 4;          // InstanceData morph, blend weight
inline constexpr GLuint kAttribTargetPosition = 5;         // morph target stream (MorphBuffers)
inline constexpr GLuint kAttribTargetNormal = 6;
inline constexpr GLuint kAttribUv = 7;
inline constexpr GLuint kAttribTargetUv = 8;            // morph target stream (MorphBuffers)
inline constexpr GLuint kAttribColor = 9;  // linear RGBA COLOR_0 (HLOD nodes, vd meshes); constant white elsewhere

// A static mesh in its own VAO: positions then normals (when `normals` is not empty) in one
// VBO, indices in an IBO; the per-object attributes stay disabled, so the instance shader reads
// the constant transform set before each draw. Returns the bytes uploaded.
struct StaticMeshGl {
  GLuint vao = 0, vbo = 0, ibo = 0;
};
size_t upload_static_mesh(StaticMeshGl& gl, std::span<const float> positions, std::span<const float> normals,
                          std::span<const uint32_t> indices);
void release_static_mesh(StaticMeshGl& gl);

class MeshBuffers {
 public:
  MeshBuffers() = default;
  ~MeshBuffers();
  MeshBuffers(const MeshBuffers&) = delete;
  MeshBuffers& operator=(const MeshBuffers&) = delete;

  void upload(std::span<const LodChain> chains);

  const MeshLayout& layout() const { return layout_; }
  GLuint vao() const { return vao_; }
  GLuint vbo() const { return vbo_; }  // position + normal, 6 floats per vertex
  GLuint uv_vbo() const { return uv_vbo_; }  // uv, 2 floats per vertex
  const MaterialTextures& materials() const { return materials_; }
  size_t bytes() const { return bytes_; }

 private:
  MeshLayout layout_;
  MaterialTextures materials_;
  GLuint vao_ = 0, vbo_ = 0, uv_vbo_ = 0, ibo_ = 0;
  size_t bytes_ = 0;
};

}  // namespace lod::viewer
