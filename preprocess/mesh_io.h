// Mesh loading (OBJ, PLY, OFF, STL) into flat arrays by single-pass readers of our own
// (OpenMesh's readers are not used); glTF 2.0 (.gltf, .glb) through preprocess/gltf_io.h. Every failure names the file and what is wrong; `out`
// is only written on success.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "preprocess/mesh.h"
#include "runtime/status.h"

namespace lod {

// Refuses: missing or unreadable files, anything but a regular file (a directory, FIFO or
// device is named as such and never blocks), unknown extensions, empty files, declared
// counts the file cannot hold, meshes without triangles, non-finite coordinates (also values
// finite as double but not as float), faces referencing vertices that do not exist (the
// vertex named as the file numbers it). A UTF-8 byte-order mark before an OBJ or ASCII STL
// is skipped. Polygons are fan-triangulated; points-only files are refused.
Status load_mesh(const std::filesystem::path& path, MeshData& out);
// The same over `bytes`, the file's content already read (freed once parsed): a caller that
// hashed the file first reads it once. A glTF is read from `path` (its buffers may be files),
// and so is any file when `bytes` is empty (a caller that had no need to read it).
Status load_mesh(const std::filesystem::path& path, std::vector<uint8_t>&& bytes, MeshData& out);
// load_mesh, and the content hash (hash_bytes) of exactly the bytes it parsed: a binary PLY
// in the scanners' layout is read straight into the mesh's arrays (no copy of the file in
// memory), any other file whole, then parsed.
Status load_mesh_hashed(const std::filesystem::path& path, MeshData& out, uint64_t& content_hash);

// The same readers over bytes already in memory; `extension` picks the format (".ply",
// ".off", ".stl", ".obj", ".gltf", ".glb"; any case), `name` is used in messages. Never reads
// past `size`; a glTF naming an external buffer is refused (nothing is read from disk).
Status load_mesh_from_memory(const std::string& name, const std::string& extension, const uint8_t* data, size_t size,
                             MeshData& out);

// The files an OBJ's materials name (its mtllib files and their map_Kd / map_Ke / map_Bump /
// bump / norm / map_Pm / map_Pr images, next to it), so
// a cache key can cover them too; missing ones are left out (the load says why). Files are
// read through runtime/regular_file.h: what is not a regular file is listed, not read.
std::vector<std::filesystem::path> obj_external_files(const std::filesystem::path& path);

// Writes positions + triangles as binary PLY (for --export and outside tools).
Status save_ply(const std::filesystem::path& path, const float* positions, size_t vertex_count,
                const uint32_t* indices, size_t index_count);

// Writes positions (+ normals and uvs when given, else null) + triangles as Wavefront OBJ text
// ("v", "vt", "vn", "f a/a/a ..." numbered from 1). uvs are glTF's (origin top left); OBJ's vt
// has its origin bottom left, so v is written as 1 - v. colors (linear RGBA per vertex, or null)
// go on the "v" lines as sRGB "v x y z r g b", the extension MeshLab reads (alpha is not written).
Status save_obj(const std::filesystem::path& path, const float* positions, const float* normals, size_t vertex_count,
                const uint32_t* indices, size_t index_count, const float* uvs = nullptr, const float* colors = nullptr);

// Materials for save_obj: the faces of each submesh after a "usemtl", the materials in
// <stem>.mtl next to the .obj ("mtllib"), each with Kd, d, Ke, Pm, Pr and, for each image it
// has, map_Kd, map_Bump -bm (normal scale), map_Ke, and map_Pm -imfchan b + map_Pr -imfchan g
// (both naming the metallic-roughness image) naming a copy of it, <stem>-image<k><ext>, next to
// the .mtl (one copy per image however many maps name it). MTL has no occlusion statement: an
// occlusion image is not written, said in `notes`. An image that is missing or larger than
// 256 MiB is left out and said in `notes`.
struct ObjMaterialView {
  std::string name;
  float base_color[4] = {1, 1, 1, 1};
  std::filesystem::path base_color_image;
  float metallic = 0, roughness = 1;
  std::filesystem::path metallic_roughness_image;
  std::filesystem::path normal_image;
  float normal_scale = 1;
  std::filesystem::path occlusion_image;
  std::filesystem::path emissive_image;
  float emissive[3] = {0, 0, 0};
  // Images held in memory, in kTextureSlots order (base colour, metallic-roughness, normal,
  // occlusion, emissive): a slot with one copies its bytes (named by its type's extension)
  // instead of the file its path names.
  std::array<const EmbeddedImage*, kTextureSlots> embedded_images{};
};
struct ObjSubmeshView {
  size_t first_index = 0;
  size_t index_count = 0;
  int32_t material = -1;  // -1: the default material (white)
};
struct ObjSurfaces {
  std::vector<ObjMaterialView> materials;
  std::vector<ObjSubmeshView> submeshes;  // cover the indices in order
  std::vector<std::string>* notes = nullptr;
};
Status save_obj(const std::filesystem::path& path, const float* positions, const float* normals, size_t vertex_count,
                const uint32_t* indices, size_t index_count, const float* uvs, const ObjSurfaces& surfaces,
                const float* colors = nullptr);

}  // namespace lod
