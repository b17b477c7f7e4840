// glTF 2.0 export (Khronos glTF 2.0 specification, 4.4 "GLB File Format Specification"):
//   check_mesh -> pack_buffer (views and accessors laid out) -> describe (JSON) -> write_glb
//   or write_gltf_and_bin, each through a temporary file renamed into place.
#include "preprocess/gltf_write.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
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
  return Status::success();
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

json pack_buffer(const GltfMeshView& m, Packed& p) {
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
  int indices;
  if (m.vertex_count <= 65535) {  // 65535 itself is the primitive-restart value, never a vertex
    std::vector<uint16_t> small(m.indices, m.indices + m.index_count);
    indices = p.add(small.data(), 2 * small.size(), kElementArrayBuffer, kUShort, m.index_count, "SCALAR");
  } else {
    indices = p.add(m.indices, 4 * m.index_count, kElementArrayBuffer, kUInt, m.index_count, "SCALAR");
  }
  while (p.bin.size() % 4) p.bin.push_back(0);
  return {{"attributes", attributes}, {"indices", indices}, {"mode", 4}};
}

json describe(const GltfMeshView& m, const Packed& p, const json& primitive, const std::string& bin_uri) {
  json buffer = {{"byteLength", p.bin.size()}};
  if (!bin_uri.empty()) buffer["uri"] = bin_uri;
  json j = {{"asset", {{"version", "2.0"}, {"generator", "lodkit"}}},
            {"scene", 0},
            {"scenes", json::array({{{"nodes", {0}}}})},
            {"nodes", json::array({{{"mesh", 0}, {"name", m.name}}})},
            {"meshes", json::array({{{"name", m.name}, {"primitives", json::array({primitive})}}})},
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
  Packed packed;
  const json primitive = pack_buffer(mesh, packed);
  if (uint64_t(packed.bin.size()) + (uint64_t(1) << 20) > std::numeric_limits<uint32_t>::max())
    return Status::error(what + ": " + std::to_string(packed.bin.size()) + " bytes of buffer exceed what GLB holds (4 GiB)");
  if (ext == ".glb") return write_atomically(path, glb_bytes(describe(mesh, packed, primitive, ""), packed.bin));
  const std::string bin_name = path.stem().string() + ".bin";
  if (Status s = write_atomically(path.parent_path() / bin_name, packed.bin); !s) return s;
  const std::string text = describe(mesh, packed, primitive, uri_of(bin_name)).dump(1, ' ', false, json::error_handler_t::replace);
  return write_atomically(path, std::vector<uint8_t>(text.begin(), text.end()));
}

}  // namespace lod
