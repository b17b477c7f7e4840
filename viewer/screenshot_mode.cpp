// --screenshot: the service in driven mode, N frames along the config's camera path, each
// stepped then drawn into an offscreen target of the requested size, then the last picture
// written as PNG. Moving instances are staged at each frame's time and committed before the
// step, as `lod run` does. Deterministic: the same config and N give the same frame and picture.
#include <chrono>
#include <cstdio>
#include <memory>

#include "jobs/scene_motion.h"
#include "jobs/service.h"
#include "runtime/camera_path.h"
#include "viewer/frustum_lines.h"
#include "viewer/overhead_camera.h"
#include "viewer/overlay.h"
#include "viewer/render_target.h"
#include "viewer/screenshot.h"
#include "viewer/viewer_session.h"

namespace lod::viewer {

namespace {

// The frame drawn before the service has published one: nothing visible.
const Frame kNoFrame;

// Morphing objects are drawn at their finer level: the frame says what that adds. False (and
// says so) when what was submitted or what the GL counted differs from that.
bool drew_what_was_selected(uint32_t n, const FrameRow& row) {
  if (row.gpu_primitives == int64_t(row.drawn) && row.drawn == row.tris_selected + row.morph_extra)
    return true;
  std::fprintf(
      stderr,
      "lod-viewer: frame %u: selected %llu + %llu for %u morphing objects, submitted %llu, GL counted "
      "%lld triangles\n",
      n, (unsigned long long)row.tris_selected, (unsigned long long)row.morph_extra, row.morphing,
      (unsigned long long)row.drawn, (long long)row.gpu_primitives);
  return false;
}

}  // namespace

int run_screenshot(ViewerSession& s) {
  const ViewerOptions& o = s.options;
  std::string message;
  OffscreenTarget target;
  if (!target.create(o.width, o.height, &message)) {
    std::fprintf(stderr, "lod-viewer: %s\n", message.c_str());
    return 2;
  }
  FrustumLines frustum_lines;
  if (o.bird_eye && !frustum_lines.init(&message)) {
    std::fprintf(stderr, "lod-viewer: %s\n", message.c_str());
    return 2;
  }
  Overlay overlay;
  if (o.overlay && !overlay.init(s.window.handle())) {
    std::fprintf(stderr, "lod-viewer: Dear ImGui could not start on this context\n");
    return 2;
  }

  CameraPath path = s.loaded.config.camera;
  path.lens = s.lens(o.width, o.height);
  const std::unique_ptr<Service> owned = s.make_service(s.loaded.config.rate_hz);
  Service& service = *owned;
  SceneMotion motion(s.loaded.config, s.loaded.scene.objects, s.handles);
  // Frames are 1 / rate_hz apart on the service clock (1/60 s when the rate is unlimited).
  const double dt = s.loaded.config.rate_hz > 0 ? 1.0 / s.loaded.config.rate_hz : 1.0 / 60;
  RenderSettings settings;
  settings.colour_by_level = o.colour_by_level;
  settings.wireframe = o.wireframe;
  settings.backdrop = o.backdrop;
  settings.count_primitives = true;  // every drawn frame is checked against the GL's own count

  ViewerControls controls;  // the overlay shows them; nothing reads them back here
  controls.colour_by_level = o.colour_by_level;
  controls.wireframe = o.wireframe;
  controls.backdrop = o.backdrop;
  controls.budget = s.graph.selection.budget;
  controls.mode = o.bird_eye ? CameraMode::overhead : CameraMode::path;

  const uint32_t frames = o.frames < 0 ? 1 : uint32_t(o.frames);
  uint64_t failed = 0, mismatched = 0;
  DrawStats last;
  const auto start = std::chrono::steady_clock::now();
  for (uint32_t n = 0; n < frames; ++n) {
    const auto t0 = std::chrono::steady_clock::now();
    if (motion.moving() > 0) {  // where the movers are at this frame's time, in the frame it computes
      motion.stage(service, (n + 1) * dt);
      service.commit(n + 1);
    }
    const View view = view_at(path, n);
    set_view(service, 0, view);
    if (!service.step(dt)) ++failed;
    const FrameRef held = service.acquire_frame();
    const Frame& frame = held ? *held : kNoFrame;
    const double service_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    target.bind();
    const View viewing = o.bird_eye ? s.overhead(frame, path.lens) : view;
    last = s.renderer.render(frame, viewing, settings);
    if (o.bird_eye) {
      s.renderer.render_culled(frame, s.handles, viewing);
      frustum_lines.draw(view, viewing);
    }
    if (o.overlay) {
      const double viewer_ms = s.log.rows().empty() ? 0 : s.log.rows().back().viewer_ms;
      const OverlayFacts facts = s.overlay_facts(
          held.get(), last, service.stats(), std::chrono::duration<double>(t0 - start).count(), viewer_ms);
      overlay.draw(facts, controls, /*with_controls=*/false);
    }
    glfwPollEvents();
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (!drew_what_was_selected(n, s.record(n, frame, last, ms, service_ms))) ++mismatched;
  }

  target.bind();
  const std::vector<uint8_t> rgb = read_pixels_top_down(o.width, o.height);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (Status st = write_png(o.screenshot, o.width, o.height, rgb); !st) {
    std::fprintf(stderr, "lod-viewer: %s\n", st.message.c_str());
    return 1;
  }
  const FrameRow& row = s.log.rows().back();
  std::fprintf(stderr,
               "lod-viewer: wrote %s (%dx%d) after %u frames: %u visible, %llu triangles selected, %llu drawn "
               "in %u draws, %u levels\n",
               o.screenshot.c_str(), o.width, o.height, frames, row.visible, (unsigned long long)row.tris_selected,
               (unsigned long long)row.drawn, row.draws, row.levels_drawn);
  if (!s.finish("screenshot")) return 1;
  if (failed) {
    std::fprintf(stderr, "lod-viewer: %llu of %u LOD frames failed (last good frame kept)\n",
                 (unsigned long long)failed, frames);
    return 1;
  }
  if (mismatched) {
    std::fprintf(stderr, "lod-viewer: %llu frames drew a different triangle count than selected (+ morphing)\n",
                 (unsigned long long)mismatched);
    return 1;
  }
  return 0;
}

}  // namespace lod::viewer
