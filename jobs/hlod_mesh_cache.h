// The mesh as an HLOD build takes it (loaded and cleaned), kept in the distributed bake's cache
// beside the subtrees under the source's content hash: a rerun, and every rank of
// it, reads a few arrays instead of parsing and cleaning the file again. Written like a subtree
// entry (temporary, read back, rename); read as hostile input (sizes, checksum, key, indices).
#pragma once
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

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

// The entry's bytes in parts, the big arrays in place (a 14M-triangle mesh is 250 MB): what
// store_hlod_mesh writes, and what the ranks of a node copy once into memory they share.
struct HlodMeshEntry {
  std::vector<std::span<const uint8_t>> parts;  // into the mesh and `owned`
  std::vector<std::vector<uint8_t>> owned;      // the head, submeshes, materials, images, checksum
  uint64_t size() const;
  void copy_to(uint8_t* out) const;  // size() bytes
};
HlodMeshEntry hlod_mesh_entry(uint64_t source_hash, const MeshData& mesh, uint64_t input_triangles,
                              const HlodSurfaces& surfaces = {});

// Stores an entry's bytes made by hlod_mesh_entry (held in memory a node's ranks share).
Status store_hlod_mesh_bytes(const std::filesystem::path& dir, uint64_t source_hash, std::span<const uint8_t> entry);

// `out` gets positions, indices, uvs, uv1, colours, submeshes and `source` (named `source_name`), `surfaces`
// (when given) the materials and their images; `why` says why an entry was refused.
CacheLookup load_hlod_mesh(const std::filesystem::path& dir, uint64_t source_hash, const std::string& source_name,
                           MeshData& out, uint64_t& input_triangles, std::string* why = nullptr,
                           HlodSurfaces* surfaces = nullptr);

// An entry's mesh read in place: its arrays point into the entry's bytes (and source_name's),
// which must outlive it; the small parts are copied.
struct HlodMeshInPlace {
  MeshView mesh;
  std::vector<Submesh> submeshes;  // mesh.submeshes points here
  HlodSurfaces surfaces;
  uint64_t input_triangles = 0;
};
// `check`: the bytes are hostile (a file): checksum, every index and value, as load_hlod_mesh.
// Without it (bytes this program made, in memory), the head, counts and small parts only: no pass
// over the arrays. Little-endian hosts only (elsewhere an error: the caller copies instead).
Status view_hlod_mesh(std::span<const uint8_t> entry, uint64_t source_hash, std::string_view source_name, bool check,
                      HlodMeshInPlace& out);

}  // namespace lod
