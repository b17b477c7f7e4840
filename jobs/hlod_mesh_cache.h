// The mesh as an HLOD build takes it (loaded and cleaned), kept in the distributed bake's cache
// beside the subtrees under the source's content hash (issue 16): a rerun, and every rank of
// it, reads a few arrays instead of parsing and cleaning the file again. Written like a subtree
// entry (temporary, read back, rename); read as hostile input (sizes, checksum, key, indices).
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>

#include "jobs/hlod_subtree_cache.h"  // CacheLookup
#include "preprocess/hlod_build.h"    // HlodSurfaces
#include "preprocess/mesh.h"
#include "runtime/status.h"

namespace lod {

// 4: colours and TEXCOORD_1; 3: embedded images; 2: uvs, submeshes, materials
inline constexpr uint32_t kHlodMeshEntryVersion = 4;

std::filesystem::path hlod_mesh_entry_path(const std::filesystem::path& dir, uint64_t source_hash);

// Positions, indices, uvs, uv1, colours and submeshes of `mesh` (cleaned), its materials and the images they
// embed as the tree stores them, and the triangle count it had before cleaning.
Status store_hlod_mesh(const std::filesystem::path& dir, uint64_t source_hash, const MeshData& mesh,
                       uint64_t input_triangles, const HlodSurfaces& surfaces = {});

// `out` gets positions, indices, uvs, uv1, colours, submeshes and `source` (named `source_name`), `surfaces`
// (when given) the materials and their images; `why` says why an entry was refused.
CacheLookup load_hlod_mesh(const std::filesystem::path& dir, uint64_t source_hash, const std::string& source_name,
                           MeshData& out, uint64_t& input_triangles, std::string* why = nullptr,
                           HlodSurfaces* surfaces = nullptr);

}  // namespace lod
