// Overlay: the Dear ImGui panel over the scene: frame rate, the LOD thread's per-stage
// milliseconds, visible objects, triangles in view / selected / drawn / M, the level
// histogram, a plot of the last seconds, and the controls (mode, wireframe, colour by level,
// freeze LOD, budget).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "jobs/service.h"
#include "runtime/frame.h"
#include "viewer/instance_renderer.h"
#include "viewer/viewer_controls.h"

namespace lod::viewer {

struct OverlayFacts {
  double time_s = 0;          // since start
  double viewer_ms = 0;       // last viewer frame, CPU wall time
  const Frame* frame = nullptr;
  DrawStats drawn;
  uint64_t selected = 0;      // selected_as_drawn(): vd objects at their active mesh
  ServiceStats service;
  uint32_t threads = 0;       // LOD thread pool size
  size_t objects = 0;
  size_t levels_in_scene = 0;
  std::string gl;             // GL version and renderer
};

class Overlay {
 public:
  Overlay() = default;
  ~Overlay();
  Overlay(const Overlay&) = delete;
  Overlay& operator=(const Overlay&) = delete;

  // Chains GLFW callbacks installed before this call.
  bool init(GLFWwindow* window);
  // Builds and renders the panel into the bound framebuffer; `with_controls` adds the
  // widgets (a screenshot has no use for them).
  void draw(const OverlayFacts& facts, ViewerControls& controls, bool with_controls);
  bool wants_mouse() const;
  bool wants_keyboard() const;

 private:
  struct Sample {
    double t;
    float viewer_ms, lod_ms, selected_k, drawn_k;
  };
  void record(const OverlayFacts& facts);

  bool ready_ = false;
  std::vector<Sample> history_;   // last kHistorySeconds, oldest first
  std::vector<float> plot_;       // scratch for PlotLines
};

}  // namespace lod::viewer
