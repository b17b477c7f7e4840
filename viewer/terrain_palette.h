// The terrain's height colours: green lowlands, brown slopes, white peaks over the frame's
// height range (TerrainRenderer's shader computes the same ramp).
#pragma once
#include <algorithm>
#include <glm/glm.hpp>

namespace lod::viewer {

inline constexpr float kTerrainLow[3] = {0.20f, 0.45f, 0.18f};
inline constexpr float kTerrainMid[3] = {0.55f, 0.42f, 0.25f};
inline constexpr float kTerrainHigh[3] = {0.95f, 0.95f, 0.95f};

// Colour of a height at t in [0, 1] of the range (clamped).
inline glm::vec3 terrain_height_colour(float t) {
  const glm::vec3 low(kTerrainLow[0], kTerrainLow[1], kTerrainLow[2]);
  const glm::vec3 mid(kTerrainMid[0], kTerrainMid[1], kTerrainMid[2]);
  const glm::vec3 high(kTerrainHigh[0], kTerrainHigh[1], kTerrainHigh[2]);
  t = std::clamp(t, 0.f, 1.f);
  return t < 0.5f ? glm::mix(low, mid, t * 2.f) : glm::mix(mid, high, t * 2.f - 1.f);
}

}  // namespace lod::viewer
