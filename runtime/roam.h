// ROAM: real-time optimally adapting meshes over a height field (Duchaineau et al. 1997).
// Duchaineau, Wolinsky, Sigeti, Miller, Aldrich, Mineev-Weinstein, "ROAMing Terrain: Real-time
// Optimally Adapting Meshes", IEEE Visualization 1997: bintree triangles, split with forced
// splits of the base neighbour, merge of diamonds, nested world-space error bounds (wedgies),
// a split queue and a merge queue keyed by projected error, frame-to-frame coherence.
//
// Grid: one (2^n + 1)-square height field (resample_square() makes one from any field), cut by
// its (0,0)-(M,M) diagonal into the two base bintree triangles, M = 2^n.
// Diamonds, not a pointer pool: a bintree triangle and its base neighbour form a diamond, and
// every diamond is addressed by the sample at the midpoint of their shared base (its centre),
// so the bintree is implicit in the grid: the pool is one flag per sample. Splitting a diamond
// splits both of its triangles; a diamond may be split only when the diamonds centred at its
// two apices (its parents) are split, and splitting one forces its parents first -- Duchaineau's
// forced split of the base neighbour. Border diamonds have one triangle. With this invariant no
// crack or T-junction can appear (check_terrain_mesh() verifies it from the triangles alone).
//
// Error bounds: error[d] = max(|h(centre) - mean h(base ends)|, error of its 4 children), the
// nested wedgie thickness, in world units, computed bottom-up once; each diamond also has a
// bounding sphere around its centre sample that contains its children's spheres. Projected
// error = error * focal_pixels / max(distance to the sphere, near plane), 0 when the sphere is
// outside the frustum (culled subtrees stay coarse). Both nestings make the projected error of a
// parent >= its children's, so forced splits never contradict the queue order.
//
// Frame update: the split queue holds the unsplit diamonds whose parents are split (their
// triangles are in the mesh), the merge queue the split diamonds with no split child. Each frame
// re-keys at most those two fronts (O(mesh), not O(grid)) and then splits and merges from where
// the last frame stopped, so the work follows the changes. (Duchaineau's deferred re-keying by
// camera-speed bounds is done exactly for the pixel-error target while the camera translates
// without turning: each front diamond gets the travel distance within which neither its
// distance test nor its frustum test can cross (both are 1-Lipschitz in the eye position), and
// only the diamonds whose distance has run out are re-keyed; a turn, a zoom or the
// triangle-count target re-keys the whole front.)
// Pure functions over RoamState: no threads, no I/O; after roam_reset() no allocation (the
// queues are reserved for every diamond; roam_triangles() reuses the caller's vector; the
// events log grows to the largest frame's changes once).
#pragma once
#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <vector>

#include "runtime/height_field.h"
#include "runtime/view.h"

namespace lod {

// The immutable part, built once from the height field and shared by every state.
struct RoamTerrain {
  uint32_t levels = 0;               // n
  uint32_t size = 0;                 // samples per side, 2^n + 1; diamond id = sample index y * size + x
  std::vector<glm::vec3> positions;  // world position of every sample (x, height, y)
  std::vector<float> error;          // nested wedgie thickness per diamond, world units
  std::vector<float> radius;         // nested bounding-sphere radius around positions[d]
  std::vector<std::array<int32_t, 2>> parents;   // -1: none (root, border)
  std::vector<std::array<int32_t, 4>> children;  // -1: outside the grid or below the finest
  std::vector<uint8_t> triangles;  // bintree triangles in the diamond: 2, 1 on the border, 0 corner
  int32_t root = 0;
};

enum class RoamTarget : uint8_t {
  pixel_error,     // every visible leaf's projected error <= pixel_error (optionally capped)
  triangle_count,  // target - 2 <= triangles <= target: within one diamond of the target
  time_limit,      // the finest mesh max_ms allows: the triangle_count loop (largest errors first), stopped by the clock
};

// A clock the caller lends for a time limit: runtime/ reads none itself, so tests can drive
// one. now_ms(context) is monotonic, in milliseconds from any origin.
struct RoamClock {
  double (*now_ms)(const void* context) = nullptr;
  const void* context = nullptr;
};

struct RoamParams {
  RoamTarget target = RoamTarget::pixel_error;
  float pixel_error = 1.f;              // tau, pixels
  uint32_t triangle_count = 20000;      // the target in triangle_count mode
  uint32_t max_triangles = UINT32_MAX;  // pixel_error mode: splits stop at this many triangles
  uint32_t max_operations = 1u << 22;   // splits + merges per frame (a time limit, in work)
  // With a clock, any target: splits and merges stop once max_ms have passed since the update
  // began (re-keying included), checked every kRoamClockStride operations; the next frame goes
  // on from there. Pixel-error splits and merges then alternate, so a frame cut short has done
  // some of both. 0 = no limit.
  float max_ms = 0;
  RoamClock clock;
};

// Operations between two clock reads under a time limit (a read costs ~20 ns, a split ~100 ns).
inline constexpr uint32_t kRoamClockStride = 32;

// One indexed binary heap over diamond ids; sign = +1 keeps the largest priority on top (split
// queue), -1 the smallest (merge queue). slot[d] = position in heap, -1 when absent.
struct RoamQueue {
  std::vector<int32_t> heap;
  std::vector<int32_t> slot;
  float sign = 1;
};

struct RoamFrameStats {
  uint32_t splits = 0;  // including forced splits
  uint32_t merges = 0;
  uint32_t rekeyed = 0;  // front diamonds whose priority was recomputed
  uint32_t triangles = 0;
  uint8_t budget_bound = 0;  // 1: max_operations, max_triangles or max_ms stopped the update early
  uint8_t time_bound = 0;    // 1: it was max_ms
};

struct RoamState {
  std::vector<uint8_t> split;   // per diamond
  std::vector<float> priority;  // per diamond in either queue: projected error, pixels
  RoamQueue split_queue;        // sign +1
  RoamQueue merge_queue;        // sign -1
  uint32_t triangle_count = 2;
  uint32_t splits = 0, merges = 0;  // running totals
  // The view the priorities were computed for (roam_set_view).
  glm::vec3 eye{0};
  float focal = 1, near_plane = 0.1f;
  Frustum frustum{};
  // Deferred re-keying (pixel-error target, camera translating without turning): a front
  // diamond's split/merge decision cannot change before the camera has travelled `slack`
  // metres, so it is re-keyed only when the travel passes its deadline.
  uint8_t defer = 0;            // 1: deadlines are kept for the front
  float tau = 0;                // the pixel error the deadlines were computed for
  float travel = 0;             // metres the eye moved since deferral started
  View anchor{};                // the view whose orientation the deadlines assume
  std::vector<float> deadline;  // per front diamond: travel at which to re-key it
  RoamQueue deadline_queue;     // sign -1 over deadline: the soonest first
  // This update's changes in order, for geomorphing (runtime/terrain_morph.h): a split of d
  // is logged as d, a merge as ~d; roam_update clears it first.
  std::vector<int32_t> events;
};

// True when a width x height field can be a ROAM grid: square, 2^n + 1 with 1 <= n <= 15.
bool roam_size_valid(uint32_t width, uint32_t height);
// Precondition: roam_size_valid(field.width, field.height).
RoamTerrain build_roam_terrain(const HeightField& field);

// The coarsest mesh (the two base triangles); sizes every array once.
void roam_reset(RoamState& state, const RoamTerrain& terrain);
// Takes the view (eye, focal length, frustum) later priorities are computed for.
void roam_set_view(RoamState& state, const View& view);
// Projected error of one diamond for the state's view, pixels (0 when culled).
float roam_projected_error(const RoamState& state, const RoamTerrain& terrain, int32_t diamond);

// Splits a diamond, forcing its parents first; no-op when already split.
void roam_split(RoamState& state, const RoamTerrain& terrain, int32_t diamond);
// Merges a split diamond none of whose children is split (a member of the merge queue).
void roam_merge(RoamState& state, const RoamTerrain& terrain, int32_t diamond);

// One frame: takes the view, re-keys both fronts, then splits and merges to the target from the
// previous frame's mesh. Calling it on a fresh roam_reset() state is the from-scratch build.
RoamFrameStats roam_update(RoamState& state, const RoamTerrain& terrain, const View& view,
                           const RoamParams& params);

// The mesh: 3 sample indices per triangle, (apex, base end, base end), counter-clockwise in
// grid (x, y) coordinates; the diamond split next in a triangle is centred at the midpoint of
// its base ends. Appends to `indices` after clearing it; returns the triangle count.
size_t roam_triangles(std::vector<uint32_t>& indices, const RoamState& state, const RoamTerrain& terrain);
// The same mesh without the subtrees whose bounding sphere is outside the state's frustum (the
// draw list; the culled triangles are coarse already since culled diamonds have priority 0).
size_t roam_visible_triangles(std::vector<uint32_t>& indices, const RoamState& state,
                              const RoamTerrain& terrain);
// The same mesh for an explicit split flag per sample (e.g. ROAM's splits plus merges still
// geomorphing); the flags must be closed under parents (a flagged diamond's parents flagged).
size_t roam_triangles_of(std::vector<uint32_t>& indices, std::span<const uint8_t> split, const RoamTerrain& terrain);
// A diamond's base ends (the samples its centre splits the base between) and its depth in the
// bintree (root 0, finest 2n - 1): a diamond's base ends are vertices of coarser depth.
std::array<int32_t, 2> roam_base_ends(const RoamTerrain& terrain, int32_t diamond);
int roam_depth(const RoamTerrain& terrain, int32_t diamond);

// The diamond a mesh triangle belongs to (centred at the midpoint of its base, indices 1 and
// 2), or -1 for a finest-level triangle, which cannot be split.
int32_t roam_diamond_of(const RoamTerrain& terrain, uint32_t base_a, uint32_t base_b);

}  // namespace lod
