#include "viewer/frame_renderer.h"

#include "viewer/level_palette.h"

namespace lod::viewer {

bool FrameRenderer::init(const Scene& scene, std::string* message) {
  scene_ = &scene;
  if (!instances_.init(message)) return false;
  meshes_.upload(scene.chains);
  if (const GLenum err = glGetError(); err != GL_NO_ERROR) {
    *message = "uploading " + std::to_string(meshes_.layout().index_count / 3) + " triangles failed (GL error " +
               std::to_string(err) + ")";
    return false;
  }
  return true;
}

DrawStats FrameRenderer::render(const Frame& frame, const View& viewing, const RenderSettings& settings) {
  glViewport(0, 0, viewing.width, viewing.height);
  glClearColor(kBackground[0], kBackground[1], kBackground[2], 1.f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);  // meshes from the wild have mixed windings; shading is two-sided
  glDisable(GL_BLEND);
  glDisable(GL_SCISSOR_TEST);

  build_draw_list(frame, scene_->objects, meshes_.layout(), list_);
  return instances_.draw(list_, meshes_, view_matrix(viewing), projection_matrix(viewing), settings);
}

}  // namespace lod::viewer
