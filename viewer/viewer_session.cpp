#include "viewer/viewer_session.h"

#include <algorithm>
#include <bit>
#include <cstdio>

#include "jobs/service.h"
#include "viewer/frame_check.h"

namespace lod::viewer {

View ViewerSession::lens(int width, int height) const {
  View v = loaded.config.camera.lens;
  v.width = width;
  v.height = height;
  return v;
}

std::unique_ptr<Service> ViewerSession::make_service(double rate_hz) {
  spheres = model_spheres(loaded.scene.chains);
  return lod::make_service(loaded.scene, graph, rate_hz, &handles);
}

View ViewerSession::overhead(const Frame& frame, const View& lens) const {
  return overhead_view(loaded.scene.objects, frame, spheres, lens);
}

OverlayFacts ViewerSession::overlay_facts(const Frame* frame, const DrawStats& drawn,
                                          const ServiceStats& service, double time_s,
                                          double viewer_ms) const {
  OverlayFacts facts;
  facts.time_s = time_s;
  facts.viewer_ms = viewer_ms;
  facts.frame = frame;
  facts.selected = frame ? selected_as_drawn(*frame, renderer.draw_list()) : 0;
  facts.drawn = drawn;
  facts.service = service;
  facts.threads = threads;
  facts.objects =
      frame ? frame->object_count : loaded.scene.objects.size();  // live objects at the frame's tick
  facts.levels_in_scene = max_levels();
  facts.gl = window.description();
  return facts;
}

size_t ViewerSession::max_levels() const {
  size_t n = 0;
  for (uint8_t c : loaded.scene.models.level_count) n = std::max<size_t>(n, c);
  return n;
}

const FrameRow& ViewerSession::record(uint64_t viewer_frame, const Frame& frame, const DrawStats& drawn,
                                      double viewer_ms, double service_ms) {
  FrameRow row;
  row.viewer_frame = viewer_frame;
  row.lod_frame = frame.index;
  row.visible = frame.visible;
  row.tris_selected = selected_as_drawn(frame, renderer.draw_list());
  row.drawn = drawn.triangles;
  row.morphing = frame.morphing;
  row.morph_extra = frame.tris_morph_extra;
  row.morph_draws = drawn.morph_draws;
  row.vd_objects = drawn.vd_draws;
  row.vd_drawn = drawn.vd_triangles;
  row.gpu_primitives = drawn.gpu_primitives;
  row.draws = drawn.draws;
  row.hlod_nodes = frame.hlod_nodes_drawn;
  row.hlod_draws = drawn.hlod_draws;
  row.hlod_drawn = drawn.hlod_triangles;
  row.hlod_missing = drawn.hlod_missing + renderer.hlod_list().rejected;
  row.resident_bytes = frame.resident_bytes;
  row.gpu_node_bytes = renderer.hlod_nodes().bytes();
  row.proxies = drawn.proxy_draws;
  row.proxy_drawn = drawn.proxy_triangles;
  row.proxy_objects = frame.scene_proxy_objects;
  uint64_t levels = 0;  // bit per chain level (< kMaxLevels)
  for (const DrawBatch& b : renderer.draw_list().batches) levels |= uint64_t(1) << b.level;
  row.levels_drawn = uint32_t(std::popcount(levels));
  row.rejected = renderer.draw_list().rejected + renderer.proxy_list().rejected;
  std::string why;
  row.whole = frame_is_whole(frame, loaded.scene, &why) ? 1 : 0;
  if (!row.whole)
    std::fprintf(stderr, "lod-viewer: viewer frame %llu drew LOD frame %llu that is not whole: %s\n",
                 (unsigned long long)viewer_frame, (unsigned long long)frame.index, why.c_str());
  row.viewer_ms = viewer_ms;
  row.lod_ms = frame.total_ms;
  row.service_ms = service_ms;
  log.add(row);
  return log.rows().back();
}

bool ViewerSession::finish(const char* mode_name) {
  const FrameTimeSummary s = log.summary(log.rows().size() > 20 ? 10 : 0);
  std::fprintf(stderr,
               "lod-viewer %s: %zu frames, viewer frame ms mean %.2f p50 %.2f p95 %.2f p99 %.2f max %.2f; "
               "at most %.3f ms in lod::Service calls; %llu distinct LOD frames drawn\n",
               mode_name, s.frames, s.mean_ms, s.p50_ms, s.p95_ms, s.p99_ms, s.max_ms,
               s.service_max_ms, (unsigned long long)s.lod_frames_seen);
  if (options.stats.empty()) return true;
  if (Status st = log.write_csv(options.stats); !st) {
    std::fprintf(stderr, "lod-viewer: %s\n", st.message.c_str());
    return false;
  }
  return true;
}

}  // namespace lod::viewer
