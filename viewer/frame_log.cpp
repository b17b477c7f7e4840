#include "viewer/frame_log.h"

#include <algorithm>
#include <cstdio>
#include <set>

namespace lod::viewer {

FrameTimeSummary FrameLog::summary(size_t skip) const {
  FrameTimeSummary s;
  std::set<uint64_t> lod_frames;
  for (const FrameRow& r : rows_) lod_frames.insert(r.lod_frame);
  s.lod_frames_seen = lod_frames.size();
  if (rows_.size() <= skip) return s;
  std::vector<double> ms;
  for (size_t i = skip; i < rows_.size(); ++i) {
    ms.push_back(rows_[i].viewer_ms);
    s.service_max_ms = std::max(s.service_max_ms, rows_[i].service_ms);
  }
  std::sort(ms.begin(), ms.end());
  auto at = [&](double q) { return ms[std::min(ms.size() - 1, size_t(q * double(ms.size())))]; };
  s.frames = ms.size();
  for (double m : ms) s.mean_ms += m;
  s.mean_ms /= double(ms.size());
  s.p50_ms = at(0.50);
  s.p95_ms = at(0.95);
  s.p99_ms = at(0.99);
  s.max_ms = ms.back();
  return s;
}

Status FrameLog::write_csv(const std::filesystem::path& path) const {
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return Status::error(path.string() + ": cannot write the frame statistics");
  std::fprintf(f, "viewer_frame,lod_frame,visible,tris_selected,drawn,gpu_primitives,draws,levels_drawn,rejected,"
                  "whole,viewer_ms,lod_ms,service_ms,vd_objects,vd_drawn,morphing,morph_extra,morph_draws,"
                  "hlod_nodes,hlod_draws,hlod_drawn,hlod_missing,resident_bytes,gpu_node_bytes,proxies,proxy_drawn,"
                  "proxy_objects\n");
  for (const FrameRow& r : rows_) {
    std::fprintf(f, "%llu,%llu,%u,%llu,%llu,%lld,%u,%u,%u,%d,%.4f,%.4f,%.4f,%u,%llu,%u,%llu,%u,%u,%u,%llu,%u,%llu,%llu,%u,%llu,%u\n", (unsigned long long)r.viewer_frame,
                 (unsigned long long)r.lod_frame, r.visible, (unsigned long long)r.tris_selected,
                 (unsigned long long)r.drawn, (long long)r.gpu_primitives, r.draws, r.levels_drawn, r.rejected,
                 r.whole, r.viewer_ms, r.lod_ms, r.service_ms, r.vd_objects, (unsigned long long)r.vd_drawn,
                 r.morphing, (unsigned long long)r.morph_extra, r.morph_draws, r.hlod_nodes, r.hlod_draws,
                 (unsigned long long)r.hlod_drawn, r.hlod_missing, (unsigned long long)r.resident_bytes,
                 (unsigned long long)r.gpu_node_bytes, r.proxies, (unsigned long long)r.proxy_drawn,
                 r.proxy_objects);
  }
  const bool ok = std::fclose(f) == 0;
  return ok ? Status::success() : Status::error(path.string() + ": write failed");
}

}  // namespace lod::viewer
