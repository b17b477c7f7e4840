// View matrices (GLM, OpenGL clip conventions) and the frustum planes culling tests against.
#include "runtime/view.h"

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace lod {

glm::mat4 view_matrix(const View& v) { return glm::lookAt(v.eye, v.target, v.up); }

glm::mat4 projection_matrix(const View& v) {
  const float aspect = static_cast<float>(v.width) / static_cast<float>(v.height > 0 ? v.height : 1);
  return glm::perspective(glm::radians(v.fov_y_deg), aspect, v.near_plane, v.far_plane);
}

Frustum frustum_of(const View& v) {
  // Gribb-Hartmann: each plane is a sum or difference of rows of the clip matrix.
  const glm::mat4 m = projection_matrix(v) * view_matrix(v);
  const glm::vec4 row0(m[0][0], m[1][0], m[2][0], m[3][0]);
  const glm::vec4 row1(m[0][1], m[1][1], m[2][1], m[3][1]);
  const glm::vec4 row2(m[0][2], m[1][2], m[2][2], m[3][2]);
  const glm::vec4 row3(m[0][3], m[1][3], m[2][3], m[3][3]);
  Frustum f;
  f.planes[0] = row3 + row0;  // left
  f.planes[1] = row3 - row0;  // right
  f.planes[2] = row3 + row1;  // bottom
  f.planes[3] = row3 - row1;  // top
  f.planes[4] = row3 + row2;  // near (clip z in [-w, w])
  f.planes[5] = row3 - row2;  // far
  for (glm::vec4& p : f.planes) {
    // Normalized so dot(n, c) + w is a signed distance a sphere radius compares against.
    p /= glm::length(glm::vec3(p));
  }
  return f;
}

float focal_pixels(const View& v) {
  return 0.5f * static_cast<float>(v.height) / std::tan(0.5f * glm::radians(v.fov_y_deg));
}

}  // namespace lod
