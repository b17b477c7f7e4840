// TerrainRenderer: the frame's terrain mesh (Frame::terrain_positions / terrain_indices, world
// space, ROAM's triangles for view 0) streamed into its own VBO + IBO every frame and drawn
// coloured by height (green lowlands, brown slopes, white peaks over the frame's height range)
// and lit by a fixed sun with face normals, so relief reads without vertex normals.
#pragma once
#include <cstddef>
#include <string>

#include <epoxy/gl.h>
#include <glm/glm.hpp>

#include "runtime/frame.h"
#include "viewer/instance_renderer.h"
#include "viewer/terrain_palette.h"

namespace lod::viewer {

class TerrainRenderer {
 public:
  TerrainRenderer() = default;
  ~TerrainRenderer();
  TerrainRenderer(const TerrainRenderer&) = delete;
  TerrainRenderer& operator=(const TerrainRenderer&) = delete;

  // Compiles the shader; false with the driver's log in `message`.
  bool init(std::string* message);
  // Draws the frame's terrain (nothing when it has none) and adds it to `stats`: one draw, its
  // triangles in `triangles` and `terrain_triangles`, and in gpu_primitives when counted.
  void draw(const Frame& frame, const glm::mat4& view, const glm::mat4& projection, const RenderSettings& settings,
            DrawStats& stats);

 private:
  GLuint program_ = 0, vao_ = 0, vbo_ = 0, ibo_ = 0, query_ = 0;
  size_t vbo_capacity_ = 0, ibo_capacity_ = 0;
  GLint u_view_ = -1, u_projection_ = -1, u_range_ = -1;
};

}  // namespace lod::viewer
