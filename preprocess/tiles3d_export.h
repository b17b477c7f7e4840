// OGC 3D Tiles 1.1 export of an .hlod file: DIR/tileset.json and one GLB per node layer
// (DIR/tiles/<node>-<layer>.glb) and per boundary patch (DIR/tiles/<node>-boundary.glb).
//
// Tiles follow the octree with refine REPLACE. A node becomes a chain of tiles, coarsest layer
// first, each tile's geometricError the layer's measured error (HlodLayerInfo::error); the
// finest layer's tile has as children the children's chains and, for an inner node, a tile
// holding the node's boundary patch (geometricError 0): REPLACE draws the children instead of
// the node, and the patch is what joins them, so it is drawn with them.
//
// Coordinates: the GLBs hold the model's coordinates unchanged (glTF y-up); 3D Tiles is z-up,
// and a 3D Tiles client applies the specification's y-up to z-up rotation to glTF content, so
// the bounding volumes are written in the tileset's z-up frame: (x, y, z) -> (x, -z, y).
//
// Surfaces: a tree with uvs writes TEXCOORD_0 (with a second set TEXCOORD_1, with colours
// COLOR_0), and one with materials one primitive per material
// run with its metallic-roughness material and textures (each GLB embeds the images its
// materials use, so every tile stands alone).
//
// Nothing in the file is trusted beyond what the .hlod reader checks: every payload range is
// checked against its arrays again before a GLB is written. Names never become paths (files
// are named by node index). Everything is written into a staging folder beside DIR that
// replaces DIR only once complete, so a failed export leaves no partial tileset.
#pragma once
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "runtime/status.h"

namespace lod {

struct TilesetExportOptions {
  // Replace a non-empty DIR when it holds an earlier export (a tileset.json); otherwise a
  // non-empty DIR is refused. Never replaces a folder without a tileset.json.
  bool replace = false;
  // Write each texture image once, as DIR/textures/image<k>.png (or .jpg), and have the GLBs
  // reference it (../textures/...) instead of embedding it in every tile that uses it.
  bool shared_images = false;
};

struct TilesetExportReport {
  size_t nodes = 0;       // of the .hlod tree
  size_t tiles = 0;       // in tileset.json
  size_t glb_files = 0;   // tiles with content
  uint64_t bytes = 0;     // of every file written
  double root_error = 0;  // geometricError of the root tile
  std::vector<std::string> notes;  // what could not be written (a texture missing at export time), per GLB
  size_t shared_images = 0;        // images written once under DIR/textures (shared_images)
};

Status export_3d_tiles(const std::filesystem::path& hlod_file, const std::filesystem::path& dir,
                       const TilesetExportOptions& options, TilesetExportReport* report);

}  // namespace lod
