// View: one camera for one frame, with what the stages derive from it.
#pragma once
#include <glm/glm.hpp>

#include "lodkit/types.hpp"

namespace lod {

struct View {
  glm::vec3 eye{0, 0, 0};
  glm::vec3 target{0, 0, -1};
  glm::vec3 up{0, 1, 0};
  float fov_y_deg = 60;
  int width = 1280;    // pixels
  int height = 720;
  float near_plane = 0.5f;
  float far_plane = 5000.f;
};

struct Frustum {
  glm::vec4 planes[6];  // normalized, inside when dot(n, p) + w >= 0
};

// The frustum's planes in double about the eye: inside when dot(normal[k], p - eye) + offset[k] >= 0,
// in the order left, right, bottom, top, near, far; normals are unit length and point inwards.
struct EyePlanes {
  glm::dvec3 eye;
  glm::dvec3 normal[6];
  double offset[6];
};

// The public Camera and the View the stages use, each way (forward = target - eye).
View view_of(const Camera& c);
Camera camera_of(const View& v);
// True when a camera gives a usable view: finite, forward and up not zero nor parallel,
// fov in [kMinFovYDeg, kMaxFovYDeg], width and height > 0, 0 < near < far. Otherwise `why` names the value.
bool camera_valid(const Camera& c, const char** why);

glm::mat4 view_matrix(const View& v);
glm::mat4 projection_matrix(const View& v);
// Built from the camera's basis and half-angles rather than extracted from a float clip
// matrix, whose rows nearly cancel for a large far / near (the near plane is lost) and for a
// tiny field of view (the side planes are lost).
EyePlanes eye_planes_of(const View& v);
Frustum frustum_of(const View& v);
// Pixels per unit of size at distance 1: (height / 2) / tan(fov_y / 2).
float focal_pixels(const View& v);

}  // namespace lod
