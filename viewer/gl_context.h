// GlWindow: a GLFW window with an OpenGL 3.3 core context (epoxy resolves GL functions).
// Failures are reported, never crashed on: no display, no window, or a GL older than 3.3.
#pragma once
#include <string>

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

namespace lod::viewer {

enum class GlFailure { none, no_display, no_context, old_gl };

struct WindowOptions {
  int width = 1280;
  int height = 720;
  bool visible = true;   // hidden for screenshots: they render into an offscreen target
  bool vsync = true;
  std::string title = "lod-viewer";
};

class GlWindow {
 public:
  GlWindow() = default;
  ~GlWindow();
  GlWindow(const GlWindow&) = delete;
  GlWindow& operator=(const GlWindow&) = delete;

  // Initialises GLFW and opens the window; on failure returns the kind and fills `message`.
  GlFailure open(const WindowOptions& options, std::string* message);

  GLFWwindow* handle() const { return window_; }
  const std::string& description() const { return description_; }  // "4.5 (Core Profile) Mesa ..., llvmpipe"
  bool core_profile() const { return core_; }

 private:
  GLFWwindow* window_ = nullptr;
  bool glfw_ready_ = false;
  bool core_ = false;
  std::string description_;
};

}  // namespace lod::viewer
