// lod export --3dtiles DIR FILE.hlod: an OGC 3D Tiles 1.1 tileset of an .hlod tree.
#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "cli/names.h"
#include "preprocess/tiles3d_export.h"

namespace lod::cli {

int export_command(const ExportArgs& args) {
  if (args.tiles_dir.empty()) {
    std::fprintf(stderr, "lod export: name what to write (--3dtiles DIR)\n");
    return 1;
  }
  TilesetExportOptions options;
  options.replace = args.force;
  options.shared_images = args.shared_images;
  TilesetExportReport rep;
  if (Status st = export_3d_tiles(args.file, args.tiles_dir, options, &rep); !st) {
    std::fprintf(stderr, "lod export: %s\n", printable(st.message).c_str());
    return 1;
  }
  // One line per distinct note (a missing texture is said by every GLB that wanted it).
  std::vector<std::string> notes = rep.notes;
  std::sort(notes.begin(), notes.end());
  notes.erase(std::unique(notes.begin(), notes.end()), notes.end());
  for (const std::string& note : notes) std::fprintf(stderr, "lod export: note: %s\n", printable(note).c_str());
  if (args.json) {
    const nlohmann::json j = {{"dir", args.tiles_dir}, {"nodes", rep.nodes},       {"tiles", rep.tiles},
                              {"glb_files", rep.glb_files}, {"bytes", rep.bytes}, {"root_error", rep.root_error},
                              {"notes", notes}, {"shared_images", rep.shared_images}};
    std::printf("%s\n", j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
    return 0;
  }
  std::printf("%s: %zu nodes -> %zu tiles (%zu GLBs, %.2f MB), root geometricError %.6g, in %s\n",
              printable(args.file).c_str(), rep.nodes, rep.tiles, rep.glb_files, double(rep.bytes) / 1e6, rep.root_error,
              printable(args.tiles_dir).c_str());
  return 0;
}

}  // namespace lod::cli
