// glTF 2.0 export of one triangle mesh: binary .glb, or .gltf with its buffer in a .bin next
// to it (by the path's extension). Written by hand (tinygltf stays inside gltf_io.cpp): one
// buffer, one tightly packed buffer view per attribute and for the indices (each 4-byte
// aligned, with its target), POSITION with min/max, unit NORMALs, TEXCOORD_0, u16 indices
// when the vertices fit, else u32; one node, one scene. Output passes the Khronos validator
// with 0 errors (tests/integration/gltf_export_test.cpp).
#pragma once
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "runtime/status.h"

namespace lod {

struct GltfMeshView {
  std::string name;                 // mesh and node name (any UTF-8)
  const float* positions = nullptr;  // xyz per vertex
  size_t vertex_count = 0;
  const float* normals = nullptr;    // xyz per vertex, or null; zero or non-finite ones are written as +z
  const float* uvs = nullptr;        // uv per vertex, or null
  const uint32_t* indices = nullptr;  // 3 per triangle, each < vertex_count
  size_t index_count = 0;
};

// Checks everything first (indices in range, a multiple of 3, at least one triangle, finite
// positions), so a refused mesh writes nothing; then writes to a temporary file and renames.
// For .gltf the buffer goes to <stem>.bin in the same folder.
Status save_gltf(const std::filesystem::path& path, const GltfMeshView& mesh);

}  // namespace lod
