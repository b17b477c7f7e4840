// Colours of the colour-by-level mode: one distinct hue per chain level (0 = full detail),
// chosen so that neighbouring levels never look alike even after headlight shading.
#pragma once
#include <array>
#include <cstddef>

namespace lod::viewer {

inline constexpr std::array<std::array<float, 3>, 12> kLevelPalette = {{
    {0.90f, 0.10f, 0.10f},  // 0 red: full detail
    {0.10f, 0.45f, 0.95f},  // 1 blue
    {0.15f, 0.80f, 0.15f},  // 2 green
    {0.95f, 0.85f, 0.10f},  // 3 yellow
    {0.70f, 0.15f, 0.90f},  // 4 purple
    {0.10f, 0.85f, 0.85f},  // 5 cyan
    {0.95f, 0.50f, 0.05f},  // 6 orange
    {0.95f, 0.35f, 0.70f},  // 7 pink
    {0.60f, 0.95f, 0.10f},  // 8 lime
    {0.30f, 0.30f, 0.95f},  // 9 indigo
    {0.60f, 0.40f, 0.20f},  // 10 brown
    {0.70f, 0.05f, 0.30f},  // 11 maroon; deeper levels wrap around
}};

inline const std::array<float, 3>& level_colour(size_t level) { return kLevelPalette[level % kLevelPalette.size()]; }

// View-dependent objects in colour-by-level mode: they have no single level; white is no
// palette entry.
inline constexpr std::array<float, 3> kViewDependentColour = {0.97f, 0.97f, 0.97f};
// Neutral grey-blue for the normal (not colour-by-level) mode.
inline constexpr std::array<float, 3> kModelColour = {0.72f, 0.74f, 0.78f};
// Objects the LOD frame culled, seen from outside (bird's-eye, frozen LOD).
inline constexpr std::array<float, 3> kCulledColour = {0.30f, 0.30f, 0.33f};
inline constexpr std::array<float, 3> kBackground = {0.08f, 0.09f, 0.11f};

}  // namespace lod::viewer
