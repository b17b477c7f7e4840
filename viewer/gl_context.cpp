// Context creation with a clear fallback: ask for 3.3 core forward-compatible; if the driver
// refuses, take whatever context it offers and accept it only if it is at least 3.3.
#include "viewer/gl_context.h"

#include <cstdio>

namespace lod::viewer {

namespace {

std::string g_last_glfw_error;  // GLFW reports errors through a callback, not return values

void on_glfw_error(int code, const char* text) {
  char buf[512];
  std::snprintf(buf, sizeof buf, "GLFW error 0x%x: %s", code, text ? text : "?");
  g_last_glfw_error = buf;
}

GLFWwindow* create_window(const WindowOptions& o, bool core) {
  glfwDefaultWindowHints();
  if (core) {
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  }
  glfwWindowHint(GLFW_VISIBLE, o.visible ? GLFW_TRUE : GLFW_FALSE);
  glfwWindowHint(GLFW_DEPTH_BITS, 24);
  return glfwCreateWindow(o.width, o.height, o.title.c_str(), nullptr, nullptr);
}

}  // namespace

GlWindow::~GlWindow() {
  if (window_) glfwDestroyWindow(window_);
  if (glfw_ready_) glfwTerminate();
}

GlFailure GlWindow::open(const WindowOptions& options, std::string* message) {
  glfwSetErrorCallback(on_glfw_error);
  if (!glfwInit()) {
    *message = "cannot open a display (" + g_last_glfw_error +
               "); set DISPLAY, or run headless with: xvfb-run -a lod-viewer ...";
    return GlFailure::no_display;
  }
  glfw_ready_ = true;

  core_ = true;
  window_ = create_window(options, /*core=*/true);
  if (!window_) {
    const std::string core_error = g_last_glfw_error;
    std::fprintf(stderr, "lod-viewer: no OpenGL 3.3 core context (%s); trying the driver's default context\n",
                 core_error.c_str());
    core_ = false;
    window_ = create_window(options, /*core=*/false);
    if (!window_) {
      *message = "cannot create an OpenGL window (" + core_error + "; default context: " + g_last_glfw_error + ")";
      return GlFailure::no_context;
    }
  }
  glfwMakeContextCurrent(window_);
  glfwSwapInterval(options.vsync ? 1 : 0);

  const char* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  description_ = std::string(version ? version : "?") + ", " + (renderer ? renderer : "?");
  if (epoxy_gl_version() < 33 || epoxy_is_desktop_gl() == 0) {
    *message = "OpenGL 3.3 is needed, this display offers " + description_ +
               " (for software rendering install Mesa's libgl1-mesa-dri; llvmpipe gives 4.5)";
    return GlFailure::old_gl;
  }
  return GlFailure::none;
}

}  // namespace lod::viewer
