// Several views in one frame (main camera, mirror, shadow cascades): each view culls and
// chooses levels on its own, then one decision per object follows. An object is visible when
// any view sees it (never_cull: every view does); its level is the finest any view needs and
// its importance the smallest (the view that needs it most decides when it is lowered), so it
// counts once against M.
#pragma once
#include <cstdint>
#include <span>

namespace lod {

// mask[i] = bit v for each view v with visible[v][i]; every view's bit where never_cull[i],
// which is also written into each view's visible column. Returns the count with mask != 0.
// Sub-range safe (pass sub-spans of every column).
size_t combine_view_masks(std::span<uint8_t> mask, std::span<const std::span<uint8_t>> visible,
                          std::span<const uint8_t> never_cull);

// Folds view `other`'s choice into the combined one (first view's columns): where only
// `other` sees an object its level and weight are taken; where both do, the finer level and
// the smaller weight. `visible` becomes the union. Sub-range safe.
void combine_view_choice(std::span<uint8_t> level, std::span<float> weight, std::span<uint8_t> visible,
                         std::span<const uint8_t> other_level, std::span<const float> other_weight,
                         std::span<const uint8_t> other_visible);

}  // namespace lod
