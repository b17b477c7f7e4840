// lod bake: bake mesh files into .lod assets (the same cached jobs `lod run` uses).
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/names.h"
#include "jobs/bake_jobs.h"

namespace lod::cli {

int bake_command(const BakeArgs& args) {
  if (args.distributed) return bake_distributed_command(args);
  if (!args.cache_dir.empty() || args.subtrees || args.entry_memory_mb || !args.mesh_copies.empty()) {
    std::fprintf(stderr,
                 "lod bake: --cache, --subtrees, --entry-memory-mb and --mesh-copies are options of --distributed\n");
    return 1;
  }
  if (args.hlod) return bake_hlod_command(args);
  // The config's rules for ratios: 1 first, each in (0, 1], strictly decreasing, at most 16
  // (a repeated ratio used to drop a level silently).
  if (!args.ratios.empty()) {
    if (args.ratios.size() > 16) {
      std::fprintf(stderr, "lod bake: --ratios: %zu levels given, at most 16\n", args.ratios.size());
      return 1;
    }
    for (size_t k = 0; k < args.ratios.size(); ++k) {
      const float v = args.ratios[k];
      const char* why = !(v > 0 && v <= 1)                    ? "must be in (0, 1]"
                        : k == 0 && v != 1                    ? "must be 1: level 0 is the full mesh"
                        : k > 0 && !(v < args.ratios[k - 1]) ? "ratios must decrease"
                                                               : nullptr;
      if (!why) continue;
      if (k > 0 && v == args.ratios[k - 1])
        std::fprintf(stderr, "lod bake: --ratios: ratio %zu (%g) repeats the one before; %s\n", k, double(v), why);
      else if (k > 0 && v > args.ratios[k - 1])
        std::fprintf(stderr, "lod bake: --ratios: ratio %zu (%g) is above the one before (%g); %s\n", k, double(v),
                     double(args.ratios[k - 1]), why);
      else
        std::fprintf(stderr, "lod bake: --ratios: ratio %zu (%g) %s\n", k, double(v), why);
      return 1;
    }
  }
  std::vector<ModelConfig> models;
  for (const auto& file : args.models) {
    ModelConfig m;
    m.file = file;
    m.name = std::filesystem::path(file).stem().string();
    for (const auto& other : models)
      if (other.name == m.name) {
        std::fprintf(stderr, "lod bake: two models named '%s' (%s, %s)\n", printable(m.name).c_str(),
                     printable(other.file.string()).c_str(), printable(file).c_str());
        return 1;
      }
    m.bake.ratios = args.ratios;
    m.bake.method = args.method == "qem"       ? SimplifyMethod::qem
                    : args.method == "extreme" ? SimplifyMethod::extreme
                                               : SimplifyMethod::automatic;
    models.push_back(std::move(m));
  }
  std::vector<LodChain> chains;
  BakeSummary summary;
  auto log = [&](const std::string& line) {
    if (!args.json && !args.quiet) std::fprintf(stderr, "%s\n", printable(line).c_str());
  };
  if (auto st = bake_scene_models(models, args.out_dir, static_cast<uint32_t>(args.threads), chains, summary, log);
      !st) {
    std::fprintf(stderr, "lod bake: %s\n", printable(st.message).c_str());
    return 1;
  }
  nlohmann::json j = nlohmann::json::array();
  for (size_t i = 0; i < chains.size(); ++i) {
    const auto& c = chains[i];
    const auto& job = summary.jobs[i];
    if (args.json) {
      nlohmann::json levels = nlohmann::json::array();
      for (const auto& l : c.levels)
        levels.push_back({{"triangles", l.triangles()}, {"l", l.level}, {"error", l.error}, {"error_rms", l.error_rms}});
      j.push_back({{"model", c.name},
                   {"from_cache", job.from_cache},
                   {"ms", job.ms},
                   {"method", job.report.method},
                   {"notes", job.report.notes},
                   {"levels", levels}});
      continue;
    }
    if (args.quiet) continue;
    std::printf("%s: %zu levels, %s in %.0f ms%s\n", printable(c.name).c_str(), c.levels.size(),
                job.from_cache ? "from cache" : job.report.method.c_str(), job.ms,
                job.report.cleaned.changed() ? " (input cleaned)" : "");
    for (const auto& note : job.report.notes) std::printf("  note: %s\n", printable(note).c_str());
    {
      const float diag = 2 * (c.levels.empty() ? 1.f : c.levels[0].bounds.radius);
      for (size_t k = 0; k < c.levels.size(); ++k) {
        const auto& l = c.levels[k];
        if (args.measure)
          std::printf("  level %zu: %9u tris  l=%2d  hausdorff max %.6g (%.4f%% of diameter)  rms %.6g\n", k,
                      l.triangles(), l.level, l.error, 100.0 * l.error / diag, l.error_rms);
        else
          std::printf("  level %zu: %9u tris  l=%2d\n", k, l.triangles(), l.level);
      }
    }
  }
  if (args.json) std::printf("%s\n", j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  return 0;
}

}  // namespace lod::cli
