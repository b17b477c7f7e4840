// Object-space distance between two triangle surfaces: an approximation of the symmetric
// Hausdorff distance H(A,B) = max(h(A,B), h(B,A)), h(A,B) = max_a min_b |a - b| (R3),
// measured at every vertex plus dense area-weighted surface samples of each mesh, with
// closest-point queries (Embree; no Embree type appears here).
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

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

// One surface held for closest-point queries from many threads at once (HLOD builds measure
// every node's layers against one original). The const members are thread-safe.
class SurfaceDistance {
 public:
  SurfaceDistance();
  ~SurfaceDistance();
  SurfaceDistance(const SurfaceDistance&) = delete;
  SurfaceDistance& operator=(const SurfaceDistance&) = delete;

  // Copies `surface` into a BVH. `what` names it in messages.
  Status set_surface(const TriangleMeshView& surface, const std::string& what);
  // Distance from each of `count` points (xyz) to the held surface: max into out.max,
  // RMS into out.rms (samples = count). `known` (optional, one per point): a distance the
  // surface is known to be within (e.g. to a surface vertex the point came from), so the
  // query starts small; +inf where nothing is known, 0 for a point of the surface itself.
  Status from_points(const float* points, size_t count, const float* known, SurfaceError& out) const;
  // The same to `mesh` instead, whose BVH is built on the held surface's Embree device for
  // this call only (a small layer measured from the original's samples).
  Status from_points_to(const TriangleMeshView& mesh, const float* points, size_t count, const float* known,
                        SurfaceError& out) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// One-off convenience: symmetric distance between a and b.
Status measure_surface_error(const TriangleMeshView& a, const TriangleMeshView& b,
                             const SurfaceErrorSettings& settings, SurfaceError& out);

}  // namespace lod
