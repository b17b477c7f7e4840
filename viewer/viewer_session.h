// ViewerSession: what both modes (screenshot, interactive) share once the scene is loaded
// and the window is open, plus the per-frame bookkeeping they both do.
#pragma once
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "jobs/frame_graph.h"
#include "lodkit/service.hpp"
#include "runtime/frame.h"
#include "runtime/view.h"
#include "viewer/frame_log.h"
#include "viewer/frame_renderer.h"
#include "viewer/gl_context.h"
#include "viewer/overhead_camera.h"
#include "viewer/overlay.h"
#include "viewer/scene_loader.h"

namespace lod::viewer {

struct ViewerOptions {
  std::filesystem::path config;
  std::filesystem::path data_dir;    // empty = default
  std::filesystem::path cache_dir;   // empty = LOD_CACHE_DIR or <data>/../cache
  std::filesystem::path screenshot;  // empty = interactive
  std::filesystem::path stats;       // per-frame CSV, empty = none
  int64_t frames = -1;               // -1: screenshot 1 frame, interactive until closed
  int width = 1280, height = 720;
  int64_t threads = -1;              // -1 = the config's
  int64_t budget = -1;               // -1 = the config's
  double lod_rate_hz = -1;           // -1 = the config's rate_hz
  double lod_delay_ms = 0;           // sleep added to every LOD frame (measuring that the viewer never waits)
  bool colour_by_level = false;
  bool backdrop = true;              // sky gradient and ground plane (--backdrop off: flat colour)
  bool wireframe = false;
  bool bird_eye = false;             // draw from above the scene; the LOD camera still follows the path
  bool overlay = false;              // screenshot: draw the overlay too (interactive always has it)
  bool vsync = true;
};

struct ViewerSession {
  const ViewerOptions& options;
  LoadedScene& loaded;
  GlWindow& window;
  FrameRenderer& renderer;
  FrameGraphOptions graph;
  uint32_t threads = 0;  // resolved LOD pool size, for display
  FrameLog log;
  std::vector<ObjectHandle> handles;  // scene object i's handle in the service (make_service)
  std::vector<ModelSphere> spheres;   // per model, for the bird's-eye camera

  // The service over the loaded scene (objects created and committed at tick 0), filling
  // `handles` and `spheres`. `rate_hz` is its free-running rate.
  std::unique_ptr<Service> make_service(double rate_hz);
  // Bird's-eye view over the scene and where `frame` puts its entries (moving objects).
  View overhead(const Frame& frame, const View& lens) const;
  // The config's lens at the size being drawn (projected areas must match the picture).
  View lens(int width, int height) const;
  // What the overlay shows for `frame` drawn as `drawn` (null: no LOD frame published yet).
  OverlayFacts overlay_facts(const Frame* frame, const DrawStats& drawn, const ServiceStats& service,
                             double time_s, double viewer_ms) const;
  // Most levels any model has.
  size_t max_levels() const;
  // Checks the frame, fills a row from the draw, appends it to the log.
  const FrameRow& record(uint64_t viewer_frame, const Frame& frame, const DrawStats& drawn, double viewer_ms,
                         double service_ms);
  // Writes --stats if asked; prints the frame-time summary. Returns false if the CSV failed.
  bool finish(const char* mode_name);
};

int run_screenshot(ViewerSession& session);
int run_interactive(ViewerSession& session);

}  // namespace lod::viewer
