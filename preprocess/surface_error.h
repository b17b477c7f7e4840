// Object-space distance between two triangle surfaces: an approximation of the symmetric
// Hausdorff distance H(A,B) = max(h(A,B), h(B,A)), h(A,B) = max_a min_b |a - b|,
// measured at every vertex plus dense area-weighted surface samples of each mesh, with
// closest-point queries (Embree; no Embree type appears here).
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "runtime/status.h"

namespace lod {

// A triangle mesh as borrowed flat arrays.
struct TriangleMeshView {
  const float* positions = nullptr;  // xyz per vertex
  size_t vertex_count = 0;
  const uint32_t* indices = nullptr; // 3 per triangle
  size_t index_count = 0;
};

struct SurfaceErrorSettings {
  size_t surface_samples = 50000;  // per mesh and direction, on top of every vertex
  uint64_t seed = 1;
};

struct SurfaceError {
  float max = 0;        // symmetric Hausdorff approximation
  float rms = 0;        // over all samples of both directions
  size_t samples = 0;   // distance queries made
};

// Holds the reference surface (level 0) ready for queries, so that every level of a chain
// is measured against it without rebuilding. Not thread-safe; one meter per thread.
class SurfaceErrorMeter {
 public:
  SurfaceErrorMeter();
  ~SurfaceErrorMeter();
  SurfaceErrorMeter(const SurfaceErrorMeter&) = delete;
  SurfaceErrorMeter& operator=(const SurfaceErrorMeter&) = delete;

  // Copies what it needs from `reference`. `what` names it in messages.
  Status set_reference(const TriangleMeshView& reference, const SurfaceErrorSettings& settings,
                       const std::string& what);
  // Distance between `mesh` and the reference, both directions.
  Status measure(const TriangleMeshView& mesh, SurfaceError& out);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// n^3 cubic cells over a cube (x fastest), to say which part of a surface a SurfaceDistance holds.
struct SurfaceGrid {
  float lo[3] = {0, 0, 0};  // the cube's lowest corner
  float edge = 1;           // the cube's edge
  uint32_t n = 1;
  size_t cells() const { return size_t(n) * n * n; }
  // The cell holding coordinate x on `axis`, clamped into the grid (monotonic in x).
  uint32_t cell(float x, int axis) const;
};

// A box on a SurfaceGrid: the cells [lo, hi] reaches into.
struct SurfaceBox {
  float lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
};

// Parts of one surface chosen in one pass over it: per box, every triangle whose box reaches
// into one of the box's cells, so that the part built from that list holds each of those cells
// completely (SurfaceDistance::set_surface_planned). Many small parts instead of one large one:
// an HLOD build holds only the parts of the subtrees it is measuring, not a BVH of the whole.
struct SurfacePartPlan {
  SurfaceGrid grid;
  float slack = 0;                               // the whole surface's rounding slack
  size_t vertex_count = 0, triangle_count = 0;  // of the whole surface
  std::vector<SurfaceBox> boxes;
  std::vector<std::vector<uint32_t>> triangles;  // per box, ascending
};
// The plan for `boxes` over `whole` (its indices checked here). `what` names it in messages.
Status plan_surface_parts(const TriangleMeshView& whole, const SurfaceGrid& grid, std::vector<SurfaceBox> boxes,
                          SurfacePartPlan& out, const std::string& what);

// How a held surface's BVH is built. The answers never depend on it (every query visits all
// triangles within rounding of the nearest, on any BVH); only the build's and queries' time do.
enum class BvhBuilder : uint8_t {
  morton,  // Embree's Morton-code builder: on the 13.9M dragon 2.9x faster to build than sah
  sah,     // binned SAH: a tighter tree, queries up to ~10 % faster (bench_mesh_input)
};

// One surface held for closest-point queries from many threads at once (HLOD builds measure
// every node's layers against one original). The const members are thread-safe.
//
// A part (set_surface_part) holds only the triangles of a whole surface that reach into some
// wanted cells, and knows which cells it holds completely (no other triangle reaches in). A
// query found nearest within complete cells is provably the whole surface's answer, to the bit
// (every query visits all triangles within float rounding of the nearest, on any BVH).
class SurfaceDistance {
 public:
  explicit SurfaceDistance(BvhBuilder builder = BvhBuilder::morton);
  ~SurfaceDistance();
  SurfaceDistance(const SurfaceDistance&) = delete;
  SurfaceDistance& operator=(const SurfaceDistance&) = delete;

  // Copies `surface` into a BVH. `what` names it in messages.
  Status set_surface(const TriangleMeshView& surface, const std::string& what);
  // Copies the triangles of `whole` whose box reaches into a `wanted` cell (grid.cells() flags;
  // a triangle spanning very many cells is always kept). No triangle: every query unanswered.
  Status set_surface_part(const TriangleMeshView& whole, const SurfaceGrid& grid, const std::vector<uint8_t>& wanted,
                          const std::string& what);
  // The part `plan` (made over `whole`) lists for its box `box`: the box's cells held completely.
  // `remap`: whole.vertex_count entries of scratch, all UINT32_MAX (filled so when empty), and
  // left so. Reuses this object's Embree device and arrays from part to part.
  Status set_surface_planned(const TriangleMeshView& whole, const SurfacePartPlan& plan, size_t box,
                             std::vector<uint32_t>& remap, const std::string& what);
  // Whether a surface (or part) was set: queries and from_points_to may be made.
  bool ready() const;
  // Triangles held (a part's; the whole surface's otherwise).
  size_t triangles() const;
  // A part: whether the cell holding p is held completely (a caller choosing points to ask about).
  bool holds(const float* p) const;
  // Distance from each of `count` points (xyz) to the held surface: max into out.max,
  // RMS into out.rms (samples = count). `known` (optional, one per point): a distance the
  // surface is known to be within (e.g. to a surface vertex the point came from), so the
  // query starts small; +inf where nothing is known, 0 for a point of the surface itself.
  Status from_points(const float* points, size_t count, const float* known, SurfaceError& out) const;
  // The same to `mesh` instead, whose BVH is built on the held surface's Embree device for
  // this call only (a small layer measured from the original's samples).
  Status from_points_to(const TriangleMeshView& mesh, const float* points, size_t count, const float* known,
                        SurfaceError& out) const;
  // from_points on a part: a point it cannot answer exactly as the whole surface would goes to
  // whole() (from any thread, possibly several at once; it returns the whole surface, ready, or
  // null on failure) or, when `whole` is empty, is left out of `out` (answered[i] = 0; answered
  // may be null then only if every point is sure to be answered).
  Status from_points_part(const float* points, size_t count, const float* known,
                          const std::function<const SurfaceDistance*()>& whole, SurfaceError& out,
                          std::vector<uint8_t>* answered) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// One-off convenience: symmetric distance between a and b.
Status measure_surface_error(const TriangleMeshView& a, const TriangleMeshView& b,
                             const SurfaceErrorSettings& settings, SurfaceError& out);

}  // namespace lod
