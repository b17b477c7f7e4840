// FrustumLines: the LOD camera's frustum drawn as 12 lines, so that with "freeze LOD" the
// viewing camera can look from outside at what was culled and simplified.
#pragma once
#include <string>

#include <epoxy/gl.h>
#include <glm/glm.hpp>

#include "runtime/view.h"

namespace lod::viewer {

class FrustumLines {
 public:
  FrustumLines() = default;
  ~FrustumLines();
  FrustumLines(const FrustumLines&) = delete;
  FrustumLines& operator=(const FrustumLines&) = delete;

  bool init(std::string* message);
  // Draws `frustum`'s edges as seen from `viewing` (which sets the projection).
  void draw(const View& frustum, const View& viewing);

 private:
  GLuint program_ = 0, vao_ = 0, vbo_ = 0;
  GLint u_view_projection_ = -1;
};

}  // namespace lod::viewer
