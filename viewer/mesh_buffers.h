// MeshBuffers: every level of every model uploaded once into one VBO (position + normal) and
// one IBO, with a VAO whose instance attributes the instance renderer fills per draw.
#pragma once
#include <span>

#include <epoxy/gl.h>

#include "runtime/lod_chain.h"
#include "viewer/mesh_layout.h"

namespace lod::viewer {

// Vertex attribute locations shared with the shaders.
inline constexpr GLuint kAttribPosition = 0;
inline constexpr GLuint kAttribNormal = 1;
inline constexpr GLuint kAttribInstancePositionScale = 2;
inline constexpr GLuint kAttribInstanceYawMorph = 3;

class MeshBuffers {
 public:
  MeshBuffers() = default;
  ~MeshBuffers();
  MeshBuffers(const MeshBuffers&) = delete;
  MeshBuffers& operator=(const MeshBuffers&) = delete;

  void upload(std::span<const LodChain> chains);

  const MeshLayout& layout() const { return layout_; }
  GLuint vao() const { return vao_; }
  size_t bytes() const { return bytes_; }

 private:
  MeshLayout layout_;
  GLuint vao_ = 0, vbo_ = 0, ibo_ = 0;
  size_t bytes_ = 0;
};

}  // namespace lod::viewer
