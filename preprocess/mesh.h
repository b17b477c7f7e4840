// MeshData: a triangle mesh as flat arrays, the only mesh type that leaves preprocess/'s
// OpenMesh-facing files. Positions and indices are always there; the other attributes are
// optional (empty = the source had none), so readers that know only geometry leave them be.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "runtime/chain_material.h"  // AlphaMode

namespace lod {

// A surface description as glTF's metallic-roughness material gives it; textures are named
// by the URI the file uses (relative to the file), never loaded.
struct MeshMaterial {
  std::string name;
  float base_color[4] = {1, 1, 1, 1};  // linear RGBA factor
  std::string base_color_texture;      // image URI; empty when none or embedded in the file
  bool base_color_texture_embedded = false;  // the texture's image is inside the file (GLB or data URI)
  float metallic = 1;
  float roughness = 1;
  AlphaMode alpha_mode = AlphaMode::opaque;
  float alpha_cutoff = 0.5f;  // for AlphaMode::mask
  bool double_sided = false;
};

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
  std::vector<Submesh> submeshes;  // cover every triangle in order, or empty (one surface)
  std::vector<MeshMaterial> materials;  // as numbered by the file, or empty
  std::vector<std::string> warnings;    // what the reader skipped, each naming the element

  size_t vertex_count() const { return positions.size() / 3; }
  size_t triangle_count() const { return indices.size() / 3; }
};

}  // namespace lod
