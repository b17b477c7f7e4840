// HLOD bake job: load a mesh, clean it, build its HLOD on oneTBB, write DIR/<name>.hlod.
#pragma once
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "preprocess/hlod_build.h"
#include "preprocess/mesh.h"
#include "runtime/status.h"

namespace lod {

struct HlodBakeSettings {
  uint32_t min_verts = 1000;
  uint32_t threads = 0;  // 0 = all cores
};

struct HlodBakeResult {
  std::filesystem::path file;  // what was written
  HlodBuildReport report;
  size_t input_triangles = 0;
  double load_seconds = 0, build_seconds = 0, write_seconds = 0;
  uint64_t bytes = 0;
};

// Lines like "hlod dragon 40%" (every 10 %), from one thread at a time.
using HlodBakeLog = std::function<void(const std::string&)>;

// The build's version, in hlod_source_hash and the subtree cache's key, so that a tree or subtree
// cached by an older build is rebaked: 4 colours and TEXCOORD_1, 3 embedded images, 2 uvs and
// materials.
inline constexpr uint64_t kHlodBuildVersion = 4;

// The tbb parallel_for the builder's subtrees run on (inside the caller's arena).
ParallelFor tbb_parallel_for();

// The content hash of a mesh file's bytes (and of the files it names: an OBJ's .mtl files and
// images, a glTF's buffers and images) mixed with min_verts and the build's version: the
// source_hash of what bake_hlod_file writes, so a cached .hlod with it is current.
// The file is hashed in 1 MB pieces (no copy of it in memory).
Status hlod_source_hash(const std::filesystem::path& mesh_file, uint32_t min_verts, uint64_t& out);
// The same from the hash of the mesh file's bytes already taken (load_mesh_hashed's).
uint64_t hlod_source_hash_of(const std::filesystem::path& mesh_file, uint64_t content_hash, uint32_t min_verts);

// The mesh as an HLOD build takes it: loaded and cleaned (uv seams and material boundaries stay
// copies at one position), its materials converted for the tree (add_chain_materials) with the
// images they embed (only those a kept slot names, renumbered). The uvs (both sets) and colours
// stay; what the tree does not keep (a texture reading a uv set the mesh lacks) is said in
// `notes`, each naming the file.
// `content_hash` (optional): hash_bytes of the file's bytes as parsed (the file is read once).
Status load_hlod_input(const std::filesystem::path& mesh_file, MeshData& mesh, HlodSurfaces& surfaces,
                       std::vector<std::string>& notes, size_t* input_triangles = nullptr,
                       uint64_t* content_hash = nullptr);
// The same for a mesh already loaded from `mesh_file` (cleaned in place).
void prepare_hlod_input(const std::filesystem::path& mesh_file, MeshData& mesh, HlodSurfaces& surfaces,
                        std::vector<std::string>& notes);

// Builds and writes `out_dir/<name>.hlod`; source_hash is the mesh file's content hash mixed
// with min_verts. On failure the status names the file; nothing is written.
Status bake_hlod_file(const std::filesystem::path& mesh_file, const std::string& name,
                      const std::filesystem::path& out_dir, const HlodBakeSettings& settings, const HlodBakeLog& log,
                      HlodBakeResult* result);

}  // namespace lod
