// glTF 2.0 import (.gltf with external or data-URI buffers, .glb) into MeshData, through
// tinygltf (which stays inside gltf_io.cpp).
//
// Imports every triangle primitive of the default scene (scene 0 when none is named), each
// node's world transform applied (a mesh used by several nodes is copied once per node; a
// mirroring transform flips the winding back). TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN,
// indexed (u8/u16/u32) or not; POSITION, NORMAL, TEXCOORD_0 and TEXCOORD_1 as float, normalized
// (u)int8/(u)int16 or, as KHR_mesh_quantization allows, plain (u)int8/(u)int16; byte strides
// honoured; each uv set takes the KHR_texture_transform of the first texture reading it (base
// colour first; so gltfpack's quantized UVs come out in texture space), another texture on that
// set with another transform is said in the warnings; COLOR_0 (VEC3 or VEC4, float or
// normalized u8/u16) as linear RGBA, clamped to [0, 1]; a primitive lacking TEXCOORD_1 or COLOR_0
// in a file where another has it gets (0, 0) / white, said in the warnings. Materials (metallic-roughness factors, texture URIs, alpha mode,
// double-sided) become MeshData::materials, each primitive a Submesh. Images held in the file
// (buffer views, data URIs) are kept undecoded in MeshData::images when PNG or JPEG by their
// signature and at most kMaxEmbeddedImageBytes (a material names one as "embedded:<k>");
// another is left out with a warning naming the file, material and slot.
//
// Refused, with the file and the element named: Draco / meshopt compression when required,
// sparse accessors, accessors or buffer views outside their buffer, strides shorter than an
// element, index values >= the vertex count, illegal component types, truncated or
// inconsistent GLB chunks, missing buffers or images, non-finite values, node cycles, and
// scenes that would flatten (by instancing) to far more data than the file holds.
// Skipped with a warning in MeshData::warnings: point and line primitives, skins (the bind
// pose is kept), morph targets (the base shape is kept), optional extensions not applied.
#pragma once
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "preprocess/mesh.h"
#include "runtime/status.h"

namespace lod {

// Reads `path` (.gltf or .glb, by extension; any case). External buffers and images are
// resolved next to the file. `out` is only written on success.
Status load_gltf(const std::filesystem::path& path, MeshData& out);

// The same over bytes in memory: `extension` is ".gltf" or ".glb", `name` is used in
// messages. External URIs resolve against `base_dir`; with an empty `base_dir` a file
// naming an external buffer is refused and external images are not checked. Never reads
// past `size`.
Status load_gltf_from_memory(const std::string& name, const std::string& extension, const uint8_t* data, size_t size,
                             const std::filesystem::path& base_dir, MeshData& out);

// The files a .gltf or .glb names by URI (external buffers and images, resolved next to it,
// percent-decoded; data URIs excluded), so a cache key can cover them too. Empty when the
// file cannot be read or parsed: the load itself then says why.
std::vector<std::filesystem::path> gltf_external_files(const std::filesystem::path& path);

}  // namespace lod
