// HLOD cut selection (Zhou and Tian 3.3) with residency ("never a hole", as Cesium's tile selection) and
// a triangle budget (Yu, Liang and Chen's "undo the least important refinement first").
//
// The error test, fixed once. Zhou and Tian: a layer of object-space error e is drawn when
//   e <= E = d * (P / N) * tan(theta)
// with N pixels spanning the angle theta. Here both are taken on the vertical axis from the
// view centre to its edge: theta = fovy / 2 and N = H / 2, so N / tan(theta) is
// focal_pixels(view) and E = d * P / focal. That is exactly Cesium's screen-space error test
//   sse = e * H / (d * 2 tan(fovy / 2)) <= P
// (tests/unit/runtime/hlod_select_test.cpp, HlodSelect.ThresholdEqualsCesiumScreenSpaceError).
// e is scaled by the object's uniform scale; d is the distance from the eye to the node's
// world bounding sphere, 0 inside it (then only an exact layer, e = 0, passes).
//
// The cut, defined recursively from the root (hlod_select_test.cpp holds this definition
// as its brute-force reference):
//   - a node outside the frustum is *culled*: nothing of it is drawn, requested or opened
//     (Cesium does the same). Its bounds lie wholly outside one frustum plane, so no visible
//     pixel is left uncovered; `culled` lists them for validators that check closed cuts.
//     With HlodCulledNodes::cover a non-root node outside is instead drawn at its coarsest
//     layer, requested last, and waited for like a visible child: a closed cut.
//   - a visible node that is not resident is *requested*; its parent stays drawn.
//   - a visible resident node *wants* its coarsest layer with e <= E; a leaf with none wants
//     its finest; an inner node with none wants to open. It is *opened* only when every
//     visible child is resident (so every child is drawn or opened in turn): the parent
//     stays drawn, at its finest layer, until all the children that replace it are loaded.
//   - children of an opened node are visited; children of a drawn node are not, except that
//     a drawn node that wanted to open still has its resident children visited, so the cut
//     requests what it will need next (their draws are not part of the cut).
// Budget: when the cut's triangles (drawn layers + opened nodes' boundary patches) exceed
// params.triangle_budget, refinements are undone one at a time, the one whose undoing shows
// the smallest screen-space error first: a drawn node one layer coarser, or an opened node
// whose visible children are all drawn closed again (drawn at its finest layer). It stops when
// the cut fits or the root is drawn at its coarsest layer (the smallest cut; `over_budget`).
// Far over the budget the same steps are taken the other way round (HlodBudgetPass): from
// the root at its coarsest, largest error first, until the next step would not fit.
//
// Not sub-range safe: one call selects one tree's whole cut. No threads, clocks or I/O; after
// prepare_hlod_cut no allocation either (the outputs and scratch keep their capacity).
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "lodkit/types.hpp"
#include "runtime/hlod_tree.h"
#include "runtime/view.h"

namespace lod {

struct HlodView {
  glm::vec3 eye{0, 0, 0};
  float focal_px = 1;  // (H / 2) / tan(fovy / 2), focal_pixels(view)
  Frustum frustum{};
  bool cull = true;  // false: every node counts as inside the frustum
};
HlodView hlod_view_of(const View& v);

// How the budget is met. Both passes take the same steps in opposite orders, so they give the
// same cut whenever every undo lowers the triangle count (errors and triangle counts
// monotonic up the tree); `automatic` takes the one with fewer steps.
enum class HlodBudgetPass : uint8_t {
  automatic,  // undo when the wanted cut is under twice the budget, else refine
  undo,       // from the wanted cut, undo the smallest-error refinement first
  refine,     // from the root at its coarsest, refine the largest-error step first
};

// What becomes of a non-root node outside the frustum.
enum class HlodCulledNodes : uint8_t {
  skip,  // culled: nothing drawn or requested, no opening waits for it (Cesium)
  // Covered: drawn at its coarsest layer (never opened), requested after every visible node
  // when missing, and its parent opens only once it is resident, like a visible child. The
  // whole cut stays closed (every boundary edge shared by two drawn triangles), for
  // validation, shadow views or a camera that turns fast, at the price of invisible triangles.
  cover,
};

struct HlodSelectParams {
  float pixel_error = 1;                  // P, pixels
  uint64_t triangle_budget = UINT64_MAX;  // this cut's share of M
  HlodBudgetPass budget_pass = HlodBudgetPass::automatic;
  HlodCulledNodes culled = HlodCulledNodes::skip;
};

struct HlodDraw {
  uint32_t node;
  uint8_t layer;
};

// A node the cut wants that is not resident. Streaming loads the largest deficit first,
// then the nearest.
struct HlodRequest {
  uint32_t node;
  float deficit;   // pixels: screen-space error shown in its place (its parent's finest layer) - P;
                   // -FLT_MAX for a covered node outside the frustum, FLT_MAX for the root
  float distance;  // eye to its world bounds
};
// True when a is loaded before b (larger deficit, then nearer, then lower id).
bool request_before(const HlodRequest& a, const HlodRequest& b);

struct HlodCut {
  std::vector<HlodDraw> drawn;        // breadth-first order
  std::vector<uint32_t> opened;       // their boundary patches are drawn
  std::vector<uint32_t> culled;       // visited, outside the frustum, not covered
  std::vector<HlodRequest> requests;  // sorted by request_before
  // Resident nodes the cut visited (drawn, opened, or waiting for a sibling): what streaming
  // must keep. Ids in visiting order.
  std::vector<uint32_t> kept;
  uint64_t triangles = 0;         // drawn layers + opened boundaries, after the budget
  uint64_t wanted_triangles = 0;  // the same before the budget
  uint32_t undone = 0;            // refinements the budget undid
  uint32_t holes = 0;             // requested nodes with no drawn ancestor (only a missing root)
  bool over_budget = false;       // the smallest cut still exceeds the budget
};

// Per-node scratch, reused frame to frame.
struct HlodCutScratch {
  std::vector<float> distance;         // world
  float sse_numerator = 0;             // focal * scale: sse = e * sse_numerator / distance
  std::vector<uint8_t> state;          // detail::HlodNodeState
  std::vector<uint8_t> layer;          // drawn layer
  std::vector<uint8_t> wanted_layer;   // before the budget (refine pass)
  std::vector<uint8_t> open_children;  // opened children of an opened node
  std::vector<uint32_t> queue;         // breadth-first visiting order
  std::vector<uint64_t> heap;          // budget steps: error bits << 32 | ~node
};

// Sizes the outputs and the scratch for `tree` (the only allocation).
void prepare_hlod_cut(HlodCut& cut, HlodCutScratch& scratch, const HlodTree& tree);

// `resident[i]` != 0 when node i's payload is loaded. Returns the number of nodes drawn.
uint32_t select_hlod_cut(HlodCut& cut, HlodCutScratch& scratch, const HlodTree& tree,
                         std::span<const uint8_t> resident, const Transform& transform, const HlodView& view,
                         const HlodSelectParams& params);

// E = d * P / focal (see above): the largest object-space error (times scale) drawable at d.
inline float hlod_error_threshold(float distance, float pixel_error, float focal_px) {
  return distance * pixel_error / focal_px;
}

}  // namespace lod
