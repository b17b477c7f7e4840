// ViewerControls: what the person at the viewer has chosen (keys and overlay widgets both
// write here; the frame loop reads it).
#pragma once
#include <cstdint>

namespace lod::viewer {

// overhead: the LOD camera follows the path while the picture is seen from above the scene.
enum class CameraMode : uint8_t { path, fly, orbit, overhead };
inline constexpr const char* kCameraModeNames[] = {"camera path", "fly", "orbit", "bird's-eye"};
inline constexpr int kCameraModeCount = 4;

struct ViewerControls {
  CameraMode mode = CameraMode::path;
  bool paused = false;          // camera path stops advancing
  bool wireframe = false;
  bool colour_by_level = false;
  bool backdrop = true;         // sky and ground
  bool flat_normals = false;
  bool freeze_lod = false;      // the LOD camera stays where it was; the viewing camera moves on
  bool show_overlay = true;
  uint64_t budget = 0;          // M, as last sent to the service
  bool budget_changed = false;  // set by a widget or key, cleared once the service has it
  bool quit = false;
};

}  // namespace lod::viewer
