// Camera paths of a scene config: the view for frame n, a pure function of n.
#pragma once
#include <cstdint>
#include <vector>

#include "runtime/view.h"

namespace lod {

enum class PathKind : uint8_t { orbit, flythrough, keyframes };

struct CameraKeyframe {
  uint32_t frame = 0;
  glm::vec3 position{0};
  glm::vec3 look_at{0};
};

struct CameraPath {
  PathKind kind = PathKind::orbit;
  View lens;                      // fov, width, height, near, far; eye/target are overwritten
  glm::vec3 center{0};            // orbit centre; flythrough: centre of the flown box
  float radius = 400;             // orbit radius; flythrough: half extent of the loop
  float height_above = 60;        // eye height above centre
  uint32_t period_frames = 600;   // frames per loop
  std::vector<CameraKeyframe> keyframes;  // sorted by frame, at least one for `keyframes`
};

// Orbit: circle of `radius` around `center` at `height_above`, looking at the centre.
// Flythrough: a figure-eight through the scene at `height_above`, looking along the path.
// Keyframes: linear interpolation of position and look_at; held before the first and after
// the last key.
View view_at(const CameraPath& path, uint32_t frame);

}  // namespace lod
