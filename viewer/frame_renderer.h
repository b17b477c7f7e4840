// FrameRenderer: one published Frame drawn from one viewing camera into the bound framebuffer:
// clear, sky and ground (the backdrop), build the draw list, one instanced draw per (model, level, target level), then one draw per
// view-dependent object from the active mesh the frame carries, then one per node layer or
// boundary patch of the HLOD cuts, one per scene HLOD proxy, and the terrain's mesh; last the
// alpha-blended runs of the instances, view-dependent objects and HLOD nodes, farthest first.
#pragma once
#include <span>
#include <string>
#include <vector>

#include "jobs/scene.h"
#include "runtime/frame.h"
#include "runtime/view.h"
#include "viewer/backdrop_renderer.h"
#include "viewer/draw_list.h"
#include "viewer/hlod_draw_list.h"
#include "viewer/hlod_node_buffers.h"
#include "viewer/proxy_draw_list.h"
#include "viewer/scene_proxy_buffers.h"
#include "viewer/instance_renderer.h"
#include "viewer/mesh_buffers.h"
#include "viewer/morph_buffers.h"
#include "viewer/terrain_renderer.h"
#include "viewer/vd_mesh_buffers.h"

namespace lod::viewer {

class FrameRenderer {
 public:
  // Uploads every level of every chain and opens the HLOD models' files (`hlod` may be null:
  // none); false with the reason in `message`.
  bool init(const Scene& scene, const HlodModels* hlod, std::string* message);
  // Uploads the scene HLOD's proxies (drawn when a frame names them); call after init.
  void set_scene_hlod(const SceneHlodTree* tree);
  // `viewing` also gives the viewport size (width x height pixels).
  DrawStats render(const Frame& frame, const View& viewing, const RenderSettings& settings);

  // Objects the frame culled (scene objects whose handle, `handles[i]` for scene object i, has
  // no frame entry), drawn dark at their coarsest level, for views from outside the LOD camera
  // (bird's-eye, frozen LOD). Call after render(); not counted in DrawStats.
  void render_culled(const Frame& frame, std::span<const ObjectHandle> handles, const View& viewing);

  const DrawList& draw_list() const { return list_; }
  const MeshBuffers& meshes() const { return meshes_; }
  const MorphBuffers& morphs() const { return morphs_; }
  const HlodDrawList& hlod_list() const { return hlod_list_; }
  const HlodNodeBuffers& hlod_nodes() const { return hlod_nodes_; }
  const ProxyDrawList& proxy_list() const { return proxy_list_; }

 private:
  const Scene* scene_ = nullptr;
  MeshBuffers meshes_;
  MorphBuffers morphs_;
  VdMeshBuffers vd_meshes_;
  InstanceRenderer instances_;
  BackdropRenderer backdrop_;
  GroundPlane ground_;
  TerrainRenderer terrain_;
  DrawList list_;
  const HlodModels* hlod_ = nullptr;
  HlodDrawList hlod_list_;
  HlodNodeBuffers hlod_nodes_;
  const SceneHlodTree* scene_hlod_ = nullptr;
  SceneProxyBuffers proxies_;
  ProxyDrawList proxy_list_;
  Frame culled_;                             // scratch: the culled objects as a frame
  std::vector<ObjectHandle> frame_handles_;  // scratch: the frame's handles, sorted
  DrawList culled_list_;
};

}  // namespace lod::viewer
