// glTF 2.0 import (Khronos glTF 2.0 specification, KHR_mesh_quantization). tinygltf parses the
// JSON and fills the buffers (images are never decoded: only their URIs, or for images inside
// the file their PNG / JPEG bytes, matter here); then a
// chain of passes checks and flattens what it gave, allocating only once the sizes are known:
//
//   check_glb_container -> parse_with_tinygltf -> check_extensions -> check_buffer_views
//   -> collect_instances (scene tree, world matrices) -> plan_mesh (accessors checked, counts
//   known) -> check_budget -> emit_primitive per instance -> read_materials -> check_images
//
// tinygltf is compiled here and nowhere else (TINYGLTF_IMPLEMENTATION), so a sanitizer or
// fuzzer build instruments its parser too.
#include "preprocess/gltf_io.h"

// Before tinygltf: it includes nlohmann/json under hidden visibility, and whatever POSIX
// declarations that pulls in first would be hidden too (read and close then fail to link).
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <memory>

#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <limits>
#include <map>
#include <new>
#include <span>

#include "preprocess/mesh_readers.h"

namespace lod {
namespace detail {
namespace {

namespace fs = std::filesystem;

// Where the bytes came from: named in every message; external files resolve under base_dir
// (empty = in memory, none are read).
struct GltfSource {
  std::string what;
  std::string base_dir;  // absolute, or empty
  size_t file_bytes = 0;
};

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

uint32_t read_u32(const uint8_t* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}

// ---- container ----------------------------------------------------------------------------

// The GLB header and chunk table, checked before tinygltf sees it (its own check lets a BIN
// chunk run 8 bytes past the end). Sets `size` to the declared length.
Status check_glb_container(const std::string& what, const uint8_t* data, size_t& size) {
  if (size < 12) return Status::error(what + ": truncated GLB: " + std::to_string(size) + " bytes, the header needs 12");
  if (std::memcmp(data, "glTF", 4) != 0) return Status::error(what + ": not a GLB file (the first 4 bytes are not 'glTF')");
  const uint32_t version = read_u32(data + 4), length = read_u32(data + 8);
  if (version != 2) return Status::error(what + ": GLB version " + std::to_string(version) + " (only 2 is supported)");
  if (length > size)
    return Status::error(what + ": truncated GLB: the header declares " + std::to_string(length) + " bytes, the file has " +
                         std::to_string(size));
  if (length < 20) return Status::error(what + ": GLB length " + std::to_string(length) + " leaves no room for the JSON chunk");
  const uint64_t json_length = read_u32(data + 12);
  if (read_u32(data + 16) != 0x4E4F534Au) return Status::error(what + ": GLB chunk 0 is not the JSON chunk");
  if (json_length == 0) return Status::error(what + ": GLB JSON chunk is empty");
  const uint64_t json_end = 20 + json_length;
  if (json_end > length)
    return Status::error(what + ": truncated GLB: JSON chunk of " + std::to_string(json_length) + " bytes runs past the " +
                         std::to_string(length) + "-byte file");
  if (json_end < length) {
    if (json_end + 8 > length) return Status::error(what + ": truncated GLB: chunk 1 header cut short");
    const uint64_t bin_length = read_u32(data + json_end);
    if (read_u32(data + json_end + 4) != 0x004E4942u) return Status::error(what + ": GLB chunk 1 is not a BIN chunk");
    if (json_end + 8 + bin_length > length)
      return Status::error(what + ": truncated GLB: BIN chunk of " + std::to_string(bin_length) + " bytes runs past the " +
                           std::to_string(length) + "-byte file");
    if (bin_length < 4 || bin_length % 4 != 0)
      return Status::error(what + ": GLB BIN chunk length " + std::to_string(bin_length) +
                           " is not a positive multiple of 4");
  }
  size = length;
  return Status::success();
}

// ---- tinygltf callbacks: no image is decoded, no file outside base_dir is read ------------

// A data-URI image's bytes exist only here (tinygltf decoded the base64 into a scratch
// vector), so they are kept as they are, up to kMaxEmbeddedImageBytes (a larger one stays
// empty and read_texture says so). A buffer view's bytes are not touched here: tinygltf hands
// them over before check_buffer_views has checked the view lies inside its buffer.
bool keep_image_undecoded(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                          const unsigned char* bytes, int size, void*) {
  image->image.clear();
  image->as_is = true;
  if (image->bufferView < 0 && image->uri.empty() && bytes && size > 0 && size_t(size) <= kMaxEmbeddedImageBytes)
    image->image.assign(bytes, bytes + size);
  return true;
}

bool file_exists(const std::string& path, void* user) {
  const auto* src = static_cast<const GltfSource*>(user);
  if (src->base_dir.empty() || path.compare(0, src->base_dir.size() + 1, src->base_dir + "/") != 0) return false;
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

std::string expand_path(const std::string& path, void*) { return path; }

bool read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  const auto* src = static_cast<const GltfSource*>(user);
  if (src->base_dir.empty()) {
    *err = "external files are not read for input in memory";
    return false;
  }
  // Images (by their extension) have the texture limit; buffers are bounded by glTF's own.
  const std::string ext = lower(fs::path(path).extension().string());
  const bool image = ext == ".png" || ext == ".jpg" || ext == ".jpeg";
  const FileLimit limit = image ? kTextureFileLimit : FileLimit{std::numeric_limits<uint32_t>::max(), "a glTF buffer"};
  std::vector<uint8_t> bytes;
  if (Status s = read_regular_file(path, limit, bytes); !s) {
    *err = s.message;
    return false;
  }
  out->swap(bytes);
  return true;
}

// A file's bytes in storage that is not zero-filled first (a 1M-triangle GLB is 28 MB that
// would otherwise be written twice before it is parsed).
struct FileBytes {
  std::unique_ptr<uint8_t[]> data;
  size_t size = 0;
};

// The file's bytes, as many as open_mesh_file allows (a GLB: what its header declares).
Status read_file_bytes(const fs::path& path, FileBytes& out) {
  RegularFile f;
  uint64_t n = 0;
  if (Status s = open_mesh_file(path, f, n); !s) return s;
  if (n > physical_memory_bytes())
    return Status::error(f.what + ": is " + std::to_string(n) + " bytes, more than this machine's memory");
  try {
    out.data = std::make_unique_for_overwrite<uint8_t[]>(size_t(n));
  } catch (const std::bad_alloc&) {
    return Status::error(f.what + ": not enough memory to read its " + std::to_string(n) + " bytes");
  }
  Status read;
  out.size = f.read_at(out.data.get(), size_t(n), 0, read);
  if (!read) return read;
  if (out.size == 0) return Status::error(f.what + ": file is empty");
  return Status::success();
}

bool write_whole_file(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  *err = "the importer writes nothing";
  return false;
}

// tinygltf's multi-line messages as one line.
std::string one_line(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  for (size_t i = 0; (i = s.find('\n', i)) != std::string::npos;) s.replace(i, 1, "; ");
  return s;
}

bool is_compression(const std::string& ext) {
  return ext == "KHR_draco_mesh_compression" || ext == "EXT_meshopt_compression" || ext == "KHR_meshopt_compression";
}

Status compression_refusal(const std::string& what, const std::string& ext) {
  return Status::error(what + ": requires " + ext + " (" +
                       (ext == "KHR_draco_mesh_compression" ? "Draco" : "meshopt") +
                       "-compressed geometry), which is not supported; export it uncompressed");
}

Status parse_with_tinygltf(const GltfSource& src, bool binary, const uint8_t* data, size_t size,
                           tinygltf::Model& model, std::vector<std::string>& warnings) {
  if (size > std::numeric_limits<unsigned int>::max())
    return Status::error(src.what + ": is too large for glTF (" + std::to_string(size) + " bytes)");
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(keep_image_undecoded, nullptr);
  loader.SetFsCallbacks({file_exists, expand_path, read_whole_file, write_whole_file, const_cast<GltfSource*>(&src)});
  std::string err, warn;
  bool ok = false;
  try {
    ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, data, unsigned(size), src.base_dir)
                : loader.LoadASCIIFromString(&model, &err, &warn, reinterpret_cast<const char*>(data), unsigned(size),
                                             src.base_dir);
  } catch (const std::bad_alloc&) {
    return Status::error(src.what + ": not enough memory to parse it (" + std::to_string(size) + " bytes)");
  } catch (const std::exception& e) {
    ok = false;
    err += e.what();
  }
  if (!warn.empty()) warnings.push_back(src.what + ": " + one_line(warn));
  if (ok) return Status::success();
  // A compressed file usually fails on its fallback-less buffers: say why instead.
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  for (const char* ext : {"KHR_draco_mesh_compression", "EXT_meshopt_compression", "KHR_meshopt_compression"})
    if (text.find(ext) != std::string_view::npos) return compression_refusal(src.what, ext);
  return Status::error(src.what + ": not valid glTF: " + (err.empty() ? std::string("parse failed") : one_line(err)));
}

// ---- extensions and buffer views ------------------------------------------------------------

Status check_extensions(const std::string& what, const tinygltf::Model& m, std::vector<std::string>& warnings) {
  for (const std::string& ext : m.extensionsRequired) {
    if (is_compression(ext)) return compression_refusal(what, ext);
    if (ext != "KHR_mesh_quantization" && ext != "KHR_texture_transform")
      warnings.push_back(what + ": requires extension " + ext + ", which is not applied (geometry imported as is)");
  }
  for (const std::string& ext : m.extensionsUsed) {
    if (is_compression(ext))
      warnings.push_back(what + ": " + ext + " is optional here; the uncompressed fallback data is imported");
  }
  return Status::success();
}

Status check_buffer_views(const std::string& what, const tinygltf::Model& m) {
  for (size_t v = 0; v < m.bufferViews.size(); ++v) {
    const tinygltf::BufferView& view = m.bufferViews[v];
    const std::string name = what + ": buffer view " + std::to_string(v);
    if (view.buffer < 0 || size_t(view.buffer) >= m.buffers.size())
      return Status::error(name + " references buffer " + std::to_string(view.buffer) + " of " +
                           std::to_string(m.buffers.size()));
    const size_t have = m.buffers[size_t(view.buffer)].data.size();
    if (view.byteOffset > have || view.byteLength > have - view.byteOffset)
      return Status::error(name + " (bytes " + std::to_string(view.byteOffset) + " + " + std::to_string(view.byteLength) +
                           ") runs past the end of buffer " + std::to_string(view.buffer) + " (" + std::to_string(have) +
                           " bytes)");
    if (view.byteStride != 0 && (view.byteStride < 4 || view.byteStride > 252 || view.byteStride % 4 != 0))
      return Status::error(name + ": byteStride " + std::to_string(view.byteStride) +
                           " is not a multiple of 4 in [4, 252]");
  }
  return Status::success();
}

// ---- scene tree ----------------------------------------------------------------------------

struct Instance {
  int mesh = -1;
  int node = -1;
  glm::dmat4 world{1.0};
};

glm::dmat4 local_matrix(const tinygltf::Node& n) {
  if (n.matrix.size() == 16) return glm::make_mat4(n.matrix.data());  // column-major, as glTF stores it
  glm::dmat4 t{1.0}, r{1.0}, s{1.0};
  if (n.translation.size() == 3) t = glm::translate(glm::dmat4{1.0}, glm::make_vec3(n.translation.data()));
  if (n.rotation.size() == 4)
    r = glm::mat4_cast(glm::normalize(glm::dquat(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2])));
  if (n.scale.size() == 3) s = glm::scale(glm::dmat4{1.0}, glm::make_vec3(n.scale.data()));
  return t * r * s;
}

bool finite_matrix(const glm::dmat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

// Every node with a mesh in the chosen scene, with its world matrix (parents first, by an
// explicit stack: a deep chain cannot overflow the call stack). A node reached twice (a cycle,
// or a child shared by two parents) is refused, as the glTF spec forbids both.
Status collect_instances(const std::string& what, const tinygltf::Model& m, std::vector<Instance>& out,
                         std::vector<std::string>& warnings) {
  if (m.scenes.empty()) {
    if (!m.meshes.empty()) warnings.push_back(what + ": has no scene; every mesh is placed once, untransformed");
    for (size_t i = 0; i < m.meshes.size(); ++i) out.push_back({int(i), -1, glm::dmat4{1.0}});
    return Status::success();
  }
  const int scene = m.defaultScene >= 0 ? m.defaultScene : 0;
  if (size_t(scene) >= m.scenes.size())
    return Status::error(what + ": default scene " + std::to_string(scene) + " of " + std::to_string(m.scenes.size()));
  std::vector<uint8_t> seen(m.nodes.size(), 0);
  std::vector<std::pair<int, glm::dmat4>> stack;
  const std::vector<int>& roots = m.scenes[size_t(scene)].nodes;
  for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back({*it, glm::dmat4{1.0}});
  while (!stack.empty()) {
    const auto [n, parent] = stack.back();
    stack.pop_back();
    if (n < 0 || size_t(n) >= m.nodes.size())
      return Status::error(what + ": scene " + std::to_string(scene) + " references node " + std::to_string(n) + " of " +
                           std::to_string(m.nodes.size()));
    if (seen[size_t(n)]) return Status::error(what + ": node " + std::to_string(n) + " is reached twice (a cycle or a shared child)");
    seen[size_t(n)] = 1;
    const tinygltf::Node& node = m.nodes[size_t(n)];
    const glm::dmat4 world = parent * local_matrix(node);
    if (!finite_matrix(world)) return Status::error(what + ": node " + std::to_string(n) + " has a non-finite transform");
    if (node.mesh >= 0) {
      if (size_t(node.mesh) >= m.meshes.size())
        return Status::error(what + ": node " + std::to_string(n) + " references mesh " + std::to_string(node.mesh) +
                             " of " + std::to_string(m.meshes.size()));
      out.push_back({node.mesh, n, world});
      if (node.skin >= 0)
        warnings.push_back(what + ": node " + std::to_string(n) + ": skin " + std::to_string(node.skin) +
                           " is not applied (the bind pose is imported)");
    }
    for (auto it = node.children.rbegin(); it != node.children.rend(); ++it) stack.push_back({*it, world});
  }
  return Status::success();
}

// ---- accessors ------------------------------------------------------------------------------

// A checked window on an accessor's elements: element i is at data + i * stride (data null =
// the accessor has no buffer view and reads as zeros, as the spec says).
struct AccessorView {
  const uint8_t* data = nullptr;
  size_t count = 0;
  size_t stride = 0;
  int component_type = 0;
  int components = 0;
  bool normalized = false;
};

enum class Role : uint8_t { position, normal, texcoord, color, indices };

const char* role_name(Role r) {
  switch (r) {
    case Role::position: return "POSITION";
    case Role::normal: return "NORMAL";
    case Role::texcoord: return "TEXCOORD";
    case Role::color: return "COLOR";
    case Role::indices: return "indices";
  }
  return "?";
}

// Component types the core spec and KHR_mesh_quantization allow for each role (COLOR_n: float,
// or normalized unsigned byte / short; quantization adds none).
bool legal_component(Role role, int type, bool normalized) {
  if (role == Role::color)
    return type == TINYGLTF_COMPONENT_TYPE_FLOAT ? !normalized
                                                 : normalized && (type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                                                                  type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return role != Role::indices && !normalized;
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_SHORT: return role == Role::position || role == Role::texcoord || (role == Role::normal && normalized);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return role == Role::indices ? !normalized : role != Role::normal;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return role == Role::indices && !normalized;
    default: return false;
  }
}

Status view_accessor(const std::string& where, const tinygltf::Model& m, int index, Role role, AccessorView& out) {
  const std::string what = where + ": " + role_name(role) + " accessor " + std::to_string(index);
  if (index < 0 || size_t(index) >= m.accessors.size())
    return Status::error(where + ": " + role_name(role) + " references accessor " + std::to_string(index) + " of " +
                         std::to_string(m.accessors.size()));
  const tinygltf::Accessor& a = m.accessors[size_t(index)];
  if (a.sparse.isSparse) return Status::error(what + ": sparse accessors are not supported");
  int want = role == Role::indices ? TINYGLTF_TYPE_SCALAR : role == Role::texcoord ? TINYGLTF_TYPE_VEC2 : TINYGLTF_TYPE_VEC3;
  if (role == Role::color && a.type == TINYGLTF_TYPE_VEC4) want = TINYGLTF_TYPE_VEC4;  // RGB or RGBA
  if (a.type != want)
    return Status::error(what + ": type " + std::to_string(a.type) + " (expected " +
                         (want == TINYGLTF_TYPE_SCALAR ? "SCALAR"
                          : want == TINYGLTF_TYPE_VEC2 ? "VEC2"
                          : role == Role::color        ? "VEC3 or VEC4"
                                                       : "VEC3") +
                         ")");
  if (!legal_component(role, a.componentType, a.normalized))
    return Status::error(what + ": componentType " + std::to_string(a.componentType) + (a.normalized ? " normalized" : "") +
                         " is not allowed for " + role_name(role));
  if (a.count == 0) return Status::error(what + ": count is 0");
  out = {};
  out.count = a.count;
  out.component_type = a.componentType;
  out.components = want == TINYGLTF_TYPE_SCALAR ? 1 : want == TINYGLTF_TYPE_VEC2 ? 2 : want == TINYGLTF_TYPE_VEC4 ? 4 : 3;
  out.normalized = a.normalized;
  const size_t element = size_t(tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType))) * size_t(out.components);
  if (a.bufferView < 0) {
    if (role == Role::indices) return Status::error(what + ": has no buffer view");
    // All zeros: at most one element per byte of the file, so a declared count cannot
    // make us allocate more than the file could describe.
    out.stride = element;
    return Status::success();
  }
  if (size_t(a.bufferView) >= m.bufferViews.size())
    return Status::error(what + " references buffer view " + std::to_string(a.bufferView) + " of " +
                         std::to_string(m.bufferViews.size()));
  const tinygltf::BufferView& view = m.bufferViews[size_t(a.bufferView)];  // within its buffer: check_buffer_views
  if (role == Role::indices && view.byteStride != 0)
    return Status::error(what + ": buffer view " + std::to_string(a.bufferView) + " of indices has a byteStride");
  out.stride = view.byteStride != 0 ? view.byteStride : element;
  if (out.stride < element)
    return Status::error(what + ": byteStride " + std::to_string(out.stride) + " of buffer view " +
                         std::to_string(a.bufferView) + " is shorter than its " + std::to_string(element) +
                         "-byte elements");
  // Checked without overflow: count <= view length first (every element takes a byte).
  const size_t length = view.byteLength;
  const bool fits = a.byteOffset <= length && a.count <= length &&
                    (a.count - 1) * out.stride + element <= length - a.byteOffset;
  if (!fits)
    return Status::error(what + ": " + std::to_string(a.count) + " elements of " + std::to_string(element) +
                         " bytes (stride " + std::to_string(out.stride) + ", offset " + std::to_string(a.byteOffset) +
                         ") do not fit in buffer view " + std::to_string(a.bufferView) + " (" + std::to_string(length) +
                         " bytes)");
  out.data = m.buffers[size_t(view.buffer)].data.data() + view.byteOffset + a.byteOffset;
  return Status::success();
}

template <class T>
T load_as(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// One component as a float: normalized integers map to [0,1] or [-1,1] (spec 3.11).
float read_component(const uint8_t* p, int type, bool normalized) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return load_as<float>(p);
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const float v = float(load_as<int8_t>(p));
      return normalized ? std::max(v / 127.0f, -1.0f) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? float(*p) / 255.0f : float(*p);
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      const float v = float(load_as<int16_t>(p));
      return normalized ? std::max(v / 32767.0f, -1.0f) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      const float v = float(load_as<uint16_t>(p));
      return normalized ? v / 65535.0f : v;
    }
    default: return 0.0f;  // excluded by legal_component
  }
}

void read_element(const AccessorView& a, size_t i, float* out) {
  if (!a.data) {
    std::fill(out, out + a.components, 0.0f);
    return;
  }
  const uint8_t* p = a.data + i * a.stride;
  const size_t size = size_t(tinygltf::GetComponentSizeInBytes(uint32_t(a.component_type)));
  for (int c = 0; c < a.components; ++c) out[c] = read_component(p + size_t(c) * size, a.component_type, a.normalized);
}

uint32_t read_index(const AccessorView& a, size_t i) {
  const uint8_t* p = a.data + i * a.stride;
  switch (a.component_type) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return *p;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return load_as<uint16_t>(p);
    default: return load_as<uint32_t>(p);
  }
}

// ---- planning: every primitive checked and counted before anything is allocated ------------

// uv' = (m[0] u + m[1] v + m[2], m[3] u + m[4] v + m[5]): KHR_texture_transform's T * R * S.
struct UvTransform {
  double m[6] = {1, 0, 0, 0, 1, 0};
  bool identity = true;
};

// A material's five texture references in kTextureSlots order, with the texCoord each reads
// (KHR_texture_transform's texCoord overrides the texture info's, as that extension says).
struct TextureRef {
  const char* name = "";
  int index = -1, tex_coord = 0;
  const tinygltf::Value* transform = nullptr;  // the KHR_texture_transform object, or null
};

TextureRef texture_ref(const char* name, int index, int tex_coord, const tinygltf::ExtensionMap& extensions) {
  TextureRef r{name, index, tex_coord, nullptr};
  const auto it = extensions.find("KHR_texture_transform");
  if (it == extensions.end() || !it->second.IsObject()) return r;
  r.transform = &it->second;
  const tinygltf::Value& tc = it->second.Get("texCoord");
  if (tc.IsNumber() && std::isfinite(tc.GetNumberAsDouble()) && std::abs(tc.GetNumberAsDouble()) < 1e6)
    r.tex_coord = int(tc.GetNumberAsDouble());
  return r;
}

std::array<TextureRef, kTextureSlots> texture_refs(const tinygltf::Material& src) {
  const tinygltf::PbrMetallicRoughness& pbr = src.pbrMetallicRoughness;
  return {texture_ref("baseColorTexture", pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                      pbr.baseColorTexture.extensions),
          texture_ref("metallicRoughnessTexture", pbr.metallicRoughnessTexture.index,
                      pbr.metallicRoughnessTexture.texCoord, pbr.metallicRoughnessTexture.extensions),
          texture_ref("normalTexture", src.normalTexture.index, src.normalTexture.texCoord, src.normalTexture.extensions),
          texture_ref("occlusionTexture", src.occlusionTexture.index, src.occlusionTexture.texCoord,
                      src.occlusionTexture.extensions),
          texture_ref("emissiveTexture", src.emissiveTexture.index, src.emissiveTexture.texCoord,
                      src.emissiveTexture.extensions)};
}

UvTransform uv_transform_of(const TextureRef& r) {
  UvTransform t;
  if (!r.transform) return t;
  const tinygltf::Value& v = *r.transform;
  auto number = [](const tinygltf::Value& x, int i, double fallback) {
    if (!x.IsArray() || int(x.ArrayLen()) <= i || !x.Get(i).IsNumber()) return fallback;
    const double d = x.Get(i).GetNumberAsDouble();
    return std::isfinite(d) ? d : fallback;
  };
  const double ox = number(v.Get("offset"), 0, 0), oy = number(v.Get("offset"), 1, 0);
  const double sx = number(v.Get("scale"), 0, 1), sy = number(v.Get("scale"), 1, 1);
  const double angle = v.Get("rotation").IsNumber() && std::isfinite(v.Get("rotation").GetNumberAsDouble())
                        ? v.Get("rotation").GetNumberAsDouble()
                        : 0.0;
  const double c = std::cos(angle), s = std::sin(angle);
  const double mat[6] = {c * sx, s * sy, ox, -s * sx, c * sy, oy};
  std::copy(mat, mat + 6, t.m);
  t.identity = std::equal(mat, mat + 6, UvTransform{}.m);
  return t;
}

// One uv per vertex and set: the transform of the first texture (in slot order, so the base
// colour's first) reading that set is applied to it (gltfpack stores quantized uvs this way).
// A texture on the same set with another transform cannot be kept exactly: `conflict` names it.
std::array<UvTransform, 2> uv_transforms_of(const tinygltf::Model& m, int material, std::string* conflict = nullptr) {
  std::array<UvTransform, 2> out;
  if (material < 0 || size_t(material) >= m.materials.size()) return out;
  const std::array<TextureRef, kTextureSlots> refs = texture_refs(m.materials[size_t(material)]);
  for (int set = 0; set < 2; ++set) {
    const TextureRef* first = nullptr;
    for (const TextureRef& r : refs) {
      if (r.index < 0 || r.tex_coord != set) continue;
      const UvTransform t = uv_transform_of(r);
      if (!first) first = &r, out[size_t(set)] = t;
      else if (conflict && conflict->empty() && !std::equal(t.m, t.m + 6, out[size_t(set)].m))
        *conflict = std::string(r.name) + " has another KHR_texture_transform than " + first->name + " on TEXCOORD_" +
                    std::to_string(set) + "; " + first->name + "'s is applied to the uvs, so " + r.name +
                    " is sampled without its own";
    }
  }
  return out;
}

struct PrimitivePlan {
  std::array<UvTransform, 2> uv_transforms;  // TEXCOORD_0, TEXCOORD_1
  int mesh = -1, primitive = -1;
  int mode = TINYGLTF_MODE_TRIANGLES;
  int material = -1;
  AccessorView position, normal, uv, uv1, color, indices;
  bool has_normal = false, has_uv = false, has_uv1 = false, has_color = false, indexed = false;
  size_t triangles = 0;
  size_t vertices() const { return position.count; }
};

size_t triangles_of(int mode, size_t corners) {
  if (mode == TINYGLTF_MODE_TRIANGLES) return corners / 3;
  return corners >= 3 ? corners - 2 : 0;  // strip or fan
}

const char* mode_name(int mode) {
  switch (mode) {
    case TINYGLTF_MODE_POINTS: return "POINTS";
    case TINYGLTF_MODE_LINE: return "LINES";
    case TINYGLTF_MODE_LINE_LOOP: return "LINE_LOOP";
    case TINYGLTF_MODE_LINE_STRIP: return "LINE_STRIP";
    default: return "?";
  }
}

// Plans one mesh's triangle primitives (others are skipped with a warning). Attributes that
// are not imported are named once per file in `ignored` (first primitive that has them).
Status plan_mesh(const std::string& what, const tinygltf::Model& m, int mesh, std::vector<PrimitivePlan>& out,
                 std::map<std::string, std::string>& ignored, std::vector<std::string>& warnings) {
  const tinygltf::Mesh& me = m.meshes[size_t(mesh)];
  for (size_t p = 0; p < me.primitives.size(); ++p) {
    const tinygltf::Primitive& prim = me.primitives[p];
    const std::string where = what + ": mesh " + std::to_string(mesh) + " primitive " + std::to_string(p);
    if (prim.mode >= TINYGLTF_MODE_POINTS && prim.mode <= TINYGLTF_MODE_LINE_STRIP) {
      warnings.push_back(where + ": mode " + mode_name(prim.mode) + " is not a triangle mode; skipped");
      continue;
    }
    if (prim.mode < TINYGLTF_MODE_TRIANGLES || prim.mode > TINYGLTF_MODE_TRIANGLE_FAN)
      return Status::error(where + ": mode " + std::to_string(prim.mode) + " is not a glTF primitive mode");
    if (prim.extensions.count("KHR_draco_mesh_compression"))
      warnings.push_back(where + ": Draco data ignored; its uncompressed fallback accessors are imported");
    if (!prim.targets.empty())
      warnings.push_back(where + ": " + std::to_string(prim.targets.size()) +
                         " morph targets not applied (the base shape is imported)");
    PrimitivePlan plan;
    plan.mesh = mesh;
    plan.primitive = int(p);
    plan.mode = prim.mode;
    plan.material = prim.material;
    if (plan.material >= 0 && size_t(plan.material) >= m.materials.size())
      return Status::error(where + ": material " + std::to_string(plan.material) + " of " +
                           std::to_string(m.materials.size()));
    plan.uv_transforms = uv_transforms_of(m, plan.material);
    const auto pos = prim.attributes.find("POSITION");
    if (pos == prim.attributes.end()) return Status::error(where + ": has no POSITION attribute");
    for (const auto& [name, accessor] : prim.attributes) {
      Status s;
      if (name == "POSITION") s = view_accessor(where, m, accessor, Role::position, plan.position);
      else if (name == "NORMAL") s = view_accessor(where, m, accessor, Role::normal, plan.normal), plan.has_normal = true;
      else if (name == "TEXCOORD_0") s = view_accessor(where, m, accessor, Role::texcoord, plan.uv), plan.has_uv = true;
      else if (name == "TEXCOORD_1") s = view_accessor(where, m, accessor, Role::texcoord, plan.uv1), plan.has_uv1 = true;
      else if (name == "COLOR_0") s = view_accessor(where, m, accessor, Role::color, plan.color), plan.has_color = true;
      else if (name.rfind("TEXCOORD_", 0) == 0) {
        AccessorView unused;
        s = view_accessor(where, m, accessor, Role::texcoord, unused);
        ignored.emplace(name, where);
      } else {
        ignored.emplace(name, where);
      }
      if (!s) return s;
    }
    if (plan.vertices() > std::numeric_limits<uint32_t>::max())
      return Status::error(where + ": " + std::to_string(plan.vertices()) + " vertices do not fit 32-bit indices");
    const std::pair<const AccessorView*, const char*> columns[] = {
        {&plan.normal, "NORMAL"}, {&plan.uv, "TEXCOORD_0"}, {&plan.uv1, "TEXCOORD_1"}, {&plan.color, "COLOR_0"}};
    for (const auto& [attr, attr_name] : columns)
      if (attr->count != 0 && attr->count != plan.vertices())
        return Status::error(where + ": " + attr_name + " has " + std::to_string(attr->count) + " elements, POSITION " +
                             std::to_string(plan.vertices()));
    size_t corners = plan.vertices();
    if (prim.indices >= 0) {
      if (Status s = view_accessor(where, m, prim.indices, Role::indices, plan.indices); !s) return s;
      plan.indexed = true;
      corners = plan.indices.count;
    }
    plan.triangles = triangles_of(plan.mode, corners);
    if (plan.mode == TINYGLTF_MODE_TRIANGLES && corners % 3 != 0)
      warnings.push_back(where + ": " + std::to_string(corners) + " corners are not a multiple of 3; the last " +
                         std::to_string(corners % 3) + " ignored");
    if (plan.triangles == 0) {
      warnings.push_back(where + ": has no triangles (" + std::to_string(corners) + " corners); skipped");
      continue;
    }
    out.push_back(plan);
  }
  return Status::success();
}

// Instancing can make a small file flatten into a huge mesh: refuse output beyond 256 times
// the bytes the file (and its buffers) hold, with 16 MiB always allowed (below the fuzzer's
// 64 MB allocation limit), and beyond what 32-bit indices address.
Status check_budget(const std::string& what, size_t input_bytes, uint64_t vertices, uint64_t triangles,
                    uint64_t bytes_per_vertex) {
  if (vertices > std::numeric_limits<uint32_t>::max() || triangles > std::numeric_limits<uint32_t>::max() / 3)
    return Status::error(what + ": flattens to " + std::to_string(vertices) + " vertices and " + std::to_string(triangles) +
                         " triangles, beyond 32-bit indices");
  const uint64_t bytes = vertices * bytes_per_vertex + triangles * 12;
  const uint64_t budget = std::max<uint64_t>(uint64_t(16) << 20, uint64_t(input_bytes) * 256);
  if (bytes > budget)
    return Status::error(what + ": the scene flattens (nodes instancing meshes) to " + std::to_string(triangles) +
                         " triangles, " + std::to_string(bytes >> 20) + " MiB from a " + std::to_string(input_bytes) +
                         "-byte file; refusing more than 256 times its size");
  return Status::success();
}

// ---- emitting --------------------------------------------------------------------------------

struct Columns {
  bool normals = false, uvs = false, uvs1 = false, colors = false;
};

// Every element of an accessor into out[0, count * components): floats copied as they are,
// integers converted (read_component); no buffer view reads as zeros.
void decode_elements(const AccessorView& a, float* out) {
  const size_t n = a.count, k = size_t(a.components);
  if (!a.data) {
    std::fill(out, out + n * k, 0.0f);
  } else if (a.component_type == TINYGLTF_COMPONENT_TYPE_FLOAT && a.stride == 4 * k) {
    std::memcpy(out, a.data, 4 * k * n);
  } else if (a.component_type == TINYGLTF_COMPONENT_TYPE_FLOAT) {
    for (size_t i = 0; i < n; ++i) std::memcpy(out + i * k, a.data + i * a.stride, 4 * k);
  } else {
    for (size_t i = 0; i < n; ++i) read_element(a, i, out + i * k);
  }
}

// Values per block of the fused copy-and-check passes: a block just copied is still in the
// L1/L2 cache when it is checked, so a column is streamed through memory once.
constexpr size_t kBlockValues = 4096;

// Whether any of p[0, n) is inf or nan: branch-free on the exponent bits, so it vectorizes.
bool any_nonfinite(const float* p, size_t n) {
  uint32_t any = 0;
  for (size_t i = 0; i < n; ++i) any |= uint32_t((std::bit_cast<uint32_t>(p[i]) & 0x7f800000u) == 0x7f800000u);
  return any != 0;
}

// Appends the accessor's elements to `col`: tightly packed floats (the usual file) straight
// from the buffer, block by block, each block checked as it lands; the rest decoded. Returns
// whether a non-finite value may be among them (first_nonfinite then says where).
bool append_elements(const AccessorView& a, std::vector<float>& col) {
  const size_t values = a.count * size_t(a.components);
  if (a.data && a.component_type == TINYGLTF_COMPONENT_TYPE_FLOAT && a.stride == 4 * size_t(a.components)) {
    bool any = false;
    for (size_t b = 0; b < values; b += kBlockValues) {
      const size_t e = std::min(values, b + kBlockValues), at = col.size();
      col.resize(at + (e - b));  // zeros into one block, overwritten while it is in cache
      std::memcpy(col.data() + at, a.data + 4 * b, 4 * (e - b));
      any = any_nonfinite(col.data() + at, e - b) || any;
    }
    return any;
  }
  const size_t base = col.size();
  col.resize(base + values);
  decode_elements(a, col.data() + base);
  return true;
}

bool is_identity(const glm::dmat4& m) { return m == glm::dmat4(1.0); }

void transform_positions(const glm::dmat4& world, float* p, size_t n) {
  for (size_t v = 0; v < n; ++v, p += 3) {
    const glm::dvec4 w = world * glm::dvec4(p[0], p[1], p[2], 1.0);
    p[0] = float(w.x), p[1] = float(w.y), p[2] = float(w.z);
  }
}

// Normals go through the inverse transpose and are renormalized (a zero one stays zero).
void transform_normals(const glm::dmat4& world, float* p, size_t n) {
  const glm::dmat3 m = glm::transpose(glm::inverse(glm::dmat3(world)));
  for (size_t v = 0; v < n; ++v, p += 3) {
    glm::dvec3 t = m * glm::dvec3(p[0], p[1], p[2]);
    const double len = glm::length(t);
    if (len > 0) t /= len;
    p[0] = float(t.x), p[1] = float(t.y), p[2] = float(t.z);
  }
}

void transform_uvs(const UvTransform& t, float* p, size_t n) {
  for (size_t v = 0; v < n; ++v, p += 2) {
    const double u = p[0], w = p[1];
    p[0] = float(t.m[0] * u + t.m[1] * w + t.m[2]);
    p[1] = float(t.m[3] * u + t.m[4] * w + t.m[5]);
  }
}

// Index of the first non-finite value in p[0, n), or n.
size_t first_nonfinite(const float* p, size_t n) {
  for (size_t begin = 0; begin < n; begin += kBlockValues) {
    const size_t end = std::min(n, begin + kBlockValues);
    if (!any_nonfinite(p + begin, end - begin)) continue;
    for (size_t i = begin; i < end; ++i)
      if (!std::isfinite(p[i])) return i;
  }
  return n;
}

// Whether any of c[0, n) is >= limit: compares OR-ed together, which vectorizes even on
// baseline x86-64 (an unsigned max does not: SSE2 has no pmaxud).
bool any_at_least(const uint32_t* c, size_t n, uint32_t limit) {
  uint32_t any = 0;
  for (size_t i = 0; i < n; ++i) any |= uint32_t(c[i] >= limit);
  return any != 0;
}

// Appends the primitive's corners (its indices, or 0..n-1 without) to `out`; returns whether
// any is out of range (check_corners then says which), checked block by block as they land.
bool append_corners(const PrimitivePlan& plan, std::vector<uint32_t>& out) {
  const size_t base = out.size();
  const uint32_t vertices = uint32_t(plan.vertices());  // fits: plan_mesh checked
  if (!plan.indexed) {
    out.resize(base + plan.vertices());
    for (size_t i = 0; i < plan.vertices(); ++i) out[base + i] = uint32_t(i);
    return false;
  }
  const AccessorView& a = plan.indices;
  bool bad = false;
  if (a.component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {  // tight: indices have no stride
    for (size_t b = 0; b < a.count; b += kBlockValues) {
      const size_t e = std::min(a.count, b + kBlockValues), at = out.size();
      out.resize(at + (e - b));
      std::memcpy(out.data() + at, a.data + 4 * b, 4 * (e - b));
      bad = any_at_least(out.data() + at, e - b, vertices) || bad;
    }
    return bad;
  }
  out.resize(base + a.count);
  for (size_t i = 0; i < a.count; ++i) out[base + i] = read_index(a, i);
  return any_at_least(out.data() + base, a.count, vertices);
}

// Names the first corner out of range when there is one (`suspect`), then offsets every
// corner by `base`.
Status check_corners(const std::string& where, uint32_t* c, size_t count, bool suspect, size_t vertices, uint32_t base) {
  if (suspect)
    for (size_t i = 0; i < count; ++i)
      if (c[i] >= vertices)
        return Status::error(where + ": index " + std::to_string(i) + " references vertex " + std::to_string(c[i]) +
                             " of " + std::to_string(vertices));
  if (base != 0)
    for (size_t i = 0; i < count; ++i) c[i] += base;
  return Status::success();
}

enum class Winding : uint8_t { keep, flip };

// Corners to triangles (spec 3.7.2.1: strips alternate their winding, fans turn about corner
// 0), offset by `base`; under a mirroring transform the winding flips to keep the front face.
void triangles_from_corners(int mode, const uint32_t* c, size_t triangles, uint32_t base, Winding winding,
                            uint32_t* out) {
  for (size_t t = 0; t < triangles; ++t, out += 3) {
    if (mode == TINYGLTF_MODE_TRIANGLES) out[0] = c[3 * t], out[1] = c[3 * t + 1], out[2] = c[3 * t + 2];
    else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) out[0] = c[t], out[1] = c[t + 1 + t % 2], out[2] = c[t + 2 - t % 2];
    else out[0] = c[t + 1], out[1] = c[t + 2], out[2] = c[0];
    if (winding == Winding::flip) std::swap(out[1], out[2]);
    out[0] += base, out[1] += base, out[2] += base;
  }
}

// COLOR_0 as linear RGBA (an RGB one gets alpha 1; a primitive without gets white), refused
// when not finite; float values outside [0, 1] are clamped (the spec keeps colours there).
Status append_colors(const std::string& where, const PrimitivePlan& plan, size_t n, std::vector<float>& col) {
  const size_t base = col.size();
  if (!plan.has_color) {
    col.resize(base + 4 * n, 1.0f);
    return Status::success();
  }
  if (plan.color.components == 4) {
    append_elements(plan.color, col);
  } else {
    col.resize(base + 4 * n);
    float* q = col.data() + base;
    decode_elements(plan.color, q);  // 3 per vertex at the front, spread out back to front
    for (size_t v = n; v-- > 0;) {
      const float r = q[3 * v], g = q[3 * v + 1], b = q[3 * v + 2];
      q[4 * v] = r, q[4 * v + 1] = g, q[4 * v + 2] = b, q[4 * v + 3] = 1.0f;
    }
  }
  float* q = col.data() + base;
  if (const size_t bad = first_nonfinite(q, 4 * n); bad < 4 * n)
    return Status::error(where + ": vertex " + std::to_string(bad / 4) + " has a non-finite COLOR_0");
  for (size_t i = 0; i < 4 * n; ++i) q[i] = std::clamp(q[i], 0.0f, 1.0f);
  return Status::success();
}

// Appends one primitive under one node's transform, as passes over its new ranges: decode,
// transform, check finite, then corners -> triangles.
Status emit_primitive(const std::string& what, const PrimitivePlan& plan, const Instance& inst, Columns cols,
                      std::vector<uint32_t>& scratch, MeshData& out) {
  const std::string where = what + ": mesh " + std::to_string(plan.mesh) + " primitive " + std::to_string(plan.primitive);
  const size_t base = out.vertex_count(), n = plan.vertices();
  const bool moved = !is_identity(inst.world);

  // Each column is checked for non-finite values as it is copied; a transform (which can
  // overflow) or a decoded column is checked again whole.
  bool suspect = append_elements(plan.position, out.positions);
  float* p = out.positions.data() + 3 * base;
  if (moved) transform_positions(inst.world, p, n);
  if (const size_t bad = suspect || moved ? first_nonfinite(p, 3 * n) : 3 * n; bad < 3 * n)
    return Status::error(where + ": vertex " + std::to_string(bad / 3) + " has a non-finite position (" +
                         describe_nonfinite(p[bad]) + ")");
  if (cols.normals) {
    suspect = append_elements(plan.normal, out.normals);
    float* q = out.normals.data() + 3 * base;
    if (moved) transform_normals(inst.world, q, n);
    if (const size_t bad = suspect || moved ? first_nonfinite(q, 3 * n) : 3 * n; bad < 3 * n)
      return Status::error(where + ": vertex " + std::to_string(bad / 3) + " has a non-finite normal");
  }
  if (cols.uvs) {
    suspect = false;
    if (plan.has_uv) suspect = append_elements(plan.uv, out.uvs);
    else out.uvs.resize(2 * (base + n), 0.0f);  // (0, 0) for a primitive without TEXCOORD_0
    float* q = out.uvs.data() + 2 * base;
    const bool transformed = plan.has_uv && !plan.uv_transforms[0].identity;
    if (transformed) transform_uvs(plan.uv_transforms[0], q, n);
    if (const size_t bad = suspect || transformed ? first_nonfinite(q, 2 * n) : 2 * n; bad < 2 * n)
      return Status::error(where + ": vertex " + std::to_string(bad / 2) + " has a non-finite TEXCOORD_0");
  }
  if (cols.uvs1) {
    suspect = false;
    if (plan.has_uv1) suspect = append_elements(plan.uv1, out.uvs1);
    else out.uvs1.resize(2 * (base + n), 0.0f);  // (0, 0) for a primitive without TEXCOORD_1
    float* q = out.uvs1.data() + 2 * base;
    const bool transformed = plan.has_uv1 && !plan.uv_transforms[1].identity;
    if (transformed) transform_uvs(plan.uv_transforms[1], q, n);
    if (const size_t bad = suspect || transformed ? first_nonfinite(q, 2 * n) : 2 * n; bad < 2 * n)
      return Status::error(where + ": vertex " + std::to_string(bad / 2) + " has a non-finite TEXCOORD_1");
  }
  if (cols.colors)
    if (Status s = append_colors(where, plan, n, out.colors); !s) return s;

  const size_t first = out.triangle_count();
  const bool mirrored = glm::determinant(glm::dmat3(inst.world)) < 0;
  const size_t corners = plan.indexed ? plan.indices.count : n;
  if (plan.mode == TINYGLTF_MODE_TRIANGLES && !mirrored) {  // the common case: corners are the triangles
    const bool corners_suspect = append_corners(plan, out.indices);
    if (Status s = check_corners(where, out.indices.data() + 3 * first, corners, corners_suspect, n, uint32_t(base)); !s)
      return s;
    out.indices.resize(3 * (first + plan.triangles));  // a stray last corner or two
  } else {
    scratch.clear();
    const bool corners_suspect = append_corners(plan, scratch);
    if (Status s = check_corners(where, scratch.data(), corners, corners_suspect, n, 0); !s) return s;
    out.indices.resize(3 * (first + plan.triangles));
    triangles_from_corners(plan.mode, scratch.data(), plan.triangles, uint32_t(base),
                           mirrored ? Winding::flip : Winding::keep, out.indices.data() + 3 * first);
  }

  if (!out.submeshes.empty() && out.submeshes.back().material == plan.material)
    out.submeshes.back().triangle_count += uint32_t(plan.triangles);
  else
    out.submeshes.push_back({uint32_t(first), uint32_t(plan.triangles), plan.material});
  return Status::success();
}

// ---- materials and images ----------------------------------------------------------------

AlphaMode alpha_mode_of(const std::string& s) {
  if (s == "MASK") return AlphaMode::mask;
  if (s == "BLEND") return AlphaMode::blend;
  return AlphaMode::opaque;
}

// The PNG or JPEG bytes of an image the file holds itself (a buffer view, checked against its
// buffer by check_buffer_views, or a data URI, kept by keep_image_undecoded), or a reason.
std::string embedded_bytes(const tinygltf::Model& m, const tinygltf::Image& img, std::span<const uint8_t>& out) {
  if (img.bufferView >= 0) {
    if (size_t(img.bufferView) >= m.bufferViews.size())
      return "names buffer view " + std::to_string(img.bufferView) + " of " + std::to_string(m.bufferViews.size());
    const tinygltf::BufferView& view = m.bufferViews[size_t(img.bufferView)];
    if (view.byteLength > kMaxEmbeddedImageBytes)
      return "is " + std::to_string(view.byteLength) + " bytes, more than " + std::to_string(kMaxEmbeddedImageBytes);
    out = {m.buffers[size_t(view.buffer)].data.data() + view.byteOffset, view.byteLength};
  } else if (img.image.empty()) {
    return "is an empty data URI or more than " + std::to_string(kMaxEmbeddedImageBytes) + " bytes";
  } else {
    out = img.image;
  }
  if (image_type_of(out) == ImageType::unknown) {
    char head[32];
    std::snprintf(head, sizeof head, "%02x %02x %02x %02x", out.size() > 0 ? out[0] : 0, out.size() > 1 ? out[1] : 0,
                  out.size() > 2 ? out[2] : 0, out.size() > 3 ? out[3] : 0);
    return "is neither PNG nor JPEG (its first bytes are " + std::string(head) + "; glTF 2.0 core allows no other image)";
  }
  return {};
}

// Images the file holds itself, kept once each however many slots name them: glTF image ->
// MeshData::images index (-1 once refused, so it is said once per slot but copied never).
using EmbeddedIndex = std::map<int, int>;

// One texture reference (textureInfo) of material `i`: the texture and image it names must
// exist; an image inside the file is marked embedded and, when PNG or JPEG, kept in `images`
// and named "embedded:<k>" (else left out, said naming the material and slot); one read
// through another TEXCOORD than the imported TEXCOORD_0 / _1 is left out with a warning.
Status read_texture(const std::string& what, const tinygltf::Model& m, size_t i, const char* slot, int index,
                    int tex_coord, std::string& uri, bool& embedded, uint8_t& tex_coord_out,
                    std::vector<EmbeddedImage>& images, EmbeddedIndex& kept, std::vector<std::string>& warnings) {
  if (index < 0) return Status::success();
  const std::string name = what + ": material " + std::to_string(i) + ": " + slot;
  if (size_t(index) >= m.textures.size())
    return Status::error(name + " references texture " + std::to_string(index) + " of " + std::to_string(m.textures.size()));
  const int image = m.textures[size_t(index)].source;
  if (image < 0) return Status::success();
  if (size_t(image) >= m.images.size())
    return Status::error(name + ": texture " + std::to_string(index) + " references image " + std::to_string(image) +
                         " of " + std::to_string(m.images.size()));
  if (tex_coord < 0 || tex_coord > kMaxTexCoord) {
    warnings.push_back(name + " reads TEXCOORD_" + std::to_string(tex_coord) +
                       "; only TEXCOORD_0 and TEXCOORD_1 are imported, so the texture is not kept");
    return Status::success();
  }
  tex_coord_out = uint8_t(tex_coord);
  const tinygltf::Image& img = m.images[size_t(image)];
  uri = img.uri;
  embedded = uri.empty();
  if (!embedded) return Status::success();
  auto [at, fresh] = kept.try_emplace(image, -1);
  std::span<const uint8_t> bytes;
  const std::string why = embedded_bytes(m, img, bytes);
  if (!why.empty()) {
    warnings.push_back(name + ": embedded image " + std::to_string(image) + " " + why + "; the texture is not kept");
    return Status::success();
  }
  if (fresh) {
    uint64_t total = bytes.size();
    for (const EmbeddedImage& e : images) total += e.bytes.size();
    if (images.size() >= kMaxEmbeddedImages || total > kMaxEmbeddedBytes) {
      warnings.push_back(name + ": embedded image " + std::to_string(image) + " is past the first " +
                         std::to_string(kMaxEmbeddedImages) + " images or " + std::to_string(kMaxEmbeddedBytes) +
                         " bytes kept; the texture is not kept");
      return Status::success();
    }
    at->second = int(images.size());
    images.push_back({image_type_of(bytes), std::vector<uint8_t>(bytes.begin(), bytes.end())});
  }
  if (at->second >= 0) uri = embedded_image_uri(uint32_t(at->second));
  return Status::success();
}

Status read_materials(const std::string& what, const tinygltf::Model& m, std::vector<MeshMaterial>& out,
                      std::vector<EmbeddedImage>& images, std::vector<std::string>& warnings) {
  EmbeddedIndex kept;
  for (size_t i = 0; i < m.materials.size(); ++i) {
    const tinygltf::Material& src = m.materials[i];
    const tinygltf::PbrMetallicRoughness& pbr = src.pbrMetallicRoughness;
    MeshMaterial mat;
    mat.name = src.name;
    for (size_t c = 0; c < 4 && c < pbr.baseColorFactor.size(); ++c) mat.base_color[c] = float(pbr.baseColorFactor[c]);
    mat.metallic = float(pbr.metallicFactor);
    mat.roughness = float(pbr.roughnessFactor);
    mat.alpha_mode = alpha_mode_of(src.alphaMode);
    mat.alpha_cutoff = float(src.alphaCutoff);
    mat.double_sided = src.doubleSided;
    // Factors as written; the bake clamps what is out of range and says so (add_chain_materials).
    mat.normal_scale = float(src.normalTexture.scale);
    mat.occlusion_strength = float(src.occlusionTexture.strength);
    for (size_t c = 0; c < 3 && c < src.emissiveFactor.size(); ++c) mat.emissive[c] = float(src.emissiveFactor[c]);
    const auto slots = texture_slots(mat);
    const std::array<TextureRef, kTextureSlots> refs = texture_refs(src);
    for (size_t k = 0; k < kTextureSlots; ++k)
      if (Status s = read_texture(what, m, i, refs[k].name, refs[k].index, refs[k].tex_coord, *slots[k].uri,
                                  *slots[k].embedded, mat.tex_coords[k], images, kept, warnings);
          !s)
        return s;
    std::string conflict;
    uv_transforms_of(m, int(i), &conflict);
    if (!conflict.empty()) warnings.push_back(what + ": material " + std::to_string(i) + ": " + conflict);
    out.push_back(std::move(mat));
  }
  return Status::success();
}

// RFC 3986 percent-decoding of a relative URI, for finding the file it names.
std::string decode_uri(const std::string& uri) {
  std::string s;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(uint8_t(uri[i + 1])) && std::isxdigit(uint8_t(uri[i + 2]))) {
      s += char(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      s += uri[i];
    }
  }
  return s;
}

// External images must exist next to the file (a texture nobody can load is a broken asset).
Status check_images(const GltfSource& src, const tinygltf::Model& m) {
  if (src.base_dir.empty()) return Status::success();
  for (size_t i = 0; i < m.images.size(); ++i) {
    const std::string& uri = m.images[i].uri;
    if (uri.empty()) continue;
    if (uri.find("://") != std::string::npos) continue;  // a URL: not ours to fetch
    const fs::path p = fs::path(src.base_dir) / decode_uri(uri);
    std::error_code ec;
    if (!fs::is_regular_file(p, ec))
      return Status::error(src.what + ": image " + std::to_string(i) + " '" + quote_token(uri) + "' not found (looked for " +
                           p.string() + ")");
  }
  return Status::success();
}

// A file with thousands of skipped primitives says so in a few lines, not thousands.
void cap_warnings(std::vector<std::string>& warnings) {
  constexpr size_t kShown = 16;
  if (warnings.size() <= kShown) return;
  const size_t more = warnings.size() - kShown;
  warnings.resize(kShown);
  warnings.push_back("... and " + std::to_string(more) + " more warnings like these");
}

// ---- the pipeline ------------------------------------------------------------------------

Status import_model(const GltfSource& src, const tinygltf::Model& m, MeshData& out) {
  const std::string& what = src.what;
  MeshData mesh;
  mesh.source = what;
  std::vector<std::string>& warnings = mesh.warnings;
  if (Status s = check_extensions(what, m, warnings); !s) return s;
  if (Status s = check_buffer_views(what, m); !s) return s;
  std::vector<Instance> instances;
  if (Status s = collect_instances(what, m, instances, warnings); !s) return s;

  std::map<int, std::vector<PrimitivePlan>> plans;  // by mesh, planned once however often instanced
  std::map<std::string, std::string> ignored;
  uint64_t vertices = 0, triangles = 0;
  Columns cols;
  bool all_normals = true;
  for (const Instance& inst : instances) {
    auto [it, fresh] = plans.try_emplace(inst.mesh);
    if (fresh)
      if (Status s = plan_mesh(what, m, inst.mesh, it->second, ignored, warnings); !s) return s;
    for (const PrimitivePlan& p : it->second) {
      vertices += p.vertices();
      triangles += p.triangles;
      all_normals = all_normals && p.has_normal;
      cols.uvs = cols.uvs || p.has_uv;
      cols.uvs1 = cols.uvs1 || p.has_uv1;
      cols.colors = cols.colors || p.has_color;
    }
  }
  if (triangles == 0)
    return Status::error(what + ": no triangle primitives in the scene" +
                         (warnings.empty() ? std::string() : " (" + warnings.back() + ")"));
  cols.normals = all_normals;
  for (const auto& [name, first] : ignored)
    warnings.push_back(first + ": attribute " + name + " is not imported" + (name.rfind("JOINTS_", 0) == 0 || name.rfind("WEIGHTS_", 0) == 0 ? " (skinning)" : ""));
  size_t input_bytes = src.file_bytes;
  for (const tinygltf::Buffer& b : m.buffers) input_bytes += b.data.size();
  if (Status s = check_budget(what, input_bytes, vertices, triangles, 12 + (cols.normals ? 12 : 0) + (cols.uvs ? 8 : 0) + (cols.uvs1 ? 8 : 0) + (cols.colors ? 16 : 0));
      !s)
    return s;

  mesh.positions.reserve(3 * vertices);
  if (cols.normals) mesh.normals.reserve(3 * vertices);
  if (cols.uvs) mesh.uvs.reserve(2 * vertices);
  if (cols.uvs1) mesh.uvs1.reserve(2 * vertices);
  if (cols.colors) mesh.colors.reserve(4 * vertices);
  mesh.indices.reserve(3 * triangles);
  std::string missing_normals, missing_uvs, missing_uvs1, missing_colors;
  std::vector<uint32_t> scratch;
  for (const Instance& inst : instances)
    for (const PrimitivePlan& p : plans[inst.mesh]) {
      if (Status s = emit_primitive(what, p, inst, cols, scratch, mesh); !s) return s;
      const std::string name = "mesh " + std::to_string(p.mesh) + " primitive " + std::to_string(p.primitive);
      if (!p.has_normal && missing_normals.empty()) missing_normals = name;
      if (cols.uvs && !p.has_uv && missing_uvs.empty()) missing_uvs = name;
      if (cols.uvs1 && !p.has_uv1 && missing_uvs1.empty()) missing_uvs1 = name;
      if (cols.colors && !p.has_color && missing_colors.empty()) missing_colors = name;
    }
  if (!cols.normals && vertices > 0 && missing_normals.size() && std::any_of(plans.begin(), plans.end(), [](const auto& kv) {
        return std::any_of(kv.second.begin(), kv.second.end(), [](const PrimitivePlan& p) { return p.has_normal; });
      }))
    warnings.push_back(what + ": normals dropped: " + missing_normals + " has none (they are recomputed when baking)");
  if (!missing_uvs.empty()) warnings.push_back(what + ": " + missing_uvs + " has no TEXCOORD_0; its vertices get (0, 0)");
  if (!missing_uvs1.empty()) warnings.push_back(what + ": " + missing_uvs1 + " has no TEXCOORD_1; its vertices get (0, 0)");
  if (!missing_colors.empty())
    warnings.push_back(what + ": " + missing_colors + " has no COLOR_0; its vertices get white (1, 1, 1, 1)");
  if (Status s = read_materials(what, m, mesh.materials, mesh.images, warnings); !s) return s;
  if (Status s = check_images(src, m); !s) return s;
  cap_warnings(mesh.warnings);
  out = std::move(mesh);
  return Status::success();
}

Status load_gltf_bytes(const GltfSource& src, const std::string& extension, const uint8_t* data, size_t size,
                       MeshData& out) {
  const std::string ext = lower(extension);
  if (ext != ".gltf" && ext != ".glb")
    return Status::error(src.what + ": not a glTF extension '" + extension + "' (expected .gltf or .glb)");
  if (size == 0) return Status::error(src.what + ": file is empty");
  // A .gltf may hold GLB bytes and the other way round: the magic decides.
  const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  if (ext == ".glb" && !binary) return Status::error(src.what + ": not a GLB file (the first 4 bytes are not 'glTF')");
  if (binary)
    if (Status s = check_glb_container(src.what, data, size); !s) return s;
  try {
    tinygltf::Model model;
    std::vector<std::string> parse_warnings;
    if (Status s = parse_with_tinygltf(src, binary, data, size, model, parse_warnings); !s) return s;
    Status s = import_model(src, model, out);
    if (s) out.warnings.insert(out.warnings.begin(), parse_warnings.begin(), parse_warnings.end());
    return s;
  } catch (const std::bad_alloc&) {
    return Status::error(src.what + ": not enough memory to import it (" + std::to_string(size) + " bytes)");
  }
}

}  // namespace
}  // namespace detail

Status load_gltf_from_memory(const std::string& name, const std::string& extension, const uint8_t* data, size_t size,
                             const std::filesystem::path& base_dir, MeshData& out) {
  detail::GltfSource src;
  src.what = name;
  std::error_code ec;
  if (!base_dir.empty()) src.base_dir = std::filesystem::absolute(base_dir, ec).lexically_normal().string();
  while (src.base_dir.size() > 1 && src.base_dir.back() == '/') src.base_dir.pop_back();
  src.file_bytes = size;
  return detail::load_gltf_bytes(src, extension, data, size, out);
}

std::vector<std::filesystem::path> gltf_external_files(const std::filesystem::path& path) {
  std::vector<uint8_t> bytes;
  if (!detail::read_mesh_file(path, bytes)) return {};
  size_t begin = 0, size = bytes.size();
  if (size >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0) {
    if (!detail::check_glb_container(path.string(), bytes.data(), size)) return {};
    begin = 20;
    size = detail::read_u32(bytes.data() + 12);
  }
  const auto j = nlohmann::json::parse(bytes.begin() + std::ptrdiff_t(begin), bytes.begin() + std::ptrdiff_t(begin + size),
                                       nullptr, /*allow_exceptions=*/false);
  if (!j.is_object()) return {};
  const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  std::vector<std::filesystem::path> out;
  for (const char* list : {"buffers", "images"}) {
    const auto it = j.find(list);
    if (it == j.end() || !it->is_array()) continue;
    for (const auto& item : *it) {
      if (!item.is_object() || !item.contains("uri") || !item["uri"].is_string()) continue;
      const std::string uri = item["uri"].get<std::string>();
      if (uri.rfind("data:", 0) != 0) out.push_back(dir / detail::decode_uri(uri));
    }
  }
  return out;
}

Status load_gltf(const std::filesystem::path& path, MeshData& out) {
  detail::FileBytes bytes;
  if (Status s = detail::read_file_bytes(path, bytes); !s) return s;
  const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  return load_gltf_from_memory(path.string(), path.extension().string(), bytes.data.get(), bytes.size, dir, out);
}

}  // namespace lod
