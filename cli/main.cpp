// lod: bake meshes into LOD assets, run the LOD service along a camera path, inspect assets.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "cli/commands.h"
#include "cli/freed_memory.h"
#include "cli/huge_page_malloc.h"

namespace {

int run_main(int argc, char** argv) {
  CLI::App app{"lodkit: multithreaded level-of-detail runtime"};
  app.require_subcommand(1);

  lod::cli::RunArgs run;
  auto* run_cmd = app.add_subcommand("run", "bake what the scene needs (cached), then run the LOD service headless");
  run_cmd->add_option("--config", run.config, "scene config (TOML)")->required();
  // Ranges checked here: -1 is only the internal "not given" (an explicit negative count is
  // refused, not read as "use the config").
  run_cmd->add_option("--frames", run.frames, "frames along the camera path (default: config)")
      ->check(CLI::Range(int64_t{1}, int64_t{100000000}));
  run_cmd->add_option("--threads", run.threads, "worker threads, 0 = all cores (default: config)")
      ->check(CLI::Range(int64_t{0}, int64_t{1024}));
  run_cmd->add_option("--data", run.data_dir, "mesh directory searched after the config's folder");
  run_cmd->add_option("--cache", run.cache_dir, "baked asset cache (default: the config's [cache] dir, else $LOD_CACHE_DIR, else "
                 "$XDG_CACHE_HOME/lodkit or ~/.cache/lodkit)");
  run_cmd->add_option("--json", run.json_file, "write per-frame figures and a summary as JSON");
  run_cmd->add_option("--report", run.report_dir, "write frames.csv, summary.json, graph.dot and SVG plots here");
  run_cmd->add_flag("--validate", run.validate, "check every frame's invariants; fail on the first bad one");
  run_cmd->add_flag("--quiet", run.quiet, "no per-frame table");
  run_cmd->add_flag("--strict-exit", run.strict_exit,
                    "exit with code 5 when the coarsest levels exceed the budget on any frame");
  run_cmd->add_option("--stream-read-delay-ms", run.stream_read_delay_ms,
                      "measuring: every HLOD node read sleeps this long first (slow storage)")
      ->check(CLI::Range(0.0, 10000.0));
  run_cmd->add_option("--max-seconds", run.max_seconds,
                      "stop after this many wall seconds of frames (not counting the bake); the files and summary "
                      "hold the frames run")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            char* end = nullptr;
            const double v = std::strtod(text.c_str(), &end);
            if (text.empty() || *end != '\0' || !(v > 0) || !std::isfinite(v))
              return "'" + text + "' is not a positive number of seconds";
            return "";
          },
          "SECONDS > 0"));

  lod::cli::InspectArgs inspect;
  auto* inspect_cmd = app.add_subcommand("inspect", "print a .lod asset's levels or an .hlod file's tree");
  inspect_cmd->add_option("file", inspect.file, ".lod or .hlod file")->required();
  inspect_cmd->add_flag("--json", inspect.json, "print JSON");
  inspect_cmd->add_flag("--verify", inspect.verify,
                        "an .hlod file: check every node payload; exit 2 naming each damaged node, 0 when sound");
  inspect_cmd->add_option("--export", inspect.export_dir, "write every level into this directory (as --format)");
  inspect_cmd->add_option("--format", inspect.format, "format of --export: ply (default) | obj | glb | gltf")
      ->check(CLI::IsMember({"ply", "obj", "glb", "gltf"}));

  lod::cli::BakeArgs bake;
  auto* bake_cmd = app.add_subcommand("bake", "bake meshes into .lod assets");
  bake_cmd->add_option("models", bake.models, "mesh files (OBJ, PLY, OFF, STL, glTF: .gltf/.glb)")->required();
  bake_cmd->add_option("-o,--out", bake.out_dir, "output directory")->required();
  bake_cmd->add_option("--ratios", bake.ratios, "level ratios, 1.0 first (default: by size)");
  bake_cmd->add_option("--method", bake.method, "qem | extreme | auto")
      ->check(CLI::IsMember({"qem", "extreme", "auto"}));
  bake_cmd->add_option("--threads", bake.threads, "worker threads, 0 = all cores")
      ->check(CLI::Range(int64_t{0}, int64_t{1024}));
  bake_cmd->add_flag("--measure", bake.measure, "print each level's measured error");
  bake_cmd->add_flag("--json", bake.json, "print JSON");
  bake_cmd->add_flag("--quiet", bake.quiet, "print nothing but errors");
  bake_cmd->add_flag("--hlod", bake.hlod, "write an .hlod octree (precomputed model HLOD) per mesh instead of a .lod chain");
  bake_cmd->add_option("--min-verts", bake.min_verts, "--hlod: a cell with more vertices splits (default 1000)")
      ->check(CLI::Range(int64_t{3}, int64_t{100000000}));
  bake_cmd->add_flag("--distributed", bake.distributed,
                     "--hlod over MPI ranks: run under mpirun -np N (lod-bake-mpi does the bake; same bytes)");
  bake_cmd->add_option("--cache", bake.cache_dir,
                       "--distributed: subtree cache on storage every rank sees (default OUT/hlod-cache)");
  bake_cmd->add_option("--subtrees", bake.subtrees, "--distributed: subtrees to split into (default 8 per rank, at least 16)")
      ->check(CLI::Range(int64_t{0}, int64_t{1} << 20));
  bake_cmd->add_option("--entry-memory-mb", bake.entry_memory_mb,
                       "--distributed: MB of cache entries a rank holds for its write (default 0)")
      ->check(CLI::Range(uint64_t{0}, uint64_t{1} << 40));
  bake_cmd->add_option("--mesh-copies", bake.mesh_copies,
                       "--distributed: the mesh once per node (shared by its ranks) or per rank (default auto: per "
                       "node where a node runs 8 ranks or more)")
      ->check(CLI::IsMember({"auto", "node", "rank"}));

  lod::cli::ExportArgs exp;
  auto* export_cmd = app.add_subcommand("export", "write an .hlod file as an OGC 3D Tiles 1.1 tileset");
  export_cmd->add_option("--3dtiles", exp.tiles_dir, "folder for tileset.json and tiles/*.glb")->required();
  export_cmd->add_option("file", exp.file, ".hlod file")->required();
  export_cmd->add_flag("--force", exp.force, "replace DIR when it holds an earlier export (a tileset.json)");
  export_cmd->add_flag("--shared-images", exp.shared_images,
                       "write each texture once under DIR/textures and reference it from the GLBs (default: embedded in each)");
  export_cmd->add_flag("--json", exp.json, "print JSON");

  CLI11_PARSE(app, argc, argv);
  if (run_cmd->parsed()) return lod::cli::run_command(run);
  if (inspect_cmd->parsed()) return lod::cli::inspect_command(inspect);
  if (bake_cmd->parsed()) {
    lod::cli::keep_freed_memory();  // a batch job: what one phase frees, the next reuses
    return lod::cli::bake_command(bake);
  }
  if (export_cmd->parsed()) return lod::cli::export_command(exp);
  return 2;
}

}  // namespace

// Exit codes: the subcommand's (cli/commands.h); 1 as well when an exception escapes one
// (std::bad_alloc, say): "lod: <what>" on stderr instead of an abort.
int main(int argc, char** argv) {
  lod::cli::restart_with_huge_page_malloc(argv);
  try {
    return run_main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lod: %s\n", e.what());
  } catch (...) {
    std::fprintf(stderr, "lod: an unknown exception\n");
  }
  return 1;
}
