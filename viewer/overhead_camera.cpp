#include "viewer/overhead_camera.h"

#include <algorithm>
#include <cmath>

namespace lod::viewer {

View overhead_view(const ObjectSet& objects, const View& lens) {
  glm::vec3 lo(0), hi(0);
  for (size_t i = 0; i < objects.size(); ++i) {
    const glm::vec3 c(objects.cx[i], objects.cy[i], objects.cz[i]);
    const glm::vec3 r(objects.radius[i]);
    lo = i == 0 ? c - r : glm::min(lo, c - r);
    hi = i == 0 ? c + r : glm::max(hi, c + r);
  }
  const glm::vec3 centre = 0.5f * (lo + hi);
  // Half extents on the picture: x across, z up the picture.
  const float half_x = std::max(0.5f * (hi.x - lo.x), 1.f);
  const float half_z = std::max(0.5f * (hi.z - lo.z), 1.f);
  const float tan_y = std::tan(0.5f * glm::radians(lens.fov_y_deg));
  const float aspect = float(lens.width) / float(std::max(lens.height, 1));
  const float height = 1.05f * std::max(half_z / tan_y, half_x / (tan_y * aspect));
  View v = lens;
  v.eye = {centre.x, hi.y + height, centre.z};
  v.target = {centre.x, centre.y, centre.z};
  v.up = {0, 0, -1};
  v.far_plane = std::max(v.far_plane, 2 * (height + (hi.y - lo.y)));
  v.near_plane = std::max(v.near_plane, 0.001f * v.far_plane);
  return v;
}

}  // namespace lod::viewer
