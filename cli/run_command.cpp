// lod run: the main job. Bake (cached) what the scene needs, then drive lod::Service frame by
// frame along the config's camera path and report what every frame did.
#include <cmath>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include "cli/budget_shortfall.h"
#include "cli/commands.h"
#include "cli/hlod_check.h"
#include "cli/run_outputs.h"
#include "cli/run_report.h"
#include "cli/run_totals.h"
#include "cli/scene_hlod_check.h"
#include "cli/stop_signals.h"
#include "cli/terrain_check.h"
#include "jobs/bake_jobs.h"
#include "jobs/cache_folder.h"
#include "jobs/hlod_scene.h"
#include "jobs/scene.h"
#include "jobs/scene_config.h"
#include "jobs/scene_hlod_bake.h"
#include "jobs/scene_motion.h"
#include "jobs/service.h"
#include "jobs/terrain_scene.h"
#include "runtime/camera_path.h"
#include "runtime/hlod_asset.h"
#include "runtime/vertex_front.h"

namespace lod::cli {
namespace {

// A normal per vertex, each of unit length or (0, 0, 0) (only degenerate faces around it).
bool unit_or_zero_normals(const Frame& f, const VdObjectFrame& o, std::string* why) {
  if (f.vd_normals.size() != f.vd_positions.size()) {
    *why = std::to_string(f.vd_normals.size()) + " normal values for " + std::to_string(f.vd_positions.size()) +
           " position values";
    return false;
  }
  for (uint32_t v = o.first_vertex; v < o.first_vertex + o.vertex_count; ++v) {
    const float* n = &f.vd_normals[3 * size_t(v)];
    const float len2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    if (len2 != 0.f && !(std::fabs(len2 - 1.f) < 1e-4f)) {
      *why = "vertex " + std::to_string(v - o.first_vertex) + " has a normal of length " + std::to_string(std::sqrt(len2));
      return false;
    }
  }
  return true;
}

// --validate for view-dependent objects: every active mesh is a valid triangulation (indices in
// range, no degenerate triangle, each directed edge once; closed inputs: every edge twice, so
// no crack or T-junction), ranges inside the frame's arrays, totals adding up, normals
// unit or zero.
bool validate_vd_objects(const Frame& f, const Scene& scene, std::string* why) {
  char buf[256];
  uint64_t tris = 0, splits = 0, collapses = 0;
  for (size_t k = 0; k < f.vd_objects.size(); ++k) {
    const VdObjectFrame& o = f.vd_objects[k];
    if (o.entry >= f.models.size() || f.objects[o.entry] != o.object ||
        scene.chains[f.models[o.entry]].hierarchy.empty()) {
      std::snprintf(buf, sizeof buf, "vd entry %zu: object %u is not view-dependent", k, o.object);
      *why = buf;
      return false;
    }
    if (uint64_t(o.first_vertex + o.vertex_count) * 3 > f.vd_positions.size() ||
        uint64_t(o.first_index) + o.index_count > f.vd_indices.size() || o.index_count % 3 != 0) {
      std::snprintf(buf, sizeof buf, "vd object %u: vertex or index range outside the frame's arrays", o.object);
      *why = buf;
      return false;
    }
    std::string bad;
    if (!check_triangles(std::span(f.vd_indices.data() + o.first_index, o.index_count), o.vertex_count,
                         o.closed ? EdgeCheck::closed : o.oriented ? EdgeCheck::oriented : EdgeCheck::corners,
                         &bad)) {
      *why = "vd object " + std::to_string(o.object) + ": " + bad;
      return false;
    }
    // Uvs for every vertex when it has them; material runs covering its indices in order.
    if (o.has_uvs && f.vd_uvs.size() != 2 * (f.vd_positions.size() / 3)) {
      std::snprintf(buf, sizeof buf, "vd object %u: %zu uv values for %zu vertices", o.object, f.vd_uvs.size(),
                    f.vd_positions.size() / 3);
      *why = buf;
      return false;
    }
    // Second uvs and colours likewise: one per vertex, finite; colours in [0, 1].
    if ((o.has_uvs1 && f.vd_uvs1.size() != 2 * (f.vd_positions.size() / 3)) ||
        (o.has_colors && f.vd_colors.size() != 4 * (f.vd_positions.size() / 3))) {
      std::snprintf(buf, sizeof buf, "vd object %u: %zu uv1 and %zu colour values for %zu vertices", o.object,
                    f.vd_uvs1.size(), f.vd_colors.size(), f.vd_positions.size() / 3);
      *why = buf;
      return false;
    }
    for (uint32_t v = o.first_vertex; v < o.first_vertex + o.vertex_count; ++v) {
      bool ok = true;
      for (int j = 0; o.has_uvs1 && j < 2; ++j) ok = ok && std::isfinite(f.vd_uvs1[2 * size_t(v) + j]);
      for (int j = 0; o.has_colors && j < 4; ++j) {
        const float c = f.vd_colors[4 * size_t(v) + j];
        ok = ok && c >= 0 && c <= 1;
      }
      if (!ok) {
        std::snprintf(buf, sizeof buf,
                      "vd object %u: vertex %u has a non-finite uv1 or a colour outside [0, 1]", o.object,
                      v - o.first_vertex);
        *why = buf;
        return false;
      }
    }
    if (!unit_or_zero_normals(f, o, &bad)) {
      *why = "vd object " + std::to_string(o.object) + ": " + bad;
      return false;
    }
    uint64_t at = o.first_index;
    for (uint32_t r = o.first_run; o.run_count && r < o.first_run + o.run_count; ++r) {
      if (r >= f.vd_runs.size() || f.vd_runs[r].first_index != at) {
        std::snprintf(buf, sizeof buf, "vd object %u: material run %u does not continue its indices", o.object, r);
        *why = buf;
        return false;
      }
      at += f.vd_runs[r].index_count;
    }
    if (o.run_count && at != uint64_t(o.first_index) + o.index_count) {
      std::snprintf(buf, sizeof buf, "vd object %u: material runs do not cover its indices", o.object);
      *why = buf;
      return false;
    }
    tris += o.index_count / 3;
    splits += o.splits;
    collapses += o.collapses;
  }
  if (tris != f.vd_active_tris || splits != f.vd_splits || collapses != f.vd_collapses) {
    *why = "vd totals do not add up over the vd objects";
    return false;
  }
  return true;
}

// --validate: the invariants every published frame must hold.
bool validate_frame(const Frame& f, const Scene& scene, uint64_t expected_index, std::string* why) {
  char buf[256];
  if (f.index != expected_index) {
    std::snprintf(buf, sizeof buf, "frame index %llu, expected %llu", (unsigned long long)f.index,
                  (unsigned long long)expected_index);
    *why = buf;
    return false;
  }
  if (f.objects.size() != f.visible || f.levels.size() != f.visible || f.morph.size() != f.visible ||
      f.models.size() != f.visible || f.handles.size() != f.visible || f.transforms.size() != f.visible ||
      f.view_masks.size() != f.visible) {
    *why = "per-object arrays do not match the visible count";
    return false;
  }
  uint64_t tris = 0;
  for (size_t i = 0; i < f.objects.size(); ++i) {
    const uint32_t id = f.objects[i];
    if (id >= f.object_count || (i > 0 && f.objects[i - 1] >= id) || f.handles[i] == 0 || f.view_masks[i] == 0) {
      std::snprintf(buf, sizeof buf, "entry %zu: object id %u out of order or range", i, id);
      *why = buf;
      return false;
    }
    const uint32_t m = f.models[i];
    if (m >= scene.models.model_count()) {
      std::snprintf(buf, sizeof buf, "object %u: model %u of %zu", id, m, scene.models.model_count());
      *why = buf;
      return false;
    }
    if (f.levels[i] >= scene.models.level_count[m]) {
      std::snprintf(buf, sizeof buf, "object %u: level %u of %u", id, f.levels[i], scene.models.level_count[m]);
      *why = buf;
      return false;
    }
    tris += scene.models.triangles[scene.models.first_level[m] + f.levels[i]];
  }
  tris += f.hlod_tris + f.scene_proxy_tris + f.terrain_tris;  // HLOD cuts, scene proxies and the terrain count in M
  if (tris != f.tris_selected) {
    std::snprintf(buf, sizeof buf, "tris_selected %llu but the levels, hlod cuts, proxies and terrain add up to %llu",
                  (unsigned long long)f.tris_selected, (unsigned long long)tris);
    *why = buf;
    return false;
  }
  return validate_vd_objects(f, scene, why);
}

}  // namespace

int run_command(const RunArgs& args) {
  const auto wall_start = std::chrono::steady_clock::now();
  const std::string data_dir = args.data_dir.empty() ? default_data_dir().string() : args.data_dir;
  SceneConfig config;
  if (auto st = load_scene_config(args.config, data_dir, config); !st) {
    std::fprintf(stderr, "lod run: %s\n", st.message.c_str());
    return 1;
  }
  if (args.frames >= 0) {
    if (args.frames == 0 || args.frames > 100000000) {
      std::fprintf(stderr, "lod run: --frames %lld: must be between 1 and 100000000\n", (long long)args.frames);
      return 1;
    }
    config.frames = uint32_t(args.frames);
  }
  if (args.threads >= 0) {
    if (args.threads > 1024) {
      std::fprintf(stderr, "lod run: --threads %lld: at most 1024\n", (long long)args.threads);
      return 1;
    }
    config.threads = uint32_t(args.threads);
  }
  if (!(args.max_seconds >= 0)) {
    std::fprintf(stderr, "lod run: --max-seconds %g: must be positive\n", args.max_seconds);
    return 1;
  }

  const std::string cache_dir = cache_dir_for(args.cache_dir, config.cache_dir).string();
  auto log = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
  // hlod = true models stream through the hlod node; the rest are discrete objects.
  auto hlod = std::make_shared<HlodModels>();
  size_t hlod_baked = 0, hlod_cached = 0;
  if (auto st = bake_hlod_models(config, cache_dir, log, *hlod, &hlod_baked, &hlod_cached); !st) {
    std::fprintf(stderr, "lod run: %s\n", st.message.c_str());
    return 1;
  }
  if (args.stream_read_delay_ms > 0 && !hlod->empty()) {  // slow storage, as the pager sees it
    const auto delay = std::chrono::duration<double, std::milli>(args.stream_read_delay_ms);
    hlod->load = [files = hlod->files, trees = hlod->trees, delay](uint32_t model, uint32_t node, HlodPayload& out) {
      std::this_thread::sleep_for(delay);
      return read_hlod_node(files[model], node, trees[model].nodes[node], out);
    };
  }
  HlodCheck hlod_check;
  if (args.validate && !hlod->empty()) {
    hlod->culled = HlodCulledNodes::cover;  // closed cuts, so every boundary edge can be checked
    hlod_check.load(*hlod);
  }
  config = discrete_part(config);
  std::vector<LodChain> chains;
  BakeSummary bake;
  if (auto st = bake_scene_models(config.models, cache_dir, config.threads, chains, bake, log); !st) {
    std::fprintf(stderr, "lod run: %s\n", st.message.c_str());
    return 1;
  }
  bake.baked += hlod_baked;
  bake.cached += hlod_cached;
  std::fprintf(stderr, "bake: %zu models (%zu baked, %zu from cache %s) in %.0f ms\n", chains.size() + hlod->trees.size(),
               bake.baked, bake.cached, cache_dir.c_str(), bake.ms);

  Scene scene = make_scene(config, std::move(chains));
  FrameGraphOptions options = frame_graph_options(config);
  // The terrain before the scene HLOD: on_terrain blocks stand on it first.
  if (auto st = load_scene_terrain(config, options.terrain); !st) {
    std::fprintf(stderr, "lod run: %s\n", st.message.c_str());
    return 1;
  }
  if (options.terrain) place_on_terrain(scene, config, *options.terrain);
  if (!hlod->empty()) options.hlod = hlod;
  auto scene_hlod = std::make_shared<SceneHlodTree>();
  if (auto st = bake_scene_hlod(config, scene, log, *scene_hlod); !st) {
    std::fprintf(stderr, "lod run: %s: %s\n", args.config.c_str(), st.message.c_str());
    return 1;
  }
  if (!scene_hlod->empty()) options.scene_hlod = scene_hlod;
  TerrainCheck terrain_check;
  std::vector<ObjectHandle> handles;
  std::unique_ptr<Service> owned = make_service(scene, options, config.rate_hz, &handles);
  SceneHlodCheck scene_hlod_check;
  if (args.validate) scene_hlod_check.load(*scene_hlod, handles);
  Service& service = *owned;
  SceneMotion motion(config, scene.objects, handles);
  // Frames are 1 / rate_hz apart on the service clock (1/60 s when the rate is unlimited).
  const double dt = config.rate_hz > 0 ? 1.0 / config.rate_hz : 1.0 / 60;
  if (motion.moving() > 0 && !args.quiet)
    std::printf("motion: %zu of %zu objects move; their transforms are staged and committed every frame (tick = "
                "frame number)\n",
                motion.moving(), scene.objects.size());

  RunSummary summary;
  summary.config = std::filesystem::path(args.config).filename().string();
  summary.objects = scene.objects.size();
  summary.models = scene.chains.size() + hlod->trees.size();
  summary.hlod_models = hlod->trees.size();
  summary.scene_hlod_nodes = scene_hlod->nodes.size();
  summary.stream_budget = hlod->empty() ? 0 : hlod->stream.budget_bytes;
  summary.threads = config.threads;
  summary.budget = config.selection.budget;
  summary.budget_count = config.selection.count == BudgetCount::levels ? "levels" : "triangles";
  summary.bake_ms = bake.ms;
  summary.baked_models = bake.baked;
  summary.cached_models = bake.cached;

  std::vector<std::string> model_names;
  for (const ModelConfig& m : config.models) model_names.push_back(m.name);
  bool told_shortfall = false;
  uint64_t told_failures = 0;  // HLOD node reads that failed, each told once  // the first over-budget frame is explained, the summary counts them all

  // Nothing here grows with the run: each frame's figures go to the files as they come, and
  // the summary and plots are kept in fixed-size running totals (cli/run_outputs.h).
  RunOutputs outputs;
  if (auto st = outputs.open(args.json_file, args.report_dir); !st) {
    std::fprintf(stderr, "lod run: %s\n", st.message.c_str());
    return 1;
  }
  RunTotals totals;
  uint64_t recorded = 0, last_frame = 0;
  FrameRecord last;
  bool last_printed = true;
  summary.frames_requested = config.frames;
  summary.max_seconds = args.max_seconds;
  const uint32_t every = config.frames <= 40 ? 1 : (config.frames + 29) / 30;
  if (!args.quiet) std::printf("%s\n%s\n", table_header().c_str(), table_legend().c_str());
  // Streaming scenes run at rate_hz in wall time: the loader threads get a frame's time per
  // frame, as under a renderer (back to back, frames take microseconds and loads trail far behind).
  const bool paced = !hlod->empty();
  const auto paced_start = std::chrono::steady_clock::now();
  const auto deadline = paced_start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                          std::chrono::duration<double>(args.max_seconds));
  StopSignals stop_signals;  // SIGINT / SIGTERM end the loop; the files and summary still follow
  for (uint32_t n = 0; n < config.frames; ++n) {
    if (const int sig = stop_signals.requested()) {
      summary.stop = RunStop::signal;
      summary.stop_signal = sig;
      break;
    }
    if (args.max_seconds > 0 && std::chrono::steady_clock::now() >= deadline) {
      summary.stop = RunStop::max_seconds;
      break;
    }
    if (paced) std::this_thread::sleep_until(paced_start + std::chrono::duration<double>(n * dt));
    if (motion.moving() > 0) {
      motion.stage(service, (n + 1) * dt);
      service.commit(n + 1);
    }
    set_view(service, 0, view_at(config.camera, n));
    if (!service.step(dt)) {
      std::fprintf(stderr, "lod run: frame %u failed; the service kept the last good frame\n", n);
      continue;
    }
    const FrameRef held = service.acquire_frame();
    const Frame& frame = *held;
    if (args.validate) {
      std::string why;
      if (!validate_frame(frame, scene, recorded == 0 ? frame.index : last_frame + 1, &why)) {
        std::fprintf(stderr, "lod run --validate: frame %u: %s\n", n, why.c_str());
        return 3;
      }
      if (!hlod_check.check(frame, &why) || !scene_hlod_check.check(frame, &why)) {
        std::fprintf(stderr, "lod run --validate: frame %u: %s\n", n, why.c_str());
        return 3;
      }
      // Counted, not fatal: the summary says on how many frames the terrain cracked.
      if (!terrain_check.check(frame, &why)) {
        if (summary.terrain_failures++ == 0)
          std::fprintf(stderr, "lod run --validate: frame %u: %s\n", n, why.c_str());
      }
      const uint64_t cost = config.selection.count == BudgetCount::levels ? frame.level_cost : frame.tris_selected;
      if (!frame.over_budget && cost > frame.budget) {
        std::fprintf(stderr, "lod run --validate: frame %u: cost %llu exceeds budget %llu without over_budget\n", n,
                     (unsigned long long)cost, (unsigned long long)frame.budget);
        return 3;
      }
    }
    if (frame.over_budget && !told_shortfall) {
      told_shortfall = true;
      if (frame.coarsest_cost <= frame.budget && frame.hlod_tris > 0)  // the discrete levels fit: HLOD did not
        std::fprintf(stderr,
                     "lod run: frame %u: budget %llu cannot be met: the hlod models' smallest cuts (%llu triangles) "
                     "exceed what the discrete objects leave of M (%llu)\n",
                     n, (unsigned long long)frame.budget, (unsigned long long)frame.hlod_tris,
                     (unsigned long long)(frame.budget - std::min(frame.budget, frame.tris_selected - frame.hlod_tris)));
      else
        std::fprintf(stderr, "lod run: frame %u: %s\n", n,
                     shortfall_text(budget_shortfall(frame, scene.models, config.selection.count), model_names).c_str());
    }
    for (; told_failures < frame.stream_failed.size(); ++told_failures) {  // each by file, node and why
      summary.stream_failed.push_back(frame.stream_failed[told_failures].message);
      std::fprintf(stderr, "lod run: frame %u: hlod read failed: %s (%s)\n", n, summary.stream_failed.back().c_str(),
                   frame.stream_failed[told_failures].node == 0 ? "the root: the model is not drawn"
                                                                : "its parent stays drawn");
    }
    last = record_of(frame);
    last_frame = last.frame;
    ++recorded;
    totals.add(last);
    if (auto st = outputs.add(last); !st) {
      std::fprintf(stderr, "lod run: frame %u: %s\n", n, st.message.c_str());
      return 1;
    }
    last_printed = !args.quiet && (n % every == 0 || n + 1 == config.frames);
    if (last_printed) std::printf("%s\n", table_row(last).c_str());
  }
  if (!args.quiet && !last_printed) std::printf("%s\n", table_row(last).c_str());  // stopped early
  summary.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  totals.fill(summary);
  summary.plot_frames_per_bucket = outputs.frames_per_bucket();
  if (summary.threads == 0) summary.threads = std::max(1u, std::thread::hardware_concurrency());
  std::printf("%s", summary_text(summary).c_str());
  const auto stats = service.stats();
  if (stats.errors) std::printf("  service errors: %llu frames lost\n", (unsigned long long)stats.errors);

  if (auto st = outputs.finish(summary, FrameGraph::dot()); !st) {
    std::fprintf(stderr, "lod run: %s\n", st.message.c_str());
    return 1;
  }
  if (!args.json_file.empty()) std::printf("  json: %s\n", args.json_file.c_str());
  if (!args.report_dir.empty())
    std::printf("  report: %s/{frames.csv,summary.json,triangles.svg,drawn.svg,levels.svg,level_changes.svg,"
                "pixel_error.svg,stage_ms.svg,graph.dot}\n",
                args.report_dir.c_str());
  std::fflush(stdout);
  // Stopped by a signal: the files are whole, the exit code is the shell's for that signal.
  if (summary.stop == RunStop::signal) return 128 + summary.stop_signal;
  if (stats.errors) return 4;
  if (summary.terrain_failures > 0) {
    std::fprintf(stderr, "lod run --validate: the terrain failed the crack check on %zu frames\n",
                 summary.terrain_failures);
    return 3;
  }
  if (args.strict_exit && summary.over_budget_frames > 0) {
    std::fprintf(stderr, "lod run --strict-exit: the coarsest levels exceeded the budget on %zu of %zu frames\n",
                 summary.over_budget_frames, summary.frames);
    return 5;
  }
  return 0;
}

}  // namespace lod::cli
