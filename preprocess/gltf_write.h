// glTF 2.0 export of one triangle mesh: binary .glb, or .gltf with its buffer in a .bin next
// to it (by the path's extension). Written by hand (tinygltf stays inside gltf_io.cpp): one
// buffer, one tightly packed buffer view per attribute and for the indices (each 4-byte
// aligned, with its target), POSITION with min/max, unit NORMALs, TEXCOORD_0 and _1, COLOR_0, u16 indices
// when the vertices fit, else u32; one node, one scene; one primitive per submesh (they share
// the vertex attributes), each with its metallic-roughness material; its images (PNG or JPEG
// files, or bytes in memory such as a chain's embedded images: base colour, metallic-roughness,
// normal, occlusion, emissive) are embedded in the GLB's buffer, or copied next to a .gltf. With a normal texture (and normals and uvs) the mesh gets
// TANGENTs computed here (per-triangle accumulation from positions and uvs, orthogonalised
// against the normal, w the handedness), referenced by the primitives whose material has the
// normal texture, so no viewer has to generate a tangent space. Output passes the Khronos
// validator with 0 errors (tests/integration/gltf_export_test.cpp).
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "runtime/chain_material.h"
#include "runtime/embedded_image.h"
#include "runtime/status.h"

namespace lod {

struct GltfMaterialView {
  std::string name;
  float base_color[4] = {1, 1, 1, 1};
  float metallic = 1;
  float roughness = 1;
  AlphaMode alpha_mode = AlphaMode::opaque;
  float alpha_cutoff = 0.5f;
  bool double_sided = false;
  // PNG or JPEG files (by their first bytes) for the textures; empty = none. One that is
  // missing, unreadable, not PNG/JPEG or larger than 256 MiB is left out, said in `notes`.
  std::filesystem::path base_color_image;
  std::filesystem::path metallic_roughness_image;
  std::filesystem::path normal_image;
  std::filesystem::path occlusion_image;
  std::filesystem::path emissive_image;
  // Images held in memory (a chain's embedded images), in kTextureSlots order; a slot with one
  // uses its bytes and ignores its path (checked, embedded and copied like a file's).
  std::array<const EmbeddedImage*, kTextureSlots> embedded_images{};
  float normal_scale = 1;        // written as normalTexture.scale
  float occlusion_strength = 1;  // occlusionTexture.strength
  float emissive[3] = {0, 0, 0};  // emissiveFactor
  // The uv set each texture reads, in kTextureSlots order (written as textureInfo.texCoord; a
  // texture reading a set the mesh does not have is left out, said in `notes`).
  std::array<uint8_t, kTextureSlots> tex_coords{};
};

// A baked material for the writer: factors copied, each texture slot either one of `images`
// (an "embedded:<k>" URI, k checked by the asset readers; out of range: no image) or the file
// its URI names under `texture_base` (a missing file is left out by the writer and said).
GltfMaterialView gltf_material_view(const ChainMaterial& m, const std::vector<EmbeddedImage>& images,
                                    const std::string& texture_base);

// The images in kTextureSlots order (runtime/chain_material.h).
inline std::array<const std::filesystem::path*, kTextureSlots> image_slots(const GltfMaterialView& m) {
  return {&m.base_color_image, &m.metallic_roughness_image, &m.normal_image, &m.occlusion_image, &m.emissive_image};
}
inline std::array<std::filesystem::path*, kTextureSlots> image_slots(GltfMaterialView& m) {
  return {&m.base_color_image, &m.metallic_roughness_image, &m.normal_image, &m.occlusion_image, &m.emissive_image};
}

// Triangles [first_index, first_index + index_count) of the mesh drawn with `material`
// (-1 = the default material).
struct GltfSubmeshView {
  size_t first_index = 0;
  size_t index_count = 0;
  int32_t material = -1;
};

struct GltfMeshView {
  std::string name;                 // mesh and node name (any UTF-8)
  const float* positions = nullptr;  // xyz per vertex
  size_t vertex_count = 0;
  const float* normals = nullptr;    // xyz per vertex, or null; zero or non-finite ones are written as +z
  const float* uvs = nullptr;        // uv per vertex, or null
  const float* uvs1 = nullptr;       // second uv set per vertex (TEXCOORD_1), or null
  const float* colors = nullptr;     // linear RGBA per vertex (COLOR_0, written as float VEC4), or null
  const uint32_t* indices = nullptr;  // 3 per triangle, each < vertex_count
  size_t index_count = 0;
  std::vector<GltfMaterialView> materials;  // optional
  std::vector<GltfSubmeshView> submeshes;   // optional: cover the indices in order; empty = one primitive
  std::vector<std::string>* notes = nullptr;  // optional: what could not be written (a texture left out)
  // Optional, GLB only: an image is referenced by the URI this returns for its file, or for the
  // material's image in memory (`embedded` set, `image` empty) (relative to the GLB; the caller
  // has put the file there) instead of being embedded, so that files sharing an image (a 3D
  // Tiles export's tiles) hold it once; an empty URI embeds it after all.
  std::function<std::string(const std::filesystem::path& image, const EmbeddedImage* embedded)> image_uri;
};

// Checks everything first (indices in range, a multiple of 3, at least one triangle, finite
// positions, submeshes covering the indices with existing materials), so a refused mesh writes
// nothing; then writes to a temporary file and renames. For .gltf the buffer goes to
// <stem>.bin in the same folder, and image k to <stem>-image<k>.png (or .jpg).
Status save_gltf(const std::filesystem::path& path, const GltfMeshView& mesh);

}  // namespace lod
