// lod-viewer: a GLFW + OpenGL 3.3 window drawing what lod::Service publishes.
//
// Exit codes: 0 done; 1 bad command line, config, assets or output file; 2 no display, no
// OpenGL 3.3, or the GL refused a resource.
#include <chrono>
#include <map>
#include <cstdio>
#include <thread>

#include <CLI/CLI.hpp>

#include "jobs/service.h"
#include "jobs/terrain_scene.h"
#include "viewer/frame_renderer.h"
#include "viewer/gl_context.h"
#include "viewer/scene_loader.h"
#include "viewer/viewer_session.h"

namespace {

constexpr int kExitBadInput = 1;
constexpr int kExitNoGl = 2;

int run(const lod::viewer::ViewerOptions& o) {
  using namespace lod::viewer;
  if (o.width <= 0 || o.height <= 0 || o.width > 16384 || o.height > 16384) {
    std::fprintf(stderr, "lod-viewer: --width/--height %dx%d: each must be in 1..16384\n", o.width, o.height);
    return kExitBadInput;
  }

  // Scene first: a bad config is reported the same way with or without a display.
  LoadedScene loaded;
  auto log = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
  if (lod::Status st = load_scene(o.config, o.data_dir, o.cache_dir, loaded, log); !st) {
    std::fprintf(stderr, "lod-viewer: %s\n", st.message.c_str());
    return kExitBadInput;
  }
  std::shared_ptr<const lod::TerrainModel> terrain = loaded.terrain;  // [[terrain]]: drawn from each frame's mesh
  if (o.threads >= 0) loaded.config.threads = uint32_t(o.threads);
  std::fprintf(stderr, "lod-viewer: %zu models (%zu hlod), %zu objects (bake %.0f ms: %zu baked, %zu cached in %s)\n",
               loaded.scene.chains.size() + loaded.hlod->trees.size(), loaded.hlod->trees.size(),
               loaded.scene.objects.size(), loaded.bake.ms, loaded.bake.baked,
               loaded.bake.cached, loaded.cache_dir.c_str());

  GlWindow window;
  WindowOptions wo;
  wo.width = o.width;
  wo.height = o.height;
  wo.visible = o.screenshot.empty();
  wo.vsync = o.vsync && o.screenshot.empty();
  std::string message;
  if (window.open(wo, &message) != GlFailure::none) {
    std::fprintf(stderr, "lod-viewer: %s\n", message.c_str());
    return kExitNoGl;
  }
  std::fprintf(stderr, "lod-viewer: OpenGL %s%s\n", window.description().c_str(),
               window.core_profile() ? "" : " (not a core profile: the driver refused 3.3 core)");

  FrameRenderer renderer;
  if (!renderer.init(loaded.scene, loaded.hlod.get(), &message)) {
    std::fprintf(stderr, "lod-viewer: %s\n", message.c_str());
    return kExitNoGl;
  }

  ViewerSession session{o, loaded, window, renderer, {}, 0, {}, {}, {}};
  session.graph = frame_graph_options(loaded.config);
  if (!loaded.hlod->empty()) session.graph.hlod = loaded.hlod;
  if (!loaded.scene_hlod->empty()) session.graph.scene_hlod = loaded.scene_hlod;  // make_service binds handles
  renderer.set_scene_hlod(loaded.scene_hlod.get());
  session.graph.terrain = terrain;
  if (o.budget > 0) session.graph.selection.budget = uint64_t(o.budget);
  if (o.lod_delay_ms > 0) {
    // Through the graph's stage hook, so the delay sits inside the LOD frame, on its thread.
    const auto delay = std::chrono::duration<double, std::milli>(o.lod_delay_ms);
    session.graph.stage_hook = [delay](lod::Stage stage) {
      if (stage == lod::Stage::view) std::this_thread::sleep_for(delay);
    };
  }
  session.threads = loaded.config.threads ? loaded.config.threads : std::max(1u, std::thread::hardware_concurrency());
  return o.screenshot.empty() ? run_interactive(session) : run_screenshot(session);
}

}  // namespace

int main(int argc, char** argv) {
  lod::viewer::ViewerOptions o;
  CLI::App app{"lod-viewer: draws the frames lod::Service publishes (GLFW + OpenGL 3.3 core)"};
  app.footer("Keys: 1/2/3/4 camera path/fly/orbit/bird's-eye, WASD QE + right mouse to fly, wheel zooms, L freezes\n"
             "LOD, Z wireframe, C colour by level, F flat shading, [ ] halve/double M, P pauses, H hides the\n"
             "overlay, Esc quits.\n"
             "Exit codes: 0 done; 1 bad command line, config, assets or output file; 2 no display or no\n"
             "OpenGL 3.3 (headless: xvfb-run -a lod-viewer ...).");
  app.add_option("--config", o.config, "scene config (TOML)")->required();
  app.add_option("--data", o.data_dir, "mesh directory searched after the config's folder");
  app.add_option("--cache", o.cache_dir, "bake cache (default: the config's [cache] dir, else LOD_CACHE_DIR, else $XDG_CACHE_HOME/lodkit, else ~/.cache/lodkit)");
  app.add_option("--screenshot", o.screenshot, "render --frames frames along the camera path, write this PNG, exit");
  app.add_option("--frames", o.frames, "frames to render (screenshot default 1; interactive: stop after N)");
  app.add_option("--width", o.width, "window / picture width in pixels");
  app.add_option("--height", o.height, "window / picture height in pixels");
  app.add_option("--threads", o.threads, "LOD thread pool size (0 = all cores; default: the config's)");
  app.add_option("--budget", o.budget, "budget M, in the config's budget unit (default: the config's)");
  app.add_option("--lod-rate", o.lod_rate_hz, "interactive: LOD service rate in Hz (default: the config's rate_hz)");
  app.add_option("--lod-delay-ms", o.lod_delay_ms, "slow the LOD thread down: sleep this long in every LOD frame");
  app.add_option("--stats", o.stats, "write one CSV row per viewer frame");
  app.add_flag("--color-by-level,--colour-by-level", o.colour_by_level, "colour objects by their chain level");
  app.add_option("--backdrop", o.backdrop, "sky gradient and ground plane: on (default) or off (flat background)")
      ->transform(CLI::CheckedTransformer(std::map<std::string, bool>{{"on", true}, {"off", false}}))
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.add_flag("--wireframe", o.wireframe, "draw triangle edges only");
  app.add_flag("--bird-eye", o.bird_eye, "look from above the scene at what the path camera's LOD frames select");
  app.add_flag("--overlay", o.overlay, "screenshot: draw the statistics overlay too");
  bool no_vsync = false;
  app.add_flag("--no-vsync", no_vsync, "interactive: do not wait for vertical sync");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : kExitBadInput;
  }
  o.vsync = !no_vsync;
  if (o.frames == 0 || o.frames < -1) {
    std::fprintf(stderr, "lod-viewer: --frames %lld: must be at least 1\n", (long long)o.frames);
    return kExitBadInput;
  }
  if (o.lod_delay_ms < 0 || o.lod_delay_ms > 60000) {
    std::fprintf(stderr, "lod-viewer: --lod-delay-ms must be 0..60000\n");
    return kExitBadInput;
  }
  if (o.threads > 1024 || o.threads < -1 || o.budget == 0 || o.budget < -1) {
    std::fprintf(stderr, "lod-viewer: --threads must be 0..1024 and --budget at least 1\n");
    return kExitBadInput;
  }
  return run(o);
}
