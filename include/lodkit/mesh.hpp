// A model's level geometry and materials, as a renderer draws them: views into lodkit's own
// immutable arrays (no copy), returned by lod::Service::level_mesh() and material().
//
// Ownership and lifetime: every span and string_view points into memory the service owns; it
// stays valid and unchanged for the service's lifetime (models are never removed or changed).
// Arrays the baked chain stores in a drawable layout already (positions, normals, uvs,
// colours, indices) are viewed in place; the rest (submesh runs, materials, texture paths) is
// built once per model when the model is added. Calls returning these views are safe from
// any thread once add_model has returned.
//
// MeshSubmesh is laid out exactly like lodkit.h's lod_submesh; lod_mesh and lod_material hold
// the same fields as pointers and counts, pointing at the same memory.
#pragma once
#include <cstdint>
#include <span>
#include <string_view>

namespace lod {

// Indices [first_index, first_index + index_count) of a level (level-local: 0 is the level's
// first index), whole triangles, drawn with material `material` (-1: the default surface,
// Material's defaults). Laid out exactly like lod_submesh.
struct MeshSubmesh {
  uint32_t first_index = 0;
  uint32_t index_count = 0;
  int32_t material = -1;
};

// One level of a model. Units are the model's object space as the source file gave them.
struct LevelMeshView {
  uint64_t id = 0;            // nonzero; unique per (model, level) within a service, stable for its lifetime
  uint32_t vertex_count = 0;  // the level's vertices; every index is below it
  std::span<const float> positions;        // 3 per vertex (x y z)
  std::span<const float> normals;          // 3 per vertex, unit length (a source's zero normal stays zero), or empty
  std::span<const float> uvs;              // 2 per vertex, TEXCOORD_0 (glTF: origin top left), or empty
  std::span<const float> uvs1;             // 2 per vertex, TEXCOORD_1 (lod_mesh has no twin), or empty
  std::span<const float> colors;           // 4 per vertex, linear RGBA, or empty
  std::span<const float> morph_positions;  // 3 per vertex, the vertex at morph = 1; empty for level meshes
  // 3 per triangle, counter-clockwise front faces: the source file's winding, kept by the bake
  // (glTF, OBJ, PLY, OFF and STL all define front faces as counter-clockwise).
  std::span<const uint32_t> indices;
  // Empty: one surface, the whole level, with the default material. Otherwise runs that cover
  // `indices` in order without gaps, grouped by material.
  std::span<const MeshSubmesh> submeshes;

  uint32_t index_count() const { return static_cast<uint32_t>(indices.size()); }
  uint32_t triangle_count() const { return index_count() / 3; }
};

enum class MaterialAlpha : int { opaque = 0, mask = 1, blend = 2 };  // glTF's alphaMode, values as lod_material's

// A texture: a file (absolute path: the source's folder at bake time joined with the file it
// named) or an image the source held in itself (a GLB buffer view, a data: URI) as its encoded
// bytes and MIME type ("image/png", "image/jpeg"). Neither: no texture (also for a texture the
// source named by URL). Strings are NUL-terminated (data() may be handed to C).
struct MaterialTexture {
  std::string_view path;           // file on disk (not checked to exist), or empty
  std::span<const uint8_t> bytes;  // embedded PNG or JPEG, or empty
  std::string_view mime;           // with bytes, else empty
  uint32_t texcoord = 0;           // uv set it reads: 0 = LevelMeshView::uvs (TEXCOORD_0), 1 = uvs1

  bool empty() const { return path.empty() && bytes.empty(); }
};

// glTF 2.0's metallic-roughness material as the bake read it (from glTF, or from OBJ/MTL);
// what the source did not say has glTF's default.
struct Material {
  std::string_view name;  // as the source named it (NUL-terminated), may be empty
  float base_color[4] = {1, 1, 1, 1};  // linear RGBA factor, each in [0, 1]
  float metallic = 1;                  // [0, 1]
  float roughness = 1;                 // [0, 1]
  float emissive[3] = {0, 0, 0};       // linear RGB factor, each in [0, 1]
  MaterialAlpha alpha_mode = MaterialAlpha::opaque;
  float alpha_cutoff = 0.5f;  // used with MaterialAlpha::mask
  bool double_sided = false;
  MaterialTexture base_color_texture;          // sRGB colour, multiplied by base_color
  MaterialTexture metallic_roughness_texture;  // roughness in G, metalness in B
  MaterialTexture normal_texture;              // tangent-space normals
  MaterialTexture occlusion_texture;           // ambient occlusion in R
  MaterialTexture emissive_texture;            // sRGB emitted colour
};

}  // namespace lod
