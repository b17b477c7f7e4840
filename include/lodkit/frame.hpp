// Frame: what one pass of the per-frame graph publishes for a consumer (renderer, viewer).
// Part of the public API: plain columns, one entry per visible object, no library types.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "lodkit/types.hpp"

namespace lod {

// The frame graph's nodes (FrameGraph::dot() shows their edges); Frame::stage_ms per node.
enum class Stage : uint8_t {
  commit, bounds, view, visibility, importance, selection, entries, geomorph, vdlod, vd_mesh, hlod, scene_hlod,
  terrain, publish, count
};
inline constexpr const char* kStageNames[] = {"commit",   "bounds",   "view",  "visibility", "importance", "selection",
                                              "entries",  "geomorph", "vdlod", "vd_mesh",    "hlod",       "scene_hlod",
                                              "terrain",  "publish"};
inline constexpr std::size_t kStageCount = static_cast<std::size_t>(Stage::count);
inline constexpr std::size_t kHistogramLevels = 32;  // histogram bins by l = round(log2 tris)

// One view-dependent object's active mesh in a Frame (runtime/vertex_front.h): what a renderer
// draws instead of a discrete level. Positions are object space and already geomorphed.
// Frame::vd_normals holds a unit (or zero) normal per vertex: with authored normals in the tree
// (has_authored_normals), its geomorphed normals renormalised; else a smooth normal computed
// from the shown (geomorphed) faces, so shading morphs with the shape and hard edges (split
// vertex copies) stay hard.
// With uvs (has_uvs), Frame::vd_uvs holds one per vertex, geomorphed with the positions; so do
// Frame::vd_uvs1 (glTF TEXCOORD_1, has_uvs1) and Frame::vd_colors (glTF COLOR_0, linear RGBA,
// has_colors; multiply it into the base colour, as glTF does); with
// materials, the object's triangles come grouped by material, run_count runs from first_run of
// Frame::vd_runs (in material order), which cover its indices in order.
struct VdRunFrame {
  uint32_t first_index = 0;  // into Frame::vd_indices (the object's indices are among them)
  uint32_t index_count = 0;  // 3 per triangle
  int32_t material = -1;     // the chain's material, -1 = the default surface
};
struct VdObjectFrame {
  uint32_t object = 0;        // Frame::objects value of this object (its entry is `entry`)
  uint32_t entry = 0;         // index of its entry in the frame's per-entry columns
  uint32_t first_vertex = 0;  // into Frame::vd_positions, in vertices
  uint32_t vertex_count = 0;
  uint32_t first_index = 0;   // into Frame::vd_indices; indices are local to this object's vertices
  uint32_t index_count = 0;   // 3 per triangle
  uint32_t splits = 0;        // this frame
  uint32_t collapses = 0;
  uint32_t moving = 0;        // vertices still geomorphing
  float threshold = 0;        // pixel threshold after this frame's feedback
  bool closed = false;        // the object's full mesh is closed (every edge in two faces)
  bool oriented = false;      // ... consistently oriented (each directed edge once)
  bool has_uvs = false;       // its vertices' uvs are in Frame::vd_uvs
  bool has_uvs1 = false;      // ... second uvs in Frame::vd_uvs1
  bool has_colors = false;    // ... colours in Frame::vd_colors
  bool has_authored_normals = false;  // Frame::vd_normals are the tree's (authored), not computed
  uint32_t first_run = 0;     // into Frame::vd_runs; run_count == 0: no materials (one surface)
  uint32_t run_count = 0;
};

// One node of an HLOD model's cut (models with hlod = true, numbered in config order among
// them): draw layer `layer` of node `node` (HlodTree order), placed by the model's transform.
struct HlodDrawFrame {
  uint32_t model = 0;
  uint32_t node = 0;
  uint8_t layer = 0;  // 0 = the node's finest
};
// A node of the cut replaced by its children: draw its boundary patch.
struct HlodOpenedFrame {
  uint32_t model = 0;
  uint32_t node = 0;
};

// A node of an HLOD model that could not be read (a payload failing its checksum, a truncated
// file, the storage's error); never read again, its parent stays drawn. The message names the
// file, the node and why: "/cache/scene-1f2e.hlod: node 17: payload checksum mismatch (the file
// is damaged)". A damaged cache entry is marked bad and rebaked by the next run (it says so).
struct HlodFailedFrame {
  uint32_t model = 0;
  uint32_t node = 0;
  std::string message;
};

struct Frame {
  uint64_t index = 0;   // frame number, increasing
  uint64_t tick = 0;    // the tick of the last commit this frame was computed from
  double time_s = 0;    // service clock (seconds of step(dt) or of free-running) at this frame
  uint32_t view_count = 1;
  std::array<Camera, kMaxViews> views{};  // the views it was computed for (first view_count)

  // One entry per visible object, in the service's object order (which changes as objects
  // come and go: use `handles` to follow an object from frame to frame).
  std::vector<ObjectHandle> handles;   // the object's handle
  std::vector<uint32_t> models;        // its model
  std::vector<Transform> transforms;   // the transform this frame was computed with
  std::vector<uint8_t> view_masks;     // bit v set: view v sees it (never_cull: every view)
  std::vector<uint32_t> objects;       // its dense index in the service at this frame
  std::vector<uint8_t> levels;    // chain level index (0 = full detail); a chain's culled level
                                  // (a last ratio of 0, no triangles) means: not drawn
  std::vector<float> morph;       // geomorph factor in [0, 1] towards `levels` (1 = settled)
  // Level each object morphs FROM (equal to `levels` once settled, and always for view-dependent
  // objects, which draw their active mesh, and for chains without morph targets). To blend, a renderer draws the FINER of (from, to)
  // with every vertex at mix(own, target in the coarser level, w), the targets composed through
  // the levels in between (i -> i+1 -> ... -> j, LodChain::morph_targets); w = morph when the
  // object coarsens (from < to) and 1 - morph when it refines, so morph 0 looks exactly like
  // the old level and morph 1 exactly like the new one. Going back mid-morph to the level it
  // came from continues from the same shape (morph restarts at 1 - morph); any other change in
  // mid-morph starts from the level the object was heading to.
  std::vector<uint8_t> from_levels;

  uint32_t object_count = 0;      // live objects at this frame's tick
  uint32_t visible = 0;
  uint64_t tris_in_view = 0;    // visible objects at full detail
  uint64_t tris_selected = 0;
  uint32_t morphing = 0;         // visible objects blending two levels (from_levels != levels)
  uint64_t tris_morph_extra = 0; // what drawing their finer level adds to tris_selected
  // Held back from M by selection for last frame's blends (triangle budgets; at most M / 2):
  // tris_selected <= budget - budget_morph_reserve unless over_budget.
  uint64_t budget_morph_reserve = 0;
  uint64_t level_cost = 0;      // sum of 2^l over visible objects
  uint64_t budget = 0;          // M
  uint64_t coarsest_cost = 0;   // cost with all visible objects at their coarsest level
  bool over_budget = false;     // even the coarsest levels exceed M
  uint32_t lowered_steps = 0;   // heap pops in selection
  uint32_t levels_lowered = 0;  // levels lowered by selection (= lowered_steps for one level per pop)
  // Not drawn: entries at their chain's culled level, plus objects in view 0's frustum beyond
  // lod.max_distance (those have no entry).
  uint32_t culled = 0;
  uint32_t level_changes = 0;   // entries visible last frame at another level
  // Selection quality for view 0 (runtime/selection_quality.h): the summed benefit of the
  // selected levels, and the screen-space error in pixels they leave, worst and mean. Measured
  // for services made from a config (Service::from_config, lod run); 0 otherwise.
  double benefit = 0;
  float pixel_error_max = 0;
  float pixel_error_mean = 0;
  // The benefit above over the exact optimum of the same selection problem (the initial levels,
  // the budget selection had): measured with the benefit where a frame has <= 300 entries;
  // -1 otherwise. Exact flags a true optimum; false: against an upper bound of it (costs rounded
  // to 4,096 cells), so the fraction is never overstated (runtime/selection_oracle.h).
  double benefit_optimum_fraction = -1;
  bool benefit_optimum_exact = false;
  // Occlusion culling (view 0): objects in the frustum found hidden, occluders rasterised.
  uint32_t occluded = 0;
  uint32_t occluders = 0;
  uint64_t occluder_tris = 0;
  std::array<uint32_t, kHistogramLevels> level_histogram{};  // objects per l

  // View-dependent objects (models with view_dependent = true), visible ones only, in object
  // order; their discrete level above still says the share of the budget they were given.
  std::vector<VdObjectFrame> vd_objects;
  std::vector<float> vd_positions;   // xyz per vertex, all vd objects back to back
  std::vector<uint32_t> vd_indices;  // all vd objects back to back
  std::vector<float> vd_uvs;         // uv per vertex like vd_positions when any vd object has uvs (else empty; 0 for those without)
  std::vector<float> vd_uvs1;        // TEXCOORD_1 per vertex, as vd_uvs (0 for objects without)
  std::vector<float> vd_colors;      // linear RGBA per vertex when any vd object has colours (else
                                     // empty; white (1, 1, 1, 1) for those without)
  std::vector<float> vd_normals;     // unit normal per vertex like vd_positions: the tree's authored
                                     // ones geomorphed and renormalised when it has them, else from
                                     // the shown faces (area weighted); (0, 0, 0) where none is known
  std::vector<VdRunFrame> vd_runs;   // material runs of the vd objects with materials
  uint64_t vd_active_tris = 0;
  uint64_t vd_splits = 0;
  uint64_t vd_collapses = 0;

  // HLOD models (streamed; view 0's cut): what is drawn, what the pager holds and has done.
  std::vector<HlodDrawFrame> hlod_drawn;      // per model, breadth-first
  std::vector<HlodOpenedFrame> hlod_opened;   // their boundary patches are drawn too
  uint32_t hlod_nodes_drawn = 0;              // hlod_drawn.size()
  uint64_t hlod_tris = 0;                     // drawn layers + opened patches (in tris_selected)
  uint64_t resident_bytes = 0;                // node payloads resident, against the stream budget
  uint64_t stream_budget = 0;                 // [stream] budget_mb in bytes (0: no HLOD models)
  uint64_t stream_requests = 0;               // loads issued so far
  uint64_t stream_loads = 0;                  // loads completed so far
  uint64_t stream_evictions = 0;              // nodes evicted so far (least recently used)
  uint64_t stream_failures = 0;               // node reads failed so far (each node once; parent stays drawn)
  std::vector<HlodFailedFrame> stream_failed; // which: every one so far, in the order they failed
  uint32_t holes = 0;                         // wanted, not drawable, no drawn ancestor: must be 0

  // Scene HLOD ([scene_hlod], view 0's cut): merged proxies drawn instead of the static objects
  // they stand for, which then have no entry for view 0 (a renderer draws the proxies' meshes).
  std::vector<uint32_t> scene_proxies;  // proxy (scene HLOD node) ids, breadth-first
  uint32_t scene_proxy_objects = 0;     // objects the drawn proxies stand for
  uint64_t scene_proxy_tris = 0;        // their triangles (in tris_selected)
  // Terrain ([[terrain]]: ROAM refined for view 0, the whole bintree mesh; what lies outside
  // the frustum is coarse already). Its triangles count in tris_selected, within M.
  std::vector<float> terrain_positions;   // xyz world space per vertex
  std::vector<uint32_t> terrain_indices;  // 3 per triangle into terrain_positions (ccw in grid x, y = cw seen from +y)
  std::vector<uint32_t> terrain_samples;  // per vertex: its grid sample, y * terrain_grid + x
  uint32_t terrain_grid = 0;              // samples per grid side (0: no terrain)
  uint64_t terrain_tris = 0;
  uint64_t terrain_splits = 0;            // this frame, forced splits included
  uint64_t terrain_merges = 0;
  uint64_t terrain_share = 0;             // triangles of M the terrain was given this frame
  uint32_t terrain_morphing = 0;          // vertices geomorphing (splits rising, merges lowering)
  float terrain_pixel_error = 0;          // the largest projected error left on it, pixels
  uint8_t terrain_time_bound = 0;         // 1: its max_ms stopped ROAM's update (it goes on next frame)

  std::array<double, kStageCount> stage_ms{};  // per stage, milliseconds
  double total_ms = 0;
};

}  // namespace lod
