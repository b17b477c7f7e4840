#include "viewer/frame_renderer.h"

#include <algorithm>

#include "viewer/level_palette.h"

namespace lod::viewer {

// GPU copies of HLOD nodes: a few times the stream budget, so a cut moving back and forth
// does not re-read, but bounded however long the flight.
uint64_t hlod_gpu_capacity(const HlodModels& m) { return std::max<uint64_t>(4 * m.stream.budget_bytes, 64ull << 20); }

bool FrameRenderer::init(const Scene& scene, const HlodModels* hlod, std::string* message) {
  scene_ = &scene;
  if (!instances_.init(message) || !terrain_.init(message) || !backdrop_.init(message)) return false;
  ground_ = ground_under(scene.objects);
  hlod_ = hlod && !hlod->empty() ? hlod : nullptr;
  if (hlod_ && !hlod_nodes_.init(*hlod_, hlod_gpu_capacity(*hlod_), message)) return false;
  meshes_.upload(scene.chains);
  morphs_.init(scene.chains);
  vd_meshes_.init();
  if (const GLenum err = glGetError(); err != GL_NO_ERROR) {
    *message = "uploading " + std::to_string(meshes_.layout().index_count / 3) + " triangles failed (GL error " +
               std::to_string(err) + ")";
    return false;
  }
  return true;
}

void FrameRenderer::set_scene_hlod(const SceneHlodTree* tree) {
  scene_hlod_ = tree && !tree->empty() ? tree : nullptr;
  if (scene_hlod_) proxies_.upload(*scene_hlod_);
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

  // A terrain is the ground: then the sky only.
  if (settings.backdrop)
    backdrop_.draw(view_matrix(viewing), projection_matrix(viewing), viewing.eye, ground_,
                   frame.terrain_indices.empty());
  build_draw_list(frame, meshes_.layout(), list_);
  vd_meshes_.upload(frame);
  DrawStats stats = instances_.draw(list_, meshes_, &morphs_, &vd_meshes_, view_matrix(viewing),
                                    projection_matrix(viewing), settings);
  if (hlod_) {
    build_hlod_draw_list(frame, *hlod_, hlod_list_);
    hlod_nodes_.prepare(hlod_list_);
    instances_.draw_hlod(hlod_list_, hlod_nodes_, view_matrix(viewing), projection_matrix(viewing), settings, stats);
  }
  if (scene_hlod_) {
    build_proxy_draw_list(frame, *scene_hlod_, proxy_list_);
    instances_.draw_proxies(proxy_list_, proxies_, view_matrix(viewing), projection_matrix(viewing), settings, stats);
  }
  terrain_.draw(frame, view_matrix(viewing), projection_matrix(viewing), settings, stats);
  // Blended runs last, over all of the above.
  instances_.draw_blended(list_, meshes_, &morphs_, &vd_meshes_, hlod_ ? &hlod_list_ : nullptr,
                          hlod_ ? &hlod_nodes_ : nullptr, view_matrix(viewing), projection_matrix(viewing), settings,
                          stats);
  return stats;
}

void FrameRenderer::render_culled(const Frame& frame, std::span<const ObjectHandle> handles,
                                  const View& viewing) {
  // Culled objects have no frame entry, so no transform this frame: they are drawn at the
  // scene's placement, which for a moving object is its start position, not where it is now.
  frame_handles_.assign(frame.handles.begin(), frame.handles.end());
  std::sort(frame_handles_.begin(), frame_handles_.end());
  const ObjectSet& objects = scene_->objects;
  culled_.models.clear();
  culled_.transforms.clear();
  culled_.levels.clear();
  culled_.morph.clear();
  for (size_t id = 0; id < objects.size() && id < handles.size(); ++id) {
    if (std::binary_search(frame_handles_.begin(), frame_handles_.end(), handles[id])) continue;
    const uint32_t model = objects.model[id];
    culled_.models.push_back(model);
    culled_.transforms.push_back(transform_of(objects, id));
    culled_.levels.push_back(uint8_t(scene_->models.level_count[model] - 1));
    culled_.morph.push_back(1.f);
  }
  build_draw_list(culled_, meshes_.layout(), culled_list_);
  RenderSettings dark;
  dark.colour_override = true;
  dark.colour = kCulledColour;
  instances_.draw(culled_list_, meshes_, nullptr, nullptr, view_matrix(viewing), projection_matrix(viewing), dark);
}

}  // namespace lod::viewer
