// MeshData: a triangle mesh as flat arrays, the only mesh type that leaves preprocess/'s
// OpenMesh-facing files.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace lod {

struct MeshData {
  std::string source;              // file the mesh came from, for messages
  std::vector<float> positions;    // xyz per vertex
  std::vector<float> normals;      // xyz per vertex, or empty
  std::vector<uint32_t> indices;   // 3 per triangle

  size_t vertex_count() const { return positions.size() / 3; }
  size_t triangle_count() const { return indices.size() / 3; }
};

}  // namespace lod
