// Small glTF 2.0 files built in code for the import tests: raw JSON (nlohmann) plus one
// binary buffer, written as GLB, as .gltf with a data-URI buffer, or as .gltf + .bin. Nothing
// is checked here, so the tests can also build files that break every rule.
#pragma once
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace lod::test {

inline constexpr int kByte = 5120, kUByte = 5121, kShort = 5122, kUShort = 5123, kUInt = 5125, kFloat = 5126;

class GltfFixture {
 public:
  nlohmann::json j = {{"asset", {{"version", "2.0"}}}};
  std::vector<uint8_t> bin;

  // Appends bytes (4-byte aligned) as a buffer view of buffer 0; returns its index.
  int add_view(const void* data, size_t size, size_t stride = 0) {
    while (bin.size() % 4) bin.push_back(0);
    nlohmann::json v = {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", size}};
    if (stride) v["byteStride"] = stride;
    const auto* b = static_cast<const uint8_t*>(data);
    bin.insert(bin.end(), b, b + size);
    j["bufferViews"].push_back(v);
    return int(j["bufferViews"].size()) - 1;
  }
  template <class T>
  int add_view(const std::vector<T>& values, size_t stride = 0) {
    return add_view(values.data(), values.size() * sizeof(T), stride);
  }
  int add_accessor(int view, int component_type, size_t count, const char* type, bool normalized = false,
                   size_t offset = 0) {
    nlohmann::json a = {{"bufferView", view}, {"componentType", component_type}, {"count", count}, {"type", type}};
    if (normalized) a["normalized"] = true;
    if (offset) a["byteOffset"] = offset;
    j["accessors"].push_back(a);
    return int(j["accessors"].size()) - 1;
  }
  // Float positions (and optional u32 indices) as one primitive of a new mesh; returns the mesh.
  int add_float_mesh(const std::vector<float>& positions, const std::vector<uint32_t>& indices = {}, int mode = 4) {
    const int pos = add_accessor(add_view(positions), kFloat, positions.size() / 3, "VEC3");
    nlohmann::json prim = {{"attributes", {{"POSITION", pos}}}, {"mode", mode}};
    if (!indices.empty()) prim["indices"] = add_accessor(add_view(indices), kUInt, indices.size(), "SCALAR");
    return add_mesh({prim});
  }
  int add_mesh(const std::vector<nlohmann::json>& primitives) {
    nlohmann::json mesh = nlohmann::json::object();
    mesh["primitives"] = nlohmann::json(primitives);  // an array even of one
    j["meshes"].push_back(mesh);
    return int(j["meshes"].size()) - 1;
  }
  int add_node(nlohmann::json node) {
    j["nodes"].push_back(std::move(node));
    return int(j["nodes"].size()) - 1;
  }
  // Scene 0 holds `roots` (every node without a parent, when empty).
  void set_scene(const std::vector<int>& roots) {
    j["scenes"] = nlohmann::json::array({{{"nodes", roots}}});
    j["scene"] = 0;
  }
  void finish_buffer(const std::string& uri = "") {
    while (bin.size() % 4) bin.push_back(0);
    nlohmann::json b = {{"byteLength", bin.size()}};
    if (!uri.empty()) b["uri"] = uri;
    j["buffers"] = nlohmann::json::array({b});
  }

  std::vector<uint8_t> glb() {
    finish_buffer();
    std::string json = j.dump();
    while (json.size() % 4) json += ' ';
    std::vector<uint8_t> out;
    auto u32 = [&out](uint32_t v) {
      uint8_t b[4];
      std::memcpy(b, &v, 4);
      out.insert(out.end(), b, b + 4);
    };
    out.insert(out.end(), {'g', 'l', 'T', 'F'});
    u32(2);
    u32(uint32_t(12 + 8 + json.size() + (bin.empty() ? 0 : 8 + bin.size())));
    u32(uint32_t(json.size()));
    u32(0x4E4F534A);
    out.insert(out.end(), json.begin(), json.end());
    if (!bin.empty()) {
      u32(uint32_t(bin.size()));
      u32(0x004E4942);
      out.insert(out.end(), bin.begin(), bin.end());
    }
    return out;
  }
  std::string gltf_data_uri() {
    finish_buffer("data:application/octet-stream;base64," + base64(bin));
    return j.dump(1);
  }
  // Writes dir/name.gltf and dir/name.bin; returns the .gltf path.
  std::filesystem::path write_gltf_with_bin(const std::filesystem::path& dir, const std::string& name) {
    finish_buffer(name + ".bin");
    const auto gltf = dir / (name + ".gltf");
    write(dir / (name + ".bin"), bin);
    const std::string text = j.dump(1);
    write(gltf, std::vector<uint8_t>(text.begin(), text.end()));
    return gltf;
  }

  static std::string base64(const std::vector<uint8_t>& b) {
    static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string s;
    for (size_t i = 0; i < b.size(); i += 3) {
      const uint32_t n = (uint32_t(b[i]) << 16) | (i + 1 < b.size() ? uint32_t(b[i + 1]) << 8 : 0) |
                         (i + 2 < b.size() ? uint32_t(b[i + 2]) : 0);
      s += k[(n >> 18) & 63];
      s += k[(n >> 12) & 63];
      s += i + 1 < b.size() ? k[(n >> 6) & 63] : '=';
      s += i + 2 < b.size() ? k[n & 63] : '=';
    }
    return s;
  }

 private:
  static void write(const std::filesystem::path& p, const std::vector<uint8_t>& bytes) {
    FILE* f = std::fopen(p.c_str(), "wb");
    if (!f) return;
    std::fwrite(bytes.data(), 1, bytes.size(), f);
    std::fclose(f);
  }
};

}  // namespace lod::test
