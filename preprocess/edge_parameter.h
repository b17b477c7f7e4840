// Where a collapse puts the merged vertex along its edge, as the weight of the far end's
// attributes: what the QEM simplifier and the vertex hierarchy interpolate uvs (and other
// attributes) by, so a merged vertex's uv stays between its endpoints'.
#pragma once
#include <algorithm>

namespace lod {

// Where p projects onto the edge from a to b, as a fraction of it in [0, 1] (1 for a point edge):
// the weight of b's attribute in the one the collapse gives.
inline float edge_parameter(const float* pa, const float* pb, const float* p) {
  const float d[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
  const float len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  if (!(len2 > 0)) return 1;
  return std::clamp(((p[0] - pa[0]) * d[0] + (p[1] - pa[1]) * d[1] + (p[2] - pa[2]) * d[2]) / len2, 0.f, 1.f);
}

}  // namespace lod
