// View matrices (GLM, OpenGL clip conventions) and the frustum planes culling tests against.
#include "runtime/view.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace lod {

glm::mat4 view_matrix(const View& v) {
  // glm::lookAt's basis, built in double with front_view_of's fallbacks: an up vector parallel
  // to the view direction (a camera looking straight down with up = +y) or a zero one gives
  // the basis front_view_of uses instead of NaNs (which culled every object), so the frustum
  // and the view-dependent fronts agree.
  using V = glm::dvec3;
  const V eye(v.eye);
  V fwd = V(v.target) - eye;
  fwd = glm::length(fwd) > 0 ? glm::normalize(fwd) : V(0, 0, -1);
  V right = glm::cross(fwd, V(v.up));
  if (!(glm::length(right) >= 1e-12))
    right = glm::cross(fwd, std::abs(fwd.y) < 0.9 ? V(0, 1, 0) : V(1, 0, 0));
  right = glm::normalize(right);
  const V up = glm::cross(right, fwd);
  glm::dmat4 m(1);
  for (int k = 0; k < 3; ++k) {
    m[k][0] = right[k];
    m[k][1] = up[k];
    m[k][2] = -fwd[k];
  }
  m[3][0] = -glm::dot(right, eye);
  m[3][1] = -glm::dot(up, eye);
  m[3][2] = glm::dot(fwd, eye);
  return glm::mat4(m);
}

glm::mat4 projection_matrix(const View& v) {
  const float aspect = static_cast<float>(v.width) / static_cast<float>(v.height > 0 ? v.height : 1);
  return glm::perspective(glm::radians(v.fov_y_deg), aspect, v.near_plane, v.far_plane);
}

EyePlanes eye_planes_of(const View& v) {
  using V = glm::dvec3;
  EyePlanes out;
  out.eye = V(v.eye);
  V fwd = V(v.target) - out.eye;
  fwd = glm::length(fwd) > 0 ? glm::normalize(fwd) : V(0, 0, -1);
  V right = glm::cross(fwd, V(v.up));  // view_matrix's basis and fallbacks
  if (!(glm::length(right) >= 1e-12))
    right = glm::cross(fwd, std::abs(fwd.y) < 0.9 ? V(0, 1, 0) : V(1, 0, 0));
  right = glm::normalize(right);
  const V up = glm::cross(right, fwd);
  const double ty = std::tan(0.5 * glm::radians(double(v.fov_y_deg)));
  const double aspect = double(v.width) / double(v.height > 0 ? v.height : 1);
  const double hy = std::atan(ty), hx = std::atan(aspect * ty);
  // Each side plane passes through the eye.
  const V normals[6] = {std::cos(hx) * right + std::sin(hx) * fwd, -std::cos(hx) * right + std::sin(hx) * fwd,
                        std::cos(hy) * up + std::sin(hy) * fwd,    -std::cos(hy) * up + std::sin(hy) * fwd,
                        fwd,                                       -fwd};
  const double offsets[6] = {0, 0, 0, 0, -double(v.near_plane), double(v.far_plane)};
  for (int k = 0; k < 6; ++k) out.normal[k] = normals[k], out.offset[k] = offsets[k];
  return out;
}

Frustum frustum_of(const View& v) {
  const EyePlanes e = eye_planes_of(v);
  Frustum f;
  for (int k = 0; k < 6; ++k) {
    // dot(n, p) + w >= 0 inside: w = -dot(n, eye) + the plane's distance from the eye.
    f.planes[k] = glm::vec4(glm::vec3(e.normal[k]), static_cast<float>(e.offset[k] - glm::dot(e.normal[k], e.eye)));
  }
  return f;
}

float focal_pixels(const View& v) {
  return 0.5f * static_cast<float>(v.height) / std::tan(0.5f * glm::radians(v.fov_y_deg));
}

View view_of(const Camera& c) {
  View v;
  v.eye = glm::vec3(c.eye[0], c.eye[1], c.eye[2]);
  v.target = v.eye + glm::vec3(c.forward[0], c.forward[1], c.forward[2]);
  v.up = glm::vec3(c.up[0], c.up[1], c.up[2]);
  v.fov_y_deg = c.fov_y_deg;
  v.width = static_cast<int>(c.width);
  v.height = static_cast<int>(c.height);
  v.near_plane = c.near_z;
  v.far_plane = c.far_z;
  return v;
}

Camera camera_of(const View& v) {
  Camera c;
  const glm::vec3 f = v.target - v.eye;
  for (int k = 0; k < 3; ++k) c.eye[k] = v.eye[k], c.forward[k] = f[k], c.up[k] = v.up[k];
  c.fov_y_deg = v.fov_y_deg;
  c.width = static_cast<uint32_t>(std::max(v.width, 0));
  c.height = static_cast<uint32_t>(std::max(v.height, 0));
  c.near_z = v.near_plane;
  c.far_z = v.far_plane;
  return c;
}

bool camera_valid(const Camera& c, const char** why) {
  auto fail = [&](const char* w) {
    if (why) *why = w;
    return false;
  };
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(c.eye[k]) || !std::isfinite(c.forward[k]) || !std::isfinite(c.up[k]))
      return fail("eye, forward and up must be finite");
  const glm::dvec3 f(c.forward[0], c.forward[1], c.forward[2]), u(c.up[0], c.up[1], c.up[2]);
  if (glm::length(f) < 1e-12) return fail("forward must not be zero");
  if (glm::length(u) < 1e-12) return fail("up must not be zero");
  if (glm::length(glm::cross(glm::normalize(f), glm::normalize(u))) < 1e-6) return fail("up must not be parallel to forward");
  if (!(c.fov_y_deg >= kMinFovYDeg && c.fov_y_deg <= kMaxFovYDeg)) return fail("fov_y_deg must be in [0.001, 179] degrees");
  if (c.width == 0 || c.height == 0 || c.width > 65536 || c.height > 65536) return fail("width and height must be 1..65536");
  if (!(c.near_z > 0 && std::isfinite(c.far_z) && c.far_z > c.near_z)) return fail("need 0 < near_z < far_z, finite");
  return true;
}

}  // namespace lod
