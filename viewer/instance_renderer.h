// InstanceRenderer: draws a DrawList with one instanced draw per (model, level, target level)
// batch; per-instance position, scale, rotation quaternion, geomorph factor and blend weight are vertex
// attributes with divisor 1. A blended batch adds the composed morph-target stream of its
// (level, target level) pair as a second vertex stream. Plain draws are lit by a headlight
// Lambert term. Unless a mode colours the draws (colour-by-level, an override colour), each
// level is drawn run by run with its materials, shaded with glTF's metallic-roughness BRDF
// (base colour, metallic-roughness, normal, occlusion and emissive textures and factors) under
// a sun and a sky/ground ambient; single-sided materials cull back faces. Blended runs (of
// instances, view-dependent objects and HLOD nodes alike) are a pass of their own, drawn after
// all opaque geometry: one instance or node draw at a time, farthest first, depth tested but
// not written (viewer/blend_order.h).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <epoxy/gl.h>
#include <glm/glm.hpp>

#include "viewer/blend_order.h"
#include "viewer/draw_list.h"
#include "viewer/hlod_draw_list.h"
#include "viewer/hlod_node_buffers.h"
#include "viewer/proxy_draw_list.h"
#include "viewer/scene_proxy_buffers.h"
#include "viewer/mesh_buffers.h"
#include "viewer/morph_buffers.h"
#include "viewer/vd_mesh_buffers.h"

namespace lod::viewer {

struct RenderSettings {
  bool colour_by_level = false;
  bool backdrop = true;           // sky gradient and ground plane; false: flat kBackground
  bool wireframe = false;
  bool flat_normals = false;      // face normals from screen-space derivatives
  bool count_primitives = false;  // GL_PRIMITIVES_GENERATED query around the draws (waits for the GPU)
  bool colour_override = false;   // every batch in `colour`
  std::array<float, 3> colour{};
};

struct DrawStats {
  uint32_t draws = 0;
  uint64_t instances = 0;
  uint64_t triangles = 0;        // submitted: sum of index_count / 3 * instances, vd meshes included
  uint32_t vd_draws = 0;         // view-dependent objects drawn from their active mesh
  uint64_t vd_triangles = 0;     // their triangles (part of `triangles`)
  uint64_t terrain_triangles = 0;  // the frame's terrain mesh (part of `triangles`)
  uint32_t morph_draws = 0;      // batches drawn blending towards a coarser level
  uint32_t hlod_draws = 0;       // HLOD node layers and boundary patches drawn
  uint64_t hlod_triangles = 0;   // their triangles (part of `triangles`)
  uint32_t hlod_missing = 0;     // cut entries whose node could not be read (not drawn)
  uint32_t proxy_draws = 0;      // scene HLOD proxies drawn
  uint64_t proxy_triangles = 0;  // their triangles (part of `triangles`)
  int64_t gpu_primitives = -1;   // what the GL counted, when count_primitives; else -1
};

// Which runs a draw_range call draws: opaque and masked ones, or blended ones.
enum class RunPass { opaque, blend };

class InstanceRenderer {
 public:
  InstanceRenderer() = default;
  ~InstanceRenderer();
  InstanceRenderer(const InstanceRenderer&) = delete;
  InstanceRenderer& operator=(const InstanceRenderer&) = delete;

  // Compiles the shaders; false with the driver's log in `message`.
  bool init(std::string* message);
  // Draws the opaque and masked runs of the list's instances from `meshes` (blended batches
  // with target streams from `morphs`; null draws every batch unblended at its level) and of its
  // view-dependent objects (list.vd) from `vd`, which holds the same frame's vd meshes; `vd` may
  // be null when list.vd is empty. Alpha BLEND runs are left to draw_blended().
  DrawStats draw(const DrawList& list, const MeshBuffers& meshes, MorphBuffers* morphs, const VdMeshBuffers* vd,
                 const glm::mat4& view, const glm::mat4& projection, const RenderSettings& settings);
  // Adds the HLOD cut's draws (nodes from `nodes`, prepared for the same list) to `stats`;
  // colour-by-level colours a node by its octree depth. Opaque and masked runs only.
  void draw_hlod(const HlodDrawList& list, const HlodNodeBuffers& nodes, const glm::mat4& view,
                 const glm::mat4& projection, const RenderSettings& settings, DrawStats& stats);
  // The frame's blended pass, after everything opaque (instances, view-dependent objects, HLOD
  // nodes, proxies, terrain) is drawn: the alpha BLEND runs of the same frame's `list` (drawn by
  // draw() just before, whose instance records it reuses) and HLOD cut `hlod` (may be null, as
  // may `nodes`), farthest draw first, depth test on and depth writes off. Nothing when a mode
  // colours the draws. Adds the GPU's primitive count to `stats` when asked.
  void draw_blended(const DrawList& list, const MeshBuffers& meshes, MorphBuffers* morphs, const VdMeshBuffers* vd,
                    const HlodDrawList* hlod, const HlodNodeBuffers* nodes, const glm::mat4& view,
                    const glm::mat4& projection, const RenderSettings& settings, DrawStats& stats);
  // Adds the frame's scene proxies (world space) to `stats`; colour-by-level: by octree depth.
  void draw_proxies(const ProxyDrawList& list, const SceneProxyBuffers& proxies, const glm::mat4& view,
                    const glm::mat4& projection, const RenderSettings& settings, DrawStats& stats);

 private:
  void set_frame_uniforms(const glm::mat4& view, const glm::mat4& projection, const RenderSettings& settings);
  // Program state shared by the HLOD and proxy draws; starts the primitive query if asked.
  void begin_mesh_draws(const glm::mat4& view, const glm::mat4& projection, const RenderSettings& settings);
  void end_mesh_draws(const RenderSettings& settings, DrawStats& stats);
  void set_plain_surface(const std::array<float, 3>& colour);
  void set_material(const GpuMaterial& material);
  void draw_batch(const DrawBatch& b, const MeshBuffers& meshes, MorphBuffers* morphs, const RenderSettings& settings,
                  RunPass pass, DrawStats& stats);
  void draw_hlod_node(const HlodDraw& d, const HlodNodeGpu& g, const HlodNodeRange& r,
                      const std::vector<GpuMaterial>& materials, const RenderSettings& settings, RunPass pass);
  void draw_range(const MeshBuffers& meshes, const LevelRange& r, uint32_t instances, int32_t base_vertex,
                  const RenderSettings& settings, RunPass pass);
  void bind_vd_meshes(const VdMeshBuffers& vd, const std::array<float, 3>& colour);
  void draw_vd_object(const DrawList& list, const VdDraw& d, const MeshBuffers& meshes, const RenderSettings& settings,
                      const std::array<float, 3>& colour, RunPass pass);

  GLuint program_ = 0;
  GLuint instance_vbo_ = 0;
  GLuint query_ = 0;
  size_t instance_capacity_ = 0;
  std::vector<uint8_t> range_blends_;    // scratch: per layout range, has a blended run (this frame's batches)
  std::vector<uint8_t> vd_blends_;       // scratch: per DrawList::vd, has a blended run
  std::vector<uint8_t> hlod_blends_;     // scratch: per HlodDrawList::draws, has a blended run
  std::vector<BlendDraw> blend_order_;   // scratch: the blended pass, farthest first
  GLint u_view_ = -1, u_projection_ = -1, u_colour_ = -1, u_flat_ = -1, u_show_morph_ = -1, u_blend_ = -1;
  GLint u_alpha_ = -1, u_alpha_cutoff_ = -1, u_textured_ = -1, u_normal_mapped_ = -1, u_normal_scale_ = -1;
  GLint u_vertex_colours_ = -1;
  GLint u_pbr_ = -1, u_metallic_ = -1, u_roughness_ = -1, u_mr_mapped_ = -1, u_occlusion_mapped_ = -1;
  GLint u_occlusion_strength_ = -1, u_emissive_ = -1, u_emissive_mapped_ = -1, u_sun_view_ = -1, u_up_view_ = -1;
};

}  // namespace lod::viewer
