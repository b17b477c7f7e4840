#include "viewer/overlay.h"

#include <algorithm>
#include <cstdio>

#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include "viewer/level_palette.h"

namespace lod::viewer {

namespace {

constexpr double kHistorySeconds = 10;

std::string thousands(uint64_t v) {
  // Built by appending: GCC 12 gives a false -Wrestrict on string::insert here.
  const std::string digits = std::to_string(v);
  std::string s;
  s.reserve(digits.size() + digits.size() / 3);
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) s.push_back(',');
    s.push_back(digits[i]);
  }
  return s;
}

}  // namespace

Overlay::~Overlay() {
  if (!ready_) return;
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
}

bool Overlay::init(GLFWwindow* window) {
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini next to the user's files
  ImGui::StyleColorsDark();
  if (!ImGui_ImplGlfw_InitForOpenGL(window, true) || !ImGui_ImplOpenGL3_Init("#version 330")) {
    ImGui::DestroyContext();
    return false;
  }
  ready_ = true;
  return true;
}

bool Overlay::wants_mouse() const { return ready_ && ImGui::GetIO().WantCaptureMouse; }
bool Overlay::wants_keyboard() const { return ready_ && ImGui::GetIO().WantCaptureKeyboard; }

void Overlay::record(const OverlayFacts& f) {
  Sample s{f.time_s, float(f.viewer_ms), f.frame ? float(f.frame->total_ms) : 0.f,
           f.frame ? float(f.selected) / 1000.f : 0.f, float(f.drawn.triangles) / 1000.f};
  history_.push_back(s);
  const auto first_kept = std::find_if(history_.begin(), history_.end(),
                                       [&](const Sample& x) { return x.t >= f.time_s - kHistorySeconds; });
  history_.erase(history_.begin(), first_kept);
}

void Overlay::draw(const OverlayFacts& f, ViewerControls& c, bool with_controls) {
  if (!ready_) return;
  record(f);
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();

  ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowBgAlpha(0.8f);
  ImGui::Begin("lod-viewer", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
  // Headline figures always; stage times, graphs and controls in sections that start closed,
  // so the window stays a small corner of the picture.
  ImGui::Text("%.1f fps  %.2f ms  |  LOD %.2f ms", f.viewer_ms > 0 ? 1000.0 / f.viewer_ms : 0.0, f.viewer_ms,
              f.frame ? f.frame->total_ms : 0.0);

  if (const Frame* fr = f.frame) {
    ImGui::Text("visible %s / %s  in view %s tris", thousands(fr->visible).c_str(), thousands(f.objects).c_str(),
                thousands(fr->tris_in_view).c_str());
    ImGui::Text("selected %s  drawn %s (%u draws)", thousands(f.selected).c_str(),
                thousands(f.drawn.triangles).c_str(), f.drawn.draws);
    // Both figures count view-dependent objects at their active mesh, not their level.
    if (!fr->vd_objects.empty())
      ImGui::Text("view-dep.    %u objects, %s active tris drawn", f.drawn.vd_draws,
                  thousands(f.drawn.vd_triangles).c_str());
    // Objects blending between two levels are drawn at the finer one until they settle.
    if (fr->morphing)
      ImGui::Text("morphing     %u objects, +%s tris drawn", fr->morphing, thousands(fr->tris_morph_extra).c_str());
    ImGui::Text("budget M %s%s", thousands(fr->budget).c_str(), fr->over_budget ? "  (over: coarsest levels)" : "");
    if (!fr->scene_proxies.empty())
      ImGui::Text("proxies      %zu drawn for %s objects, %s tris", fr->scene_proxies.size(),
                  thousands(fr->scene_proxy_objects).c_str(), thousands(f.drawn.proxy_triangles).c_str());
    // HLOD cuts: what the pager holds for the LOD thread, against its byte budget.
    if (fr->stream_budget)
      ImGui::Text("hlod         %u nodes, %s tris; resident %.2f / %.2f MB, %llu loads, %u holes", fr->hlod_nodes_drawn,
                  thousands(f.drawn.hlod_triangles).c_str(), double(fr->resident_bytes) / (1 << 20),
                  double(fr->stream_budget) / (1 << 20), (unsigned long long)fr->stream_loads, fr->holes);

    if (ImGui::CollapsingHeader("LOD stages")) {
      ImGui::TextDisabled("%s", f.gl.c_str());
      ImGui::Text("LOD thread: %u threads, %llu frames, %.2f ms mean, %llu errors", f.threads,
                  (unsigned long long)f.service.frames, f.service.mean_ms, (unsigned long long)f.service.errors);
      ImGui::Text("LOD frame %llu: %.3f ms", (unsigned long long)fr->index, fr->total_ms);
      if (ImGui::BeginTable("stages", 4, ImGuiTableFlags_SizingFixedFit)) {
        for (size_t s = 0; s < kStageCount; ++s) {
          ImGui::TableNextColumn();
          ImGui::Text("%s", kStageNames[s]);
          ImGui::TableNextColumn();
          ImGui::Text("%7.3f ms", fr->stage_ms[s]);
        }
        ImGui::EndTable();
      }
    }
  } else {
    ImGui::Text("waiting for the first LOD frame");
  }

  const bool graphs = ImGui::CollapsingHeader("graphs");
  if (const Frame* fr = f.frame; fr && graphs) {
    // Level histogram over Yu, Liang and Chen's l = round(log2 tris): only the occupied span.
    size_t lo = kHistogramLevels, hi = 0;
    for (size_t l = 0; l < kHistogramLevels; ++l)
      if (fr->level_histogram[l]) lo = std::min(lo, l), hi = std::max(hi, l);
    if (lo <= hi) {
      plot_.assign(fr->level_histogram.begin() + long(lo), fr->level_histogram.begin() + long(hi) + 1);
      char label[64];
      std::snprintf(label, sizeof label, "objects per l\n(l = %zu..%zu)", lo, hi);
      ImGui::PlotHistogram(label, plot_.data(), int(plot_.size()), 0, nullptr, 0.f, FLT_MAX, ImVec2(260, 60));
    }
  }

  if (graphs && history_.size() > 1) {
    auto plot = [&](const char* label, float Sample::*field, const char* unit) {
      plot_.clear();
      float top = 0;
      for (const Sample& s : history_) plot_.push_back(s.*field), top = std::max(top, s.*field);
      char overlay[64];
      std::snprintf(overlay, sizeof overlay, "%.2f %s", double(plot_.back()), unit);
      ImGui::PlotLines(label, plot_.data(), int(plot_.size()), 0, overlay, 0.f, top * 1.1f + 1e-3f, ImVec2(260, 40));
    };
    plot("viewer ms", &Sample::viewer_ms, "ms");
    plot("LOD ms", &Sample::lod_ms, "ms");
    plot("selected k", &Sample::selected_k, "k tris");
  }

  if (with_controls && ImGui::CollapsingHeader("controls")) {
    int mode = int(c.mode);
    ImGui::Text("camera");
    for (int m = 0; m < kCameraModeCount; ++m) {
      ImGui::SameLine();
      ImGui::RadioButton(kCameraModeNames[m], &mode, m);
    }
    c.mode = CameraMode(mode);
    ImGui::Checkbox("pause path [P]", &c.paused);
    ImGui::SameLine();
    ImGui::Checkbox("freeze LOD [L]", &c.freeze_lod);
    ImGui::Checkbox("wireframe [Z]", &c.wireframe);
    ImGui::SameLine();
    ImGui::Checkbox("colour by level [C]", &c.colour_by_level);
    ImGui::SameLine();
    ImGui::Checkbox("flat [F]", &c.flat_normals);
    ImGui::SameLine();
    ImGui::Checkbox("sky, ground [B]", &c.backdrop);
    uint64_t budget = c.budget;
    const uint64_t lo = 1000, hi = 100000000;
    if (ImGui::SliderScalar("budget M [ ]", ImGuiDataType_U64, &budget, &lo, &hi, "%llu",
                            ImGuiSliderFlags_Logarithmic)) {
      c.budget = budget;
      c.budget_changed = true;
    }
    ImGui::TextDisabled("1/2/3/4 path/fly/orbit/bird's-eye, WASD QE + right mouse,\nwheel, H hides, Esc quits");
  }
  if (c.colour_by_level) {
    ImGui::Text("level");
    for (size_t l = 0; l < std::min<size_t>(f.levels_in_scene, kLevelPalette.size()); ++l) {
      const auto& col = level_colour(l);
      ImGui::SameLine();
      ImGui::TextColored(ImVec4(col[0], col[1], col[2], 1), "%zu", l);
    }
  }
  if (with_controls) ImGui::TextDisabled("H hides, Esc quits");
  ImGui::End();

  ImGui::Render();
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

}  // namespace lod::viewer
