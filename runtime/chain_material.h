// Surface descriptions of a baked chain: glTF's metallic-roughness materials as the bake
// read them (from glTF or OBJ/MTL), with textures named by URI, never loaded; and the runs
// of each level's triangles drawn with one material (a level's triangles grouped by material).
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace lod {

enum class AlphaMode : uint8_t { opaque, mask, blend };

inline constexpr size_t kMaxMaterialString = 4096;  // bytes of a material name or texture URI
inline constexpr uint32_t kMaxMaterials = 65536;

struct ChainMaterial {
  std::string name;
  float base_color[4] = {1, 1, 1, 1};  // linear RGBA factor, each in [0, 1]
  float metallic = 1;                  // [0, 1]
  float roughness = 1;                 // [0, 1]
  AlphaMode alpha_mode = AlphaMode::opaque;
  float alpha_cutoff = 0.5f;  // for AlphaMode::mask, >= 0
  bool double_sided = false;
  // Base colour image: an RFC 3986 relative URI (percent-encoded, '/' separated) against
  // LodChain::texture_base, the source file's folder; empty = none.
  std::string base_color_texture;
};

// Triangles [first_index, first_index + index_count) of level `level` (level-local: 0 is the
// level's first index) drawn with material `material` (-1 = the default material).
struct LevelSubmesh {
  uint32_t level = 0;
  uint32_t first_index = 0;
  uint32_t index_count = 0;
  int32_t material = -1;
};

}  // namespace lod
