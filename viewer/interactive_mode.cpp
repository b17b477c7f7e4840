// The interactive viewer: lod::Service free-running on its own thread; every viewer frame
// stages the moving instances at wall time and commits them, sends the LOD camera with
// set_view() and draws the frame acquire_frame() holds, whatever frame that is. Nothing here
// waits on the LOD thread (holding a frame never blocks it either).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "jobs/scene_motion.h"
#include "jobs/service.h"
#include "runtime/camera_path.h"
#include "viewer/fly_camera.h"
#include "viewer/frustum_lines.h"
#include "viewer/orbit_camera.h"
#include "viewer/overhead_camera.h"
#include "viewer/overlay.h"
#include "viewer/viewer_session.h"

namespace lod::viewer {

namespace {

// GLFW delivers wheel steps and key presses by callback; a press and its release can both
// arrive within one frame, so toggles are queued rather than polled.
double g_scroll = 0;
std::vector<int> g_pressed_keys;

void on_scroll(GLFWwindow*, double, double dy) { g_scroll += dy; }
void on_key(GLFWwindow*, int key, int, int action, int) {
  if (action == GLFW_PRESS) g_pressed_keys.push_back(key);
}

float axis(GLFWwindow* w, int plus, int minus) {
  return (glfwGetKey(w, plus) == GLFW_PRESS ? 1.f : 0.f) - (glfwGetKey(w, minus) == GLFW_PRESS ? 1.f : 0.f);
}

// Key presses of this viewer frame, in order (a toggle pressed twice is back where it was).
void apply_keys(const std::vector<int>& keys, ViewerControls& controls) {
  for (int key : keys) {
    switch (key) {
      case GLFW_KEY_ESCAPE:
        controls.quit = true;
        break;
      case GLFW_KEY_1:
        controls.mode = CameraMode::path;
        break;
      case GLFW_KEY_2:
        controls.mode = CameraMode::fly;
        break;
      case GLFW_KEY_3:
        controls.mode = CameraMode::orbit;
        break;
      case GLFW_KEY_4:
        controls.mode = CameraMode::overhead;
        break;
      case GLFW_KEY_P:
        controls.paused = !controls.paused;
        break;
      case GLFW_KEY_L:
        controls.freeze_lod = !controls.freeze_lod;
        break;
      case GLFW_KEY_Z:
        controls.wireframe = !controls.wireframe;
        break;
      case GLFW_KEY_B:
        controls.backdrop = !controls.backdrop;
        break;
      case GLFW_KEY_C:
        controls.colour_by_level = !controls.colour_by_level;
        break;
      case GLFW_KEY_F:
        controls.flat_normals = !controls.flat_normals;
        break;
      case GLFW_KEY_H:
        controls.show_overlay = !controls.show_overlay;
        break;
      case GLFW_KEY_LEFT_BRACKET:
        controls.budget = std::max<uint64_t>(controls.budget / 2, 1);
        controls.budget_changed = true;
        break;
      case GLFW_KEY_RIGHT_BRACKET:
        controls.budget = std::min<uint64_t>(controls.budget * 2, uint64_t(1) << 40);
        controls.budget_changed = true;
        break;
      default:
        break;
    }
  }
}

// The frame drawn before the service has published one: nothing visible.
const Frame kNoFrame;

}  // namespace

int run_interactive(ViewerSession& s) {
  const ViewerOptions& o = s.options;
  GLFWwindow* window = s.window.handle();
  glfwSetScrollCallback(window, on_scroll);  // before ImGui, which chains them
  glfwSetKeyCallback(window, on_key);
  Overlay overlay;
  if (!overlay.init(window)) {
    std::fprintf(stderr, "lod-viewer: Dear ImGui could not start on this context\n");
    return 2;
  }
  std::string message;
  FrustumLines frustum_lines;
  if (!frustum_lines.init(&message)) {
    std::fprintf(stderr, "lod-viewer: %s\n", message.c_str());
    return 2;
  }

  const double rate_hz = o.lod_rate_hz > 0 ? o.lod_rate_hz : s.loaded.config.rate_hz;
  const double path_rate = s.loaded.config.rate_hz > 0 ? s.loaded.config.rate_hz : 60;  // path frames per second
  CameraPath path = s.loaded.config.camera;
  const std::unique_ptr<Service> owned = s.make_service(rate_hz);
  Service& service = *owned;
  SceneMotion motion(s.loaded.config, s.loaded.scene.objects, s.handles);

  ViewerControls controls;
  controls.colour_by_level = o.colour_by_level;
  controls.wireframe = o.wireframe;
  controls.backdrop = o.backdrop;
  controls.budget = s.graph.selection.budget;
  CameraMode last_mode = controls.mode;
  FlyCamera fly;
  OrbitCamera orbit;
  double path_frame = 0;
  double cursor_x = 0, cursor_y = 0;
  glfwGetCursorPos(window, &cursor_x, &cursor_y);

  int width = 0, height = 0;
  glfwGetFramebufferSize(window, &width, &height);
  path.lens = s.lens(std::max(width, 1), std::max(height, 1));
  View viewing = view_at(path, 0);
  {  // fly at about a tenth of the scene per second
    const View top = overhead_view(s.loaded.scene.objects, path.lens);
    fly.speed = std::max(1.f, 0.1f * glm::length(top.eye - top.target));
  }
  View lod_view = viewing;
  set_view(service, 0, lod_view);
  service.start();

  RenderSettings settings;
  settings.count_primitives = !o.stats.empty();  // the query waits for the GPU, so only when logging
  const uint64_t frame_limit = o.frames < 0 ? UINT64_MAX : uint64_t(o.frames);
  const auto start = std::chrono::steady_clock::now();
  auto frame_start = start;
  double last_ms = 0;
  for (uint64_t n = 0; n < frame_limit && !glfwWindowShouldClose(window) && !controls.quit; ++n) {
    const auto now = std::chrono::steady_clock::now();
    const float dt = n == 0 ? 0.f : std::chrono::duration<float>(now - frame_start).count();
    frame_start = now;
    glfwPollEvents();

    // Input: keys are ignored while an ImGui widget has the keyboard, mouse while it has the mouse.
    double x = 0, y = 0;
    glfwGetCursorPos(window, &x, &y);
    const float dx = float(x - cursor_x), dy = float(y - cursor_y);
    cursor_x = x;
    cursor_y = y;
    const bool dragging = !overlay.wants_mouse() && glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS;
    const float wheel = overlay.wants_mouse() ? 0.f : float(g_scroll);
    g_scroll = 0;
    if (!overlay.wants_keyboard()) apply_keys(g_pressed_keys, controls);
    g_pressed_keys.clear();

    glfwGetFramebufferSize(window, &width, &height);
    if (width <= 0 || height <= 0) {  // minimised: nothing to draw, keep the LOD thread running
      glfwWaitEventsTimeout(0.05);
      continue;
    }
    path.lens = s.lens(width, height);
    if (controls.mode != last_mode) {  // a new camera starts where the old one looked
      fly.look_like(viewing);
      orbit.look_like(viewing);
      last_mode = controls.mode;
    }
    if (!controls.paused && (controls.mode == CameraMode::path || controls.mode == CameraMode::overhead))
      path_frame += double(dt) * path_rate;
    // Movers where they are now (wall time), committed for the LOD thread's next frame; then
    // the newest frame, held until this viewer frame ends.
    auto service_start = std::chrono::steady_clock::now();
    if (motion.moving() > 0) {
      motion.stage(service, std::chrono::duration<double>(now - start).count());
      service.commit(n + 1);
    }
    const FrameRef held = service.acquire_frame();  // never waits
    const Frame& frame = held ? *held : kNoFrame;
    double service_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - service_start).count();

    const View path_view = view_at(path, uint32_t(std::fmod(path_frame, 4294967296.0)));
    View lod_camera = path_view;  // what the LOD thread should see, unless frozen
    switch (controls.mode) {
      case CameraMode::path:
        viewing = path_view;
        break;
      case CameraMode::overhead:
        viewing = s.overhead(frame, path.lens);
        break;
      case CameraMode::fly: {
        FlyInput in;
        if (!overlay.wants_keyboard()) {
          const float boost = glfwGetKey(window, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ? 5.f : 1.f;
          in.forward = axis(window, GLFW_KEY_W, GLFW_KEY_S) * boost;
          in.right = axis(window, GLFW_KEY_D, GLFW_KEY_A) * boost;
          in.up = axis(window, GLFW_KEY_E, GLFW_KEY_Q) * boost;
        }
        if (dragging) in.look_dx = dx, in.look_dy = dy;
        fly.speed *= std::pow(1.2f, wheel);
        fly.update(in, dt);
        viewing = fly.view(path.lens);
        lod_camera = viewing;
        break;
      }
      case CameraMode::orbit:
        if (dragging) orbit.rotate(dx, dy);
        orbit.zoom(wheel);
        viewing = orbit.view(path.lens);
        lod_camera = viewing;
        break;
    }
    service_start = std::chrono::steady_clock::now();
    if (!controls.freeze_lod) {
      lod_view = lod_camera;
      set_view(service, 0, lod_view);
    }
    if (controls.budget_changed) {
      service.set_budget(controls.budget);
      controls.budget_changed = false;
    }

    const ServiceStats service_stats = service.stats();
    service_ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - service_start).count();
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    settings.colour_by_level = controls.colour_by_level;
    settings.wireframe = controls.wireframe;
    settings.backdrop = controls.backdrop;
    settings.flat_normals = controls.flat_normals;
    const DrawStats drawn = s.renderer.render(frame, viewing, settings);
    if (controls.freeze_lod || controls.mode == CameraMode::overhead) {
      s.renderer.render_culled(frame, s.handles, viewing);
      frustum_lines.draw(lod_view, viewing);
    }
    if (controls.show_overlay) {
      const OverlayFacts facts = s.overlay_facts(held.get(), drawn, service_stats,
                                                 std::chrono::duration<double>(now - start).count(), last_ms);
      overlay.draw(facts, controls, /*with_controls=*/true);
    }
    glfwSwapBuffers(window);
    last_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - now).count();
    s.record(n, frame, drawn, last_ms, service_ms);
  }
  service.stop();
  const ServiceStats st = service.stats();
  std::fprintf(stderr, "lod-viewer: LOD thread published %llu frames (%.2f ms mean, %llu errors) at %.1f Hz\n",
               (unsigned long long)st.frames, st.mean_ms, (unsigned long long)st.errors, rate_hz);
  return s.finish("interactive") ? 0 : 1;
}

}  // namespace lod::viewer
