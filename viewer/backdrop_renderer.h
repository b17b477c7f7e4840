// BackdropRenderer: a sky gradient and an endless checkered ground plane under the scene, in
// one full-screen pass drawn first: each pixel's view ray either meets the plane (drawn with
// its true depth, fading into the horizon colour with distance) or shows the sky (depth 1).
#pragma once
#include <string>

#include <epoxy/gl.h>
#include <glm/glm.hpp>

#include "runtime/object_set.h"

namespace lod::viewer {

// Where the ground lies and how it is tiled, from the scene's objects: just under the lowest
// level-0 bounding sphere, tiles the power of ten at or under a tenth of the scene's extent.
struct GroundPlane {
  float height = 0;
  float tile = 1;
  float fade_distance = 100;  // the ground is the horizon colour this far from the eye
};
GroundPlane ground_under(const ObjectSet& objects);

class BackdropRenderer {
 public:
  BackdropRenderer() = default;
  ~BackdropRenderer();
  BackdropRenderer(const BackdropRenderer&) = delete;
  BackdropRenderer& operator=(const BackdropRenderer&) = delete;

  bool init(std::string* message);
  // `ground` false: sky only (a terrain is the ground).
  void draw(const glm::mat4& view, const glm::mat4& projection, const glm::vec3& eye, const GroundPlane& plane,
            bool ground);

 private:
  GLuint program_ = 0, vao_ = 0;
  GLint u_inverse_ = -1, u_view_projection_ = -1, u_eye_ = -1, u_ground_ = -1, u_plane_ = -1;
};

}  // namespace lod::viewer
