// lod bake: bake mesh files into .lod assets (the same cached jobs `lod run` uses).
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "jobs/bake_jobs.h"

namespace lod::cli {

int bake_command(const BakeArgs& args) {
  std::vector<ModelConfig> models;
  for (const auto& file : args.models) {
    ModelConfig m;
    m.file = file;
    m.name = std::filesystem::path(file).stem().string();
    for (const auto& other : models)
      if (other.name == m.name) {
        std::fprintf(stderr, "lod bake: two models named '%s' (%s, %s)\n", m.name.c_str(), other.file.c_str(),
                     file.c_str());
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
    if (!args.json) std::fprintf(stderr, "%s\n", line.c_str());
  };
  if (auto st = bake_scene_models(models, args.out_dir, args.threads, chains, summary, log); !st) {
    std::fprintf(stderr, "lod bake: %s\n", st.message.c_str());
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
    std::printf("%s: %zu levels, %s in %.0f ms%s\n", c.name.c_str(), c.levels.size(),
                job.from_cache ? "from cache" : job.report.method.c_str(), job.ms,
                job.report.cleaned.changed() ? " (input cleaned)" : "");
    for (const auto& note : job.report.notes) std::printf("  note: %s\n", note.c_str());
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
  if (args.json) std::printf("%s\n", j.dump(1).c_str());
  return 0;
}

}  // namespace lod::cli
