// lod run --validate for the terrain: every frame's mesh (Frame::terrain_*) is a crack-free,
// T-junction-free triangulation of the whole grid (runtime/terrain_mesh_check), its arrays
// agree with each other, and it stays within the share of M the terrain was given.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "runtime/frame.h"

namespace lod::cli {

class TerrainCheck {
 public:
  // False with `why` at the first fault of `f` (a frame without terrain passes).
  bool check(const Frame& f, std::string* why);

 private:
  std::vector<uint32_t> grid_indices_;  // the frame's triangles in sample ids
  std::vector<uint8_t> seen_;           // per sample: drawn as a vertex
};

}  // namespace lod::cli
