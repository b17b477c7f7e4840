// Mesh loading through OpenMesh's readers (OBJ, PLY, OFF, STL) into flat arrays.
// Every failure names the file and what is wrong; `out` is only written on success.
#pragma once
#include <filesystem>

#include "preprocess/mesh.h"
#include "runtime/status.h"

namespace lod {

// Refuses: missing or unreadable files, unknown extensions, empty files, meshes without
// triangles, non-finite coordinates, faces referencing vertices that do not exist.
// Polygons are triangulated; points-only files are refused.
Status load_mesh(const std::filesystem::path& path, MeshData& out);

// Writes positions + triangles as binary PLY (for --export and outside tools).
Status save_ply(const std::filesystem::path& path, const float* positions, size_t vertex_count,
                const uint32_t* indices, size_t index_count);

}  // namespace lod
