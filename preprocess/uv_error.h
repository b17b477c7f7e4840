// Texture-coordinate error of a simplified surface against its original, in texels: for
// sample points on the level's surface (every vertex a triangle uses plus area-weighted random
// points), the distance between the level's interpolated uv there and the original surface's
// uv at the closest point of the original (Embree closest-point queries; no Embree type
// appears here), scaled by the base colour texture's width and height.
//
// On a uv seam the closest point lies on two triangles at once (or on both sides within
// rounding), whose uvs differ by the seam's jump: every original triangle within the closest
// distance (plus a tie tolerance) is a candidate, and the smallest uv distance counts, so a
// level that kept its seam is not charged the seam.
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "runtime/status.h"

namespace lod {

struct UvMeshView {
  const float* positions = nullptr;  // xyz per vertex
  const float* uvs = nullptr;        // uv per vertex
  size_t vertex_count = 0;
  const uint32_t* indices = nullptr;  // 3 per triangle
  size_t index_count = 0;
};

struct UvErrorSettings {
  size_t surface_samples = 50000;  // per level, on top of every vertex
  uint64_t seed = 1;
  double texture_width = 1024, texture_height = 1024;  // texels per uv unit
  // Triangles of the original this much farther than the closest (relative to the
  // original's bounding-box diagonal) still count as at the closest point.
  double tie_tolerance = 1e-5;
};

struct UvError {
  double rms = 0, mean = 0, max = 0;  // texels
  size_t samples = 0;
};

// Holds the original surface and its uvs for queries; measures each level against it.
// Not thread-safe; one meter per thread.
class UvErrorMeter {
 public:
  UvErrorMeter();
  ~UvErrorMeter();
  UvErrorMeter(const UvErrorMeter&) = delete;
  UvErrorMeter& operator=(const UvErrorMeter&) = delete;

  // Copies `original` (indices checked against its vertices). `what` names it in messages.
  Status set_reference(const UvMeshView& original, const UvErrorSettings& settings, const std::string& what);
  Status measure(const UvMeshView& level, UvError& out) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lod
