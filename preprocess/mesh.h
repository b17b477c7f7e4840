// MeshData: a triangle mesh as flat arrays, the only mesh type that leaves preprocess/'s
// OpenMesh-facing files. Positions and indices are always there; the other attributes are
// optional (empty = the source had none), so readers that know only geometry leave them be.
#pragma once
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "runtime/chain_material.h"  // AlphaMode
#include "runtime/embedded_image.h"

namespace lod {

// A surface description as glTF's metallic-roughness material gives it; textures are named
// by the URI the file uses (relative to the file), never loaded. An image held in the file
// itself (GLB buffer view, data URI) has its embedded flag set and, when its bytes were kept
// (PNG or JPEG), the URI "embedded:<k>" naming MeshData::images[k]; else an empty URI.
struct MeshMaterial {
  std::string name;
  float base_color[4] = {1, 1, 1, 1};  // linear RGBA factor
  std::string base_color_texture;      // image URI ("embedded:<k>" when kept from inside the file); empty when none
  bool base_color_texture_embedded = false;  // the texture's image is inside the file (GLB or data URI)
  float metallic = 1;
  float roughness = 1;
  AlphaMode alpha_mode = AlphaMode::opaque;
  float alpha_cutoff = 0.5f;  // for AlphaMode::mask
  bool double_sided = false;
  // The other textures, each an image URI (empty when none) with its own embedded flag, in
  // kTextureSlots order after the base colour: metallic-roughness, normal, occlusion, emissive.
  std::string metallic_roughness_texture;
  std::string normal_texture;
  std::string occlusion_texture;
  std::string emissive_texture;
  bool metallic_roughness_texture_embedded = false;
  bool normal_texture_embedded = false;
  bool occlusion_texture_embedded = false;
  bool emissive_texture_embedded = false;
  float normal_scale = 1;          // glTF normalTexture.scale (MTL: bump -bm); the bake keeps it >= 0
  float occlusion_strength = 1;    // glTF occlusionTexture.strength, [0, 1]
  float emissive[3] = {0, 0, 0};   // glTF emissiveFactor (MTL: Ke), linear RGB in [0, 1]
  // The uv set each texture reads (glTF textureInfo.texCoord: 0 = TEXCOORD_0, 1 = TEXCOORD_1),
  // in kTextureSlots order.
  std::array<uint8_t, kTextureSlots> tex_coords{};
};

// A material's textures in kTextureSlots order (runtime/chain_material.h), for loops over them.
template <class Material, class Uri = std::conditional_t<std::is_const_v<Material>, const std::string, std::string>,
          class Flag = std::conditional_t<std::is_const_v<Material>, const bool, bool>>
struct MeshTextureSlot {
  Uri* uri;
  Flag* embedded;
};
template <class Material>
  requires std::is_same_v<std::remove_const_t<Material>, MeshMaterial>
std::array<MeshTextureSlot<Material>, kTextureSlots> texture_slots(Material& m) {
  return {{{&m.base_color_texture, &m.base_color_texture_embedded},
           {&m.metallic_roughness_texture, &m.metallic_roughness_texture_embedded},
           {&m.normal_texture, &m.normal_texture_embedded},
           {&m.occlusion_texture, &m.occlusion_texture_embedded},
           {&m.emissive_texture, &m.emissive_texture_embedded}}};
}

// A run of consecutive triangles drawn with one material (-1 = the default material).
struct Submesh {
  uint32_t first_triangle = 0;
  uint32_t triangle_count = 0;
  int32_t material = -1;  // into MeshData::materials
};

struct MeshData {
  std::string source;              // file the mesh came from, for messages
  std::vector<float> positions;    // xyz per vertex
  std::vector<float> normals;      // xyz per vertex, or empty
  std::vector<uint32_t> indices;   // 3 per triangle
  std::vector<float> uvs;          // uv per vertex (glTF TEXCOORD_0: origin top left), or empty
  std::vector<float> uvs1;         // second uv set per vertex (glTF TEXCOORD_1), or empty
  std::vector<float> colors;       // linear RGBA per vertex (glTF COLOR_0; RGB gets alpha 1), or empty
  std::vector<Submesh> submeshes;  // cover every triangle in order, or empty (one surface)
  std::vector<MeshMaterial> materials;  // as numbered by the file, or empty
  std::vector<EmbeddedImage> images;    // PNG / JPEG bytes the file held itself, named "embedded:<k>" by materials
  std::vector<std::string> warnings;    // what the reader skipped, each naming the element

  size_t vertex_count() const { return positions.size() / 3; }
  size_t triangle_count() const { return indices.size() / 3; }
};

// A mesh's arrays held elsewhere (a MeshData, or memory the ranks of a node share): what the
// builders that only read a mesh take. It does not own them; they must outlive it.
struct MeshView {
  std::string_view source;
  std::span<const float> positions, normals;
  std::span<const uint32_t> indices;
  std::span<const float> uvs, uvs1, colors;
  std::span<const Submesh> submeshes;

  MeshView() = default;
  MeshView(const MeshData& m)  // NOLINT(google-explicit-constructor): every MeshData is one
      : source(m.source), positions(m.positions), normals(m.normals), indices(m.indices), uvs(m.uvs),
        uvs1(m.uvs1), colors(m.colors), submeshes(m.submeshes) {}
  size_t vertex_count() const { return positions.size() / 3; }
  size_t triangle_count() const { return indices.size() / 3; }
};

}  // namespace lod
