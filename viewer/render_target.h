// OffscreenTarget: a framebuffer object of an exact size (RGBA8 colour + 24-bit depth), so a
// screenshot has the requested size whatever the window system did to the window.
#pragma once
#include <string>

#include <epoxy/gl.h>

namespace lod::viewer {

class OffscreenTarget {
 public:
  OffscreenTarget() = default;
  ~OffscreenTarget();
  OffscreenTarget(const OffscreenTarget&) = delete;
  OffscreenTarget& operator=(const OffscreenTarget&) = delete;

  bool create(int width, int height, std::string* message);
  void bind() const;  // as draw and read framebuffer
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  GLuint fbo_ = 0, colour_ = 0, depth_ = 0;
  int width_ = 0, height_ = 0;
};

}  // namespace lod::viewer
