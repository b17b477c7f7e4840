// glTF 2.0 export (Khronos glTF 2.0 specification, 4.4 "GLB File Format Specification"):
//   check_mesh -> load_images -> pack_buffer (views and accessors laid out, one primitive per
//   submesh) -> describe (JSON, materials) -> write_glb or write_gltf_and_bin (+ images),
//   each through a temporary file renamed into place.
#include "preprocess/gltf_write.h"

#include "preprocess/tangents.h"
#include "preprocess/texture_uri.h"
#include "runtime/regular_file.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>  // writes only
#include <limits>
#include <nlohmann/json.hpp>
#include <vector>

namespace lod {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr int kFloat = 5126, kUShort = 5123, kUInt = 5125;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

Status check_mesh(const std::string& what, const GltfMeshView& m) {
  if (m.index_count == 0 || m.index_count % 3 != 0)
    return Status::error(what + ": index count " + std::to_string(m.index_count) + " is not a positive multiple of 3");
  if (m.vertex_count == 0 || m.vertex_count > std::numeric_limits<uint32_t>::max())
    return Status::error(what + ": " + std::to_string(m.vertex_count) + " vertices");
  for (size_t i = 0; i < m.index_count; ++i)
    if (m.indices[i] >= m.vertex_count)
      return Status::error(what + ": triangle " + std::to_string(i / 3) + " references vertex " +
                           std::to_string(m.indices[i]) + " of " + std::to_string(m.vertex_count));
  for (size_t i = 0; i < 3 * m.vertex_count; ++i)
    if (!std::isfinite(m.positions[i]))
      return Status::error(what + ": vertex " + std::to_string(i / 3) + " has a non-finite position");
  size_t covered = 0;
  for (size_t i = 0; i < m.submeshes.size(); ++i) {
    const GltfSubmeshView& s = m.submeshes[i];
    const std::string at = what + ": submesh " + std::to_string(i);
    if (s.first_index != covered || s.index_count == 0 || s.index_count % 3 != 0 || s.index_count > m.index_count - covered)
      return Status::error(at + " [" + std::to_string(s.first_index) + ", +" + std::to_string(s.index_count) +
                           ") does not continue the runs before it (at " + std::to_string(covered) + " of " +
                           std::to_string(m.index_count) + ") with whole triangles");
    if (s.material < -1 || (s.material >= 0 && size_t(s.material) >= m.materials.size()))
      return Status::error(at + " names material " + std::to_string(s.material) + " of " + std::to_string(m.materials.size()));
    covered += s.index_count;
  }
  if (!m.submeshes.empty() && covered != m.index_count)
    return Status::error(what + ": submeshes cover " + std::to_string(covered) + " of " + std::to_string(m.index_count) +
                         " indices");
  for (size_t i = 0; i < m.materials.size(); ++i) {
    const GltfMaterialView& mat = m.materials[i];
    bool ok = std::isfinite(mat.metallic) && std::isfinite(mat.roughness) && std::isfinite(mat.alpha_cutoff) &&
              std::isfinite(mat.normal_scale) && std::isfinite(mat.occlusion_strength);
    for (float c : mat.emissive) ok = ok && std::isfinite(c);
    for (float c : mat.base_color) ok = ok && std::isfinite(c);
    if (!ok) return Status::error(what + ": material " + std::to_string(i) + " has a non-finite factor");
  }
  return Status::success();
}

// An image to embed or copy: its bytes and MIME type.
struct Image {
  std::filesystem::path file;
  const EmbeddedImage* embedded = nullptr;  // where the bytes came from when not a file
  std::vector<uint8_t> bytes;
  const char* mime = nullptr;
  const char* extension = nullptr;
};

// The image's bytes when it is a PNG or JPEG (by its signature), else a reason.
std::string read_image(const fs::path& file, Image& out) {
  std::error_code ec;
  if (!fs::exists(file, ec)) return "not found";
  // A regular file of at most 256 MiB (kTextureFileLimit); the reason without the path.
  if (Status s = read_regular_file(file, kTextureFileLimit, out.bytes); !s)
    return s.message.rfind(file.string() + ": ", 0) == 0 ? s.message.substr(file.string().size() + 2) : s.message;
  const size_t size = out.bytes.size();
  static const uint8_t png[8] = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
  if (size >= 8 && std::memcmp(out.bytes.data(), png, 8) == 0) {
    out.mime = "image/png", out.extension = ".png";
  } else if (size >= 3 && out.bytes[0] == 0xff && out.bytes[1] == 0xd8 && out.bytes[2] == 0xff) {
    out.mime = "image/jpeg", out.extension = ".jpg";
  } else {
    return "neither PNG nor JPEG (glTF 2.0 core allows no other image)";
  }
  return {};
}

// An image the chain carries (embedded in its source): its bytes when PNG or JPEG, else a reason.
std::string copy_image(const EmbeddedImage& embedded, Image& out) {
  const ImageType type = image_type_of(embedded.bytes);
  if (type == ImageType::unknown) return "neither PNG nor JPEG (glTF 2.0 core allows no other image)";
  if (embedded.bytes.size() > kTextureFileLimit.max_bytes) return "larger than 256 MiB";
  out.bytes = embedded.bytes;
  out.mime = mime_type(type), out.extension = file_extension(type);
  return {};
}

// Images of the materials, one per distinct file or embedded image; image_of[material][slot] indexes `images`
// (-1 = none).
using SlotImages = std::array<int, kTextureSlots>;
// Slots by name, in kTextureSlots order (runtime/chain_material.h).
constexpr size_t kBaseColorSlot = 0, kMetallicRoughnessSlot = 1, kNormalSlot = 2, kOcclusionSlot = 3, kEmissiveSlot = 4;
void load_images(const std::string& what, const GltfMeshView& m, std::vector<Image>& images,
                 std::vector<SlotImages>& image_of) {
  SlotImages none;
  none.fill(-1);
  image_of.assign(m.materials.size(), none);
  // Where each of `images` came from: a file, or bytes in memory (then the pointer is set).
  std::vector<std::pair<fs::path, const EmbeddedImage*>> sources;
  for (size_t i = 0; i < m.materials.size(); ++i) {
    const auto slots = image_slots(m.materials[i]);
    for (size_t k = 0; k < kTextureSlots; ++k) {
      const EmbeddedImage* embedded = m.materials[i].embedded_images[k];
      const fs::path file = embedded ? fs::path() : *slots[k];
      if (file.empty() && !embedded) continue;
      auto note = [&](const std::string& why) {
        if (m.notes)
          m.notes->push_back(what + ": material " + std::to_string(i) + ": " + kTextureSlotNames[k] + " texture " +
                             (embedded ? std::string("(embedded image)") : file.string()) + " " + why +
                             "; written without it");
      };
      const uint8_t set = m.materials[i].tex_coords[k];
      if (!(set == 0 ? m.uvs : set == 1 ? m.uvs1 : nullptr)) {
        note("needs texture coordinates " + std::string(set == 0 ? "TEXCOORD_0" : "TEXCOORD_" + std::to_string(set)) +
             ", and the mesh has none");
        continue;
      }
      const auto known = std::find(sources.begin(), sources.end(), std::pair(file, embedded));
      if (known != sources.end()) {
        image_of[i][k] = int(known - sources.begin());
        continue;
      }
      Image img;
      if (const std::string why = embedded ? copy_image(*embedded, img) : read_image(file, img); !why.empty()) {
        note("is " + why);
        continue;
      }
      img.file = file;
      img.embedded = embedded;
      image_of[i][k] = int(images.size());
      sources.emplace_back(file, embedded);
      images.push_back(std::move(img));
    }
  }
}

// The binary buffer and the JSON objects describing it, built together.
struct Packed {
  std::vector<uint8_t> bin;
  json views = json::array();
  json accessors = json::array();

  // Appends a tightly packed view (4-byte aligned) and one accessor over it; returns the accessor.
  int add(const void* data, size_t bytes, int target, int component_type, size_t count, const char* type) {
    while (bin.size() % 4) bin.push_back(0);
    views.push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes}, {"target", target}});
    const auto* b = static_cast<const uint8_t*>(data);
    bin.insert(bin.end(), b, b + bytes);
    accessors.push_back(
        {{"bufferView", views.size() - 1}, {"componentType", component_type}, {"count", count}, {"type", type}});
    return int(accessors.size()) - 1;
  }
};

// Unit normals (the validator requires them): a zero or non-finite one becomes +z.
std::vector<float> unit_normals(const float* n, size_t count) {
  std::vector<float> out(3 * count);
  for (size_t v = 0; v < count; ++v) {
    const double x = n[3 * v], y = n[3 * v + 1], z = n[3 * v + 2];
    const double len = std::sqrt(x * x + y * y + z * z);
    const bool ok = std::isfinite(len) && len > 1e-12;
    out[3 * v] = ok ? float(x / len) : 0.0f;
    out[3 * v + 1] = ok ? float(y / len) : 0.0f;
    out[3 * v + 2] = ok ? float(z / len) : 1.0f;
  }
  return out;
}

// The uv set a material's normal texture reads, or -1 without one.
int normal_uv_set(const GltfMeshView& m, const std::vector<SlotImages>& image_of, int32_t material) {
  if (material < 0 || image_of[size_t(material)][kNormalSlot] < 0) return -1;
  return m.materials[size_t(material)].tex_coords[kNormalSlot];
}

// Tangents are written when a primitive's material has a normal texture (and there are normals
// and uvs), and referenced by those primitives only (elsewhere they would go unused). They
// follow one uv set (`set`: that of the first such primitive's normal texture); a primitive
// whose normal texture reads the other gets none (a viewer generates them).
bool wants_tangents(const GltfMeshView& m, const std::vector<SlotImages>& image_of, int32_t material, int set) {
  return m.normals && set >= 0 && normal_uv_set(m, image_of, material) == set;
}

json pack_buffer(const GltfMeshView& m, const std::vector<SlotImages>& image_of, Packed& p, json& primitives) {
  static_assert(std::endian::native == std::endian::little, "glTF buffers are little-endian");
  json attributes;
  const int pos = p.add(m.positions, 12 * m.vertex_count, kArrayBuffer, kFloat, m.vertex_count, "VEC3");
  float lo[3], hi[3];
  for (int c = 0; c < 3; ++c) lo[c] = hi[c] = m.positions[c];
  for (size_t v = 1; v < m.vertex_count; ++v)
    for (int c = 0; c < 3; ++c) {
      lo[c] = std::min(lo[c], m.positions[3 * v + size_t(c)]);
      hi[c] = std::max(hi[c], m.positions[3 * v + size_t(c)]);
    }
  p.accessors[size_t(pos)]["min"] = {lo[0], lo[1], lo[2]};
  p.accessors[size_t(pos)]["max"] = {hi[0], hi[1], hi[2]};
  attributes["POSITION"] = pos;
  if (m.normals) {
    const std::vector<float> n = unit_normals(m.normals, m.vertex_count);
    attributes["NORMAL"] = p.add(n.data(), 4 * n.size(), kArrayBuffer, kFloat, m.vertex_count, "VEC3");
  }
  if (m.uvs) attributes["TEXCOORD_0"] = p.add(m.uvs, 8 * m.vertex_count, kArrayBuffer, kFloat, m.vertex_count, "VEC2");
  if (m.uvs1) attributes["TEXCOORD_1"] = p.add(m.uvs1, 8 * m.vertex_count, kArrayBuffer, kFloat, m.vertex_count, "VEC2");
  if (m.colors) {
    std::vector<float> c(m.colors, m.colors + 4 * m.vertex_count);  // the spec keeps float colours in [0, 1]
    for (float& x : c) x = std::isfinite(x) ? std::clamp(x, 0.0f, 1.0f) : 1.0f;
    attributes["COLOR_0"] = p.add(c.data(), 4 * c.size(), kArrayBuffer, kFloat, m.vertex_count, "VEC4");
  }
  std::vector<GltfSubmeshView> runs = m.submeshes;
  if (runs.empty()) runs.push_back({0, m.index_count, -1});
  int tangent_set = -1;
  for (const GltfSubmeshView& r : runs)
    if (tangent_set < 0) tangent_set = normal_uv_set(m, image_of, r.material);
  if (std::any_of(runs.begin(), runs.end(),
                  [&](const GltfSubmeshView& r) { return wants_tangents(m, image_of, r.material, tangent_set); })) {
    std::vector<float> t(4 * m.vertex_count);
    compute_tangents(t.data(), m.positions, m.normals, tangent_set == 1 ? m.uvs1 : m.uvs, m.vertex_count, m.indices,
                     m.index_count);
    attributes["TANGENT"] = p.add(t.data(), 4 * t.size(), kArrayBuffer, kFloat, m.vertex_count, "VEC4");
  }
  primitives = json::array();
  for (const GltfSubmeshView& run : runs) {
    const uint32_t* first = m.indices + run.first_index;
    int indices;
    if (m.vertex_count <= 65535) {  // 65535 itself is the primitive-restart value, never a vertex
      std::vector<uint16_t> small(first, first + run.index_count);
      indices = p.add(small.data(), 2 * small.size(), kElementArrayBuffer, kUShort, run.index_count, "SCALAR");
    } else {
      indices = p.add(first, 4 * run.index_count, kElementArrayBuffer, kUInt, run.index_count, "SCALAR");
    }
    json prim = {{"attributes", attributes}, {"indices", indices}, {"mode", 4}};
    if (!wants_tangents(m, image_of, run.material, tangent_set)) prim["attributes"].erase("TANGENT");
    if (run.material >= 0) prim["material"] = run.material;
    primitives.push_back(std::move(prim));
  }
  while (p.bin.size() % 4) p.bin.push_back(0);
  return primitives;
}

// Embedded images (GLB): a buffer view each, without a target; or, where `image_uri` names one,
// a reference to the caller's copy.
void pack_images(const std::vector<Image>& images, const GltfMeshView& m, Packed& p, json& out) {
  out = json::array();
  for (const Image& img : images) {
    if (const std::string uri = m.image_uri ? m.image_uri(img.file, img.embedded) : std::string(); !uri.empty()) {
      out.push_back({{"uri", uri}, {"mimeType", img.mime}});
      continue;
    }
    while (p.bin.size() % 4) p.bin.push_back(0);
    p.views.push_back({{"buffer", 0}, {"byteOffset", p.bin.size()}, {"byteLength", img.bytes.size()}});
    p.bin.insert(p.bin.end(), img.bytes.begin(), img.bytes.end());
    out.push_back({{"bufferView", p.views.size() - 1}, {"mimeType", img.mime}});
  }
  while (p.bin.size() % 4) p.bin.push_back(0);
}

const char* alpha_mode_name(AlphaMode a) {
  switch (a) {
    case AlphaMode::mask: return "MASK";
    case AlphaMode::blend: return "BLEND";
    case AlphaMode::opaque: break;
  }
  return "OPAQUE";
}

float unit(float x) { return std::clamp(x, 0.0f, 1.0f); }

// Materials, and the textures (one per image) they use.
void describe_materials(const GltfMeshView& m, const std::vector<SlotImages>& image_of, json& j) {
  if (m.materials.empty()) return;
  json materials = json::array(), textures = json::array();
  auto texture = [&](int image) {
    const json t = {{"sampler", 0}, {"source", image}};
    const auto known = std::find(textures.begin(), textures.end(), t);
    if (known != textures.end()) return size_t(known - textures.begin());
    textures.push_back(t);
    return textures.size() - 1;
  };
  for (size_t i = 0; i < m.materials.size(); ++i) {
    const GltfMaterialView& src = m.materials[i];
    const SlotImages& img = image_of[i];
    json pbr = {{"baseColorFactor", {unit(src.base_color[0]), unit(src.base_color[1]), unit(src.base_color[2]),
                                     unit(src.base_color[3])}},
                {"metallicFactor", unit(src.metallic)},
                {"roughnessFactor", unit(src.roughness)}};
    // textureInfo: the texture, and the uv set it reads when that is not TEXCOORD_0.
    auto info = [&](size_t slot) {
      json t = {{"index", texture(img[slot])}};
      if (src.tex_coords[slot] != 0) t["texCoord"] = src.tex_coords[slot];
      return t;
    };
    if (img[kBaseColorSlot] >= 0) pbr["baseColorTexture"] = info(kBaseColorSlot);
    if (img[kMetallicRoughnessSlot] >= 0) pbr["metallicRoughnessTexture"] = info(kMetallicRoughnessSlot);
    json mat = {{"pbrMetallicRoughness", pbr}, {"alphaMode", alpha_mode_name(src.alpha_mode)},
                {"doubleSided", src.double_sided}};
    if (img[kNormalSlot] >= 0) {
      mat["normalTexture"] = info(kNormalSlot);
      mat["normalTexture"]["scale"] = std::max(0.0f, src.normal_scale);
    }
    if (img[kOcclusionSlot] >= 0) {
      mat["occlusionTexture"] = info(kOcclusionSlot);
      mat["occlusionTexture"]["strength"] = unit(src.occlusion_strength);
    }
    if (img[kEmissiveSlot] >= 0) mat["emissiveTexture"] = info(kEmissiveSlot);
    // The factor alone emits too (glTF: emitted = factor x texture, the texture 1 when absent).
    if (src.emissive[0] > 0 || src.emissive[1] > 0 || src.emissive[2] > 0)
      mat["emissiveFactor"] = {unit(src.emissive[0]), unit(src.emissive[1]), unit(src.emissive[2])};
    if (!src.name.empty()) mat["name"] = src.name;
    if (src.alpha_mode == AlphaMode::mask) mat["alphaCutoff"] = std::max(0.0f, src.alpha_cutoff);
    materials.push_back(std::move(mat));
  }
  j["materials"] = std::move(materials);
  if (!textures.empty()) {
    j["textures"] = std::move(textures);
    // Repeat wrapping, trilinear filtering: what the bake's uvs were made for.
    j["samplers"] = json::array({{{"magFilter", 9729}, {"minFilter", 9987}, {"wrapS", 10497}, {"wrapT", 10497}}});
  }
}

json describe(const GltfMeshView& m, const Packed& p, const json& primitives, const std::string& bin_uri) {
  json buffer = {{"byteLength", p.bin.size()}};
  if (!bin_uri.empty()) buffer["uri"] = bin_uri;
  json j = {{"asset", {{"version", "2.0"}, {"generator", "lodkit"}}},
            {"scene", 0},
            {"scenes", json::array({{{"nodes", {0}}}})},
            {"nodes", json::array({{{"mesh", 0}, {"name", m.name}}})},
            {"meshes", json::array({{{"name", m.name}, {"primitives", primitives}}})},
            {"buffers", json::array({buffer})},
            {"bufferViews", p.views},
            {"accessors", p.accessors}};
  return j;
}

// Percent-encodes everything but RFC 3986 unreserved characters (file names become URIs).
std::string uri_of(const std::string& name) {
  static const char* hex = "0123456789ABCDEF";
  std::string s;
  for (unsigned char c : name) {
    if (std::isalnum(c) || c == '-' || c == '.' || c == '_' || c == '~') {
      s += char(c);
    } else {
      s += '%';
      s += hex[c >> 4];
      s += hex[c & 15];
    }
  }
  return s;
}

// Writes bytes to path through path.tmp, renamed over it only when complete.
Status write_atomically(const fs::path& path, const std::vector<uint8_t>& bytes) {
  const std::string what = path.string();
  fs::path tmp = path;
  tmp += ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) return Status::error(what + ": cannot be opened for writing");
    f.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    f.flush();
    if (!f) {
      std::error_code ec;
      fs::remove(tmp, ec);
      return Status::error(what + ": write failed (disk full?)");
    }
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    return Status::error(what + ": cannot be renamed into place (" + ec.message() + ")");
  }
  return Status::success();
}

void put_u32(std::vector<uint8_t>& out, uint32_t v) {
  uint8_t b[4];
  std::memcpy(b, &v, 4);
  out.insert(out.end(), b, b + 4);
}

// 12-byte header, JSON chunk padded with spaces, BIN chunk padded with zeros (spec 4.4.3).
std::vector<uint8_t> glb_bytes(const json& j, const std::vector<uint8_t>& bin) {
  std::string text = j.dump(-1, ' ', false, json::error_handler_t::replace);
  while (text.size() % 4) text += ' ';
  std::vector<uint8_t> out;
  out.reserve(28 + text.size() + bin.size());
  out.insert(out.end(), {'g', 'l', 'T', 'F'});
  put_u32(out, 2);
  put_u32(out, uint32_t(12 + 8 + text.size() + 8 + bin.size()));
  put_u32(out, uint32_t(text.size()));
  put_u32(out, 0x4E4F534Au);  // "JSON"
  out.insert(out.end(), text.begin(), text.end());
  put_u32(out, uint32_t(bin.size()));
  put_u32(out, 0x004E4942u);  // "BIN\0"
  out.insert(out.end(), bin.begin(), bin.end());
  return out;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

Status save_gltf(const std::filesystem::path& path, const GltfMeshView& mesh) {
  const std::string what = path.string();
  const std::string ext = lower(path.extension().string());
  if (ext != ".glb" && ext != ".gltf")
    return Status::error(what + ": glTF export needs a .glb or .gltf name, not '" + path.extension().string() + "'");
  if (Status s = check_mesh(what, mesh); !s) return s;
  std::vector<Image> images;
  std::vector<SlotImages> image_of;
  load_images(what, mesh, images, image_of);
  Packed packed;
  json primitives, image_list = json::array();
  pack_buffer(mesh, image_of, packed, primitives);
  if (ext == ".glb") pack_images(images, mesh, packed, image_list);
  if (uint64_t(packed.bin.size()) + (uint64_t(1) << 20) > std::numeric_limits<uint32_t>::max())
    return Status::error(what + ": " + std::to_string(packed.bin.size()) + " bytes of buffer exceed what GLB holds (4 GiB)");
  if (ext == ".glb") {
    json j = describe(mesh, packed, primitives, "");
    describe_materials(mesh, image_of, j);
    if (!images.empty()) j["images"] = image_list;
    return write_atomically(path, glb_bytes(j, packed.bin));
  }
  const std::string bin_name = path.stem().string() + ".bin";
  if (Status s = write_atomically(path.parent_path() / bin_name, packed.bin); !s) return s;
  for (size_t k = 0; k < images.size(); ++k) {
    const std::string name = path.stem().string() + "-image" + std::to_string(k) + images[k].extension;
    if (Status s = write_atomically(path.parent_path() / name, images[k].bytes); !s) return s;
    image_list.push_back({{"uri", uri_of(name)}});
  }
  json j = describe(mesh, packed, primitives, uri_of(bin_name));
  describe_materials(mesh, image_of, j);
  if (!images.empty()) j["images"] = image_list;
  const std::string text = j.dump(1, ' ', false, json::error_handler_t::replace);
  return write_atomically(path, std::vector<uint8_t>(text.begin(), text.end()));
}

GltfMaterialView gltf_material_view(const ChainMaterial& m, const std::vector<EmbeddedImage>& images,
                                    const std::string& texture_base) {
  GltfMaterialView g;
  g.name = m.name;
  std::copy(m.base_color, m.base_color + 4, g.base_color);
  g.metallic = m.metallic;
  g.roughness = m.roughness;
  g.alpha_mode = m.alpha_mode;
  g.alpha_cutoff = m.alpha_cutoff;
  g.double_sided = m.double_sided;
  g.normal_scale = m.normal_scale;
  g.occlusion_strength = m.occlusion_strength;
  std::copy(m.emissive, m.emissive + 3, g.emissive);
  g.tex_coords = m.tex_coords;
  const auto uris = texture_slots(m);
  const auto files = image_slots(g);
  for (size_t s = 0; s < kTextureSlots; ++s) {
    uint32_t image = 0;
    if (is_embedded_image_uri(*uris[s], &image))
      g.embedded_images[s] = image < images.size() ? &images[image] : nullptr;
    else *files[s] = texture_file(texture_base, *uris[s]);
  }
  return g;
}

}  // namespace lod
