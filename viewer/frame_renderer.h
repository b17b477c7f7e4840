// FrameRenderer: one published Frame drawn from one viewing camera into the bound framebuffer:
// clear, build the draw list, one instanced draw per (model, level, target level), then one draw per
// view-dependent object from the active mesh the frame carries, then the terrain's mesh.
#pragma once
#include <span>
#include <string>
#include <vector>

#include "jobs/scene.h"
#include "runtime/frame.h"
#include "runtime/view.h"
#include "viewer/draw_list.h"
#include "viewer/instance_renderer.h"
#include "viewer/mesh_buffers.h"
#include "viewer/morph_buffers.h"
#include "viewer/terrain_renderer.h"
#include "viewer/vd_mesh_buffers.h"

namespace lod::viewer {

class FrameRenderer {
 public:
  // Uploads every level of every chain; false with the reason in `message`.
  bool init(const Scene& scene, std::string* message);
  // `viewing` also gives the viewport size (width x height pixels).
  DrawStats render(const Frame& frame, const View& viewing, const RenderSettings& settings);

  // Objects the frame culled (scene objects whose handle, `handles[i]` for scene object i, has
  // no frame entry), drawn dark at their coarsest level, for views from outside the LOD camera
  // (bird's-eye, frozen LOD). Call after render(); not counted in DrawStats.
  void render_culled(const Frame& frame, std::span<const ObjectHandle> handles, const View& viewing);

  const DrawList& draw_list() const { return list_; }
  const MeshBuffers& meshes() const { return meshes_; }
  const MorphBuffers& morphs() const { return morphs_; }

 private:
  const Scene* scene_ = nullptr;
  MeshBuffers meshes_;
  MorphBuffers morphs_;
  VdMeshBuffers vd_meshes_;
  InstanceRenderer instances_;
  TerrainRenderer terrain_;
  DrawList list_;
  Frame culled_;                             // scratch: the culled objects as a frame
  std::vector<ObjectHandle> frame_handles_;  // scratch: the frame's handles, sorted
  DrawList culled_list_;
};

}  // namespace lod::viewer
