// The `lod` subcommands. Each returns the process exit code.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace lod::cli {

struct RunArgs {
  std::string config;
  std::string data_dir;      // empty = default_data_dir()
  std::string cache_dir;     // empty = cache_dir_for's default (jobs/cache_folder.h)
  std::string json_file;
  std::string report_dir;
  int64_t frames = -1;       // -1 = config
  int64_t threads = -1;      // -1 = config
  bool validate = false;
  bool quiet = false;
  bool strict_exit = false;  // exit 5 when any frame's coarsest levels exceed M
  double stream_read_delay_ms = 0;  // every HLOD node read sleeps first (measuring slow storage)
  double max_seconds = 0;    // stop after this many wall seconds of frames (the bake before them not counted); 0 = none
};
// Exit codes: 0 all frames run (or stopped by --max-seconds), 1 an error (bad input, a file that
// cannot be written), 3 --validate found a bad frame, 4 the service lost frames, 5 --strict-exit
// and a frame over budget, 128 + the signal's number (130 SIGINT, 143 SIGTERM) when a signal
// stopped it: the frames run so far are in the files and the summary, complete and consistent.
// Memory does not grow with --frames (docs/lod-run.md).
int run_command(const RunArgs& args);

struct InspectArgs {
  std::string file;
  bool json = false;
  std::string export_dir;
  std::string format = "ply";  // of --export: ply | obj | glb | gltf
  // An .hlod file: read every node's payload and check it (its checksum, its counts); exit 2
  // naming each bad node when any is damaged, 0 when all are sound. (A .lod is checked in full
  // whenever it is read.)
  bool verify = false;
};
int inspect_command(const InspectArgs& args);
// The .hlod side of `lod inspect` (cli/inspect_hlod.cpp): true when `file` starts with the
// .hlod magic bytes.
bool is_hlod_file(const std::string& file);
int inspect_hlod_command(const InspectArgs& args);

struct BakeArgs {
  std::vector<std::string> models;
  std::string out_dir;
  std::vector<float> ratios;
  std::string method = "auto";
  int64_t threads = 0;
  bool measure = false;
  bool json = false;
  bool quiet = false;  // nothing but errors (no progress, no table)
  bool hlod = false;   // write DIR/<name>.hlod (Zhou and Tian's model HLOD) instead of .lod chains
  int64_t min_verts = 1000;
  // --hlod --distributed: the bake over MPI ranks (lod-bake-mpi); the options only it takes.
  bool distributed = false;
  std::string cache_dir;         // empty = <out_dir>/hlod-cache
  int64_t subtrees = 0;          // 0 = lod-bake-mpi's default
  uint64_t entry_memory_mb = 0;
  std::string mesh_copies;  // --distributed: auto, node or rank (empty: lod-bake-mpi's default)
};
int bake_command(const BakeArgs& args);
int bake_hlod_command(const BakeArgs& args);         // cli/bake_hlod.cpp
int bake_distributed_command(const BakeArgs& args);  // cli/bake_distributed.cpp: execs lod-bake-mpi
std::string distributed_cache_dir(const BakeArgs& args);

struct ExportArgs {
  std::string file;       // the .hlod file
  std::string tiles_dir;  // --3dtiles DIR
  bool force = false;     // replace DIR when it holds an earlier export
  bool shared_images = false;  // textures written once under DIR/textures, referenced by the GLBs
  bool json = false;
};
int export_command(const ExportArgs& args);  // cli/export_command.cpp

}  // namespace lod::cli
