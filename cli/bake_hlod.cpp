// lod bake --hlod: one .hlod file per mesh (Zhou and Tian's model HLOD), with progress on stderr.
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/names.h"
#include "jobs/hlod_bake.h"

namespace lod::cli {

int bake_hlod_command(const BakeArgs& args) {
  if (!args.ratios.empty() || args.method != "auto") {
    std::fprintf(stderr, "lod bake: --ratios and --method do not apply to --hlod (its layers halve, by QEM)\n");
    return 1;
  }
  for (size_t a = 0; a < args.models.size(); ++a)
    for (size_t b = 0; b < a; ++b)
      if (std::filesystem::path(args.models[a]).stem() == std::filesystem::path(args.models[b]).stem()) {
        std::fprintf(stderr, "lod bake: two models named '%s' (%s, %s) would write one .hlod file\n",
                     printable(std::filesystem::path(args.models[a]).stem().string()).c_str(),
                     printable(args.models[b]).c_str(), printable(args.models[a]).c_str());
        return 1;
      }
  nlohmann::json j = nlohmann::json::array();
  for (const auto& file : args.models) {
    const std::string name = std::filesystem::path(file).stem().string();
    HlodBakeSettings settings;
    settings.min_verts = static_cast<uint32_t>(args.min_verts);
    settings.threads = static_cast<uint32_t>(args.threads);
    auto log = [&](const std::string& line) {
      if (!args.json && !args.quiet) std::fprintf(stderr, "%s\n", printable(line).c_str());
    };
    HlodBakeResult r;
    if (Status st = bake_hlod_file(file, name, args.out_dir, settings, log, &r); !st) {
      std::fprintf(stderr, "lod bake: %s\n", printable(st.message).c_str());
      return 1;
    }
    const HlodBuildReport& rep = r.report;
    if (args.json) {
      j.push_back({{"model", name},
                   {"file", r.file.string()},
                   {"bytes", r.bytes},
                   {"input_triangles", r.input_triangles},
                   {"nodes", rep.nodes},
                   {"leaves", rep.leaves},
                   {"depth", rep.depth},
                   {"boundary_triangles", rep.boundary_triangles},
                   {"oversized_leaves", rep.oversized_leaves},
                   {"short_layers", rep.short_layers},
                   {"load_s", r.load_seconds},
                   {"build_s", r.build_seconds},
                   {"write_s", r.write_seconds}});
      continue;
    }
    if (args.quiet) continue;
    std::printf("%s: %zu triangles -> %zu nodes (%zu leaves, depth %u), %zu boundary triangles, %.2f MB in %s\n",
                printable(name).c_str(), r.input_triangles, rep.nodes, rep.leaves, rep.depth, rep.boundary_triangles,
                double(r.bytes) / 1e6, printable(r.file.string()).c_str());
    std::printf("  load %.2f s, build %.2f s, write %.2f s\n", r.load_seconds, r.build_seconds, r.write_seconds);
    if (rep.oversized_leaves)
      std::printf("  note: %zu leaves above %lld vertices (the octree's depth limit)\n", rep.oversized_leaves,
                  (long long)args.min_verts);
    if (rep.dropped_triangles) std::printf("  note: %zu degenerate triangles dropped\n", rep.dropped_triangles);
  }
  if (args.json) std::printf("%s\n", j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  return 0;
}

}  // namespace lod::cli
