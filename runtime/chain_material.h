// Surface descriptions of a baked chain: glTF's metallic-roughness materials as the bake
// read them (from glTF or OBJ/MTL), with textures named by URI, never loaded; and the runs
// of each level's triangles drawn with one material (a level's triangles grouped by material).
#pragma once
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace lod {

enum class AlphaMode : uint8_t { opaque, mask, blend };

inline constexpr size_t kMaxMaterialString = 4096;  // bytes of a material name or texture URI
inline constexpr uint32_t kMaxMaterials = 65536;

inline constexpr size_t kTextureSlots = 5;  // texture slots per material (texture_slots below)
inline constexpr uint8_t kMaxTexCoord = 1;     // uv sets a texture may read: TEXCOORD_0 and TEXCOORD_1

struct ChainMaterial {
  std::string name;
  float base_color[4] = {1, 1, 1, 1};  // linear RGBA factor, each in [0, 1]
  float metallic = 1;                  // [0, 1]
  float roughness = 1;                 // [0, 1]
  AlphaMode alpha_mode = AlphaMode::opaque;
  float alpha_cutoff = 0.5f;  // for AlphaMode::mask, >= 0
  bool double_sided = false;
  // Images: RFC 3986 relative URIs (percent-encoded, '/' separated) against
  // LodChain::texture_base, the source file's folder; empty = none. Each reads the uv set
  // tex_coords[slot] names (0: LodChain::uvs, 1: LodChain::uvs1).
  std::string base_color_texture;
  std::string metallic_roughness_texture;  // glTF: roughness in G, metalness in B
  std::string normal_texture;              // tangent-space normals
  std::string occlusion_texture;           // ambient occlusion in R
  std::string emissive_texture;            // sRGB emitted colour
  float normal_scale = 1;                  // normalTexture.scale, >= 0 (finite)
  float occlusion_strength = 1;            // occlusionTexture.strength, [0, 1]
  float emissive[3] = {0, 0, 0};           // emissiveFactor, each in [0, 1]
  std::array<uint8_t, kTextureSlots> tex_coords{};  // uv set per texture slot: 0 or 1
};

// The five texture slots of a material, in this order everywhere (asset, export, messages).
inline constexpr const char* kTextureSlotNames[kTextureSlots] = {"base colour", "metallic-roughness", "normal",
                                                                 "occlusion", "emissive"};
inline std::array<std::string*, kTextureSlots> texture_slots(ChainMaterial& m) {
  return {&m.base_color_texture, &m.metallic_roughness_texture, &m.normal_texture, &m.occlusion_texture,
          &m.emissive_texture};
}
inline std::array<const std::string*, kTextureSlots> texture_slots(const ChainMaterial& m) {
  return {&m.base_color_texture, &m.metallic_roughness_texture, &m.normal_texture, &m.occlusion_texture,
          &m.emissive_texture};
}

// Triangles [first_index, first_index + index_count) of level `level` (level-local: 0 is the
// level's first index) drawn with material `material` (-1 = the default material).
struct LevelSubmesh {
  uint32_t level = 0;
  uint32_t first_index = 0;
  uint32_t index_count = 0;
  int32_t material = -1;
};

}  // namespace lod
