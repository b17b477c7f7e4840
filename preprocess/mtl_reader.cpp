// Wavefront MTL reader: the statements that map onto glTF's metallic-roughness material.
//   newmtl NAME            starts a material
//   Kd r g b               base colour factor (clamped to [0, 1] by the bake)
//   d a / Tr t             alpha (Tr is 1 - d); below 1 the material blends
//   map_Kd [opts] FILE     base colour texture (options and their values skipped; the rest
//                          of the line is the file)
//   Ke r g b               emissive factor (clamped to [0, 1] by the bake)
//   map_Ke [opts] FILE     emissive texture (before any non-zero Ke, the factor becomes 1 1 1:
//                          glTF multiplies the texture by it)
//   map_Bump / bump / norm [-bm s] [opts] FILE
//                          normal texture (read as a tangent-space normal map, as glTF's
//                          normalTexture; -bm gives its scale). A height-field bump map is
//                          not converted: it is taken as a normal map.
//   Pm m / Pr r            metallic / roughness factor (the PBR extension's statements)
//   map_Pm [-imfchan b] FILE and map_Pr [-imfchan g] FILE
//                          naming one image: glTF's metallic-roughness texture (metalness in B,
//                          roughness in G; lodkit's OBJ export writes them so). Separate images
//                          or other channels cannot be one glTF texture: not imported, said.
// Ns, Ka, Ks, illum and the other maps have no place in the levels' material: each keyword is
// named once in the warnings. Errors name the file and line.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <set>
#include <utility>
#include <vector>

#include "preprocess/mesh_readers.h"
#include "preprocess/texture_uri.h"

namespace lod::detail {
namespace {

bool blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

std::string_view next_token(std::string_view line, size_t& at) {
  while (at < line.size() && blank(line[at])) ++at;
  size_t e = at;
  while (e < line.size() && !blank(line[e])) ++e;
  const std::string_view t = line.substr(at, e - at);
  at = e;
  return t;
}

// The file a map statement names, after its options ("-s 1 1 1", "-clamp on", ...), each with
// its values; the rest of the line is the file (names may hold spaces). The value of "-bm"
// (bump multiplier) goes to `bm` when it is a number, the letter after "-imfchan" to `channel`.
std::string_view map_file(std::string_view line, size_t& at, std::string& number, float& bm, std::string& channel) {
  for (;;) {
    size_t before = at;
    const std::string_view t = next_token(line, at);
    if (t.empty()) return {};
    if (t[0] != '-' || t.size() < 2 || std::isdigit(uint8_t(t[1])) || t[1] == '.') {
      while (before < line.size() && blank(line[before])) ++before;
      std::string_view file = line.substr(before);
      while (!file.empty() && blank(file.back())) file.remove_suffix(1);
      return file;
    }
    if (t == "-imfchan") {
      channel = std::string(next_token(line, at));
      continue;
    }
    for (size_t peek = at, values = 0;; ++values) {  // the option's values: numbers, on / off
      const std::string_view v = next_token(line, peek);
      char* stop = nullptr;
      number.assign(v.substr(0, 64));
      const double d = v.empty() ? 0 : std::strtod(number.c_str(), &stop);
      const bool numeric = !v.empty() && stop != number.c_str();
      if (!(numeric || v == "on" || v == "off")) break;
      if (numeric && values == 0 && t == "-bm") bm = float(d);
      at = peek;
    }
  }
}

}  // namespace

Status read_mtl(const std::string& what, const uint8_t* data, size_t size, const std::string& prefix,
                std::vector<MeshMaterial>& materials, std::vector<std::string>& names, std::vector<std::string>& warnings) {
  const char* text = reinterpret_cast<const char*>(data);
  if (size >= 3 && data[0] == 0xEF && data[1] == 0xBB && data[2] == 0xBF) text += 3, size -= 3;
  std::set<std::string> skipped;
  MeshMaterial* current = nullptr;
  // map_Pm / map_Pr per material of this file: {uri, channel}, joined at the end.
  struct PbrMaps {
    std::string metallic, metallic_channel, roughness, roughness_channel;
    size_t line = 0;
  };
  std::vector<std::pair<size_t, PbrMaps>> pbr_maps;
  size_t pos = 0, line_no = 0;
  std::string number;
  while (pos < size) {
    ++line_no;
    const void* nl = std::memchr(text + pos, '\n', size - pos);
    const size_t end = nl ? size_t(static_cast<const char*>(nl) - text) : size;
    const std::string_view line(text + pos, end - pos);
    pos = nl ? end + 1 : size;
    size_t at = 0;
    const std::string_view key = next_token(line, at);
    if (key.empty() || key[0] == '#') continue;
    const std::string here = what + ":" + std::to_string(line_no);
    auto numbers = [&](float* out, int count, int needed) -> Status {
      for (int i = 0; i < count; ++i) {
        number.assign(next_token(line, at).substr(0, 64));
        if (number.empty() && i >= needed) {
          out[i] = out[i - 1];  // "Kd 0.5" is grey
          continue;
        }
        char* stop = nullptr;
        const double v = number.empty() ? 0 : std::strtod(number.c_str(), &stop);
        if (number.empty() || stop == number.c_str() || !std::isfinite(float(v)))
          return Status::error(here + ": '" + std::string(key) + "' needs " + std::to_string(needed) + " finite numbers");
        out[i] = float(v);
      }
      return Status::success();
    };
    if (key == "newmtl") {
      const std::string name(next_token(line, at));
      if (name.empty()) return Status::error(here + ": newmtl without a name");
      if (materials.size() >= kMaxMaterials)
        return Status::error(here + ": more than " + std::to_string(kMaxMaterials) + " materials");
      materials.emplace_back();
      names.push_back(name);
      current = &materials.back();
      current->name = name;
      current->metallic = 0;  // OBJ's materials are dielectric
      continue;
    }
    if (!current) {
      skipped.insert(std::string(key) + " (before any newmtl)");
      continue;
    }
    if (key == "Kd") {
      if (Status s = numbers(current->base_color, 3, 1); !s) return s;
    } else if (key == "d" || key == "Tr") {
      float a = 1;
      if (Status s = numbers(&a, 1, 1); !s) return s;
      current->base_color[3] = key == "d" ? a : 1 - a;
      if (current->base_color[3] < 1) current->alpha_mode = AlphaMode::blend;
    } else if (key == "Ke") {
      if (Status s = numbers(current->emissive, 3, 1); !s) return s;
    } else if (key == "Pm") {
      if (Status s = numbers(&current->metallic, 1, 1); !s) return s;
    } else if (key == "Pr") {
      if (Status s = numbers(&current->roughness, 1, 1); !s) return s;
    } else if (key == "map_Pm" || key == "map_Pr") {
      float bm = 1;
      std::string channel;
      const std::string_view file = map_file(line, at, number, bm, channel);
      if (file.empty()) return Status::error(here + ": " + std::string(key) + " without a file name");
      const size_t index = materials.size() - 1;
      if (pbr_maps.empty() || pbr_maps.back().first != index) pbr_maps.push_back({index, {}});
      PbrMaps& maps = pbr_maps.back().second;
      maps.line = line_no;
      (key == "map_Pm" ? maps.metallic : maps.roughness) = path_to_uri(prefix + std::string(file));
      (key == "map_Pm" ? maps.metallic_channel : maps.roughness_channel) = channel;
    } else if (key == "map_Kd" || key == "map_Ke" || key == "map_Bump" || key == "map_bump" || key == "bump" ||
               key == "norm") {
      float bm = 1;
      std::string channel;
      const std::string_view file = map_file(line, at, number, bm, channel);
      if (file.empty()) return Status::error(here + ": " + std::string(key) + " without a file name");
      const std::string uri = path_to_uri(prefix + std::string(file));
      if (key == "map_Kd") {
        current->base_color_texture = uri;
      } else if (key == "map_Ke") {
        current->emissive_texture = uri;
        // glTF multiplies the texture by the factor: without a Ke so far, the texture emits as is.
        if (current->emissive[0] == 0 && current->emissive[1] == 0 && current->emissive[2] == 0)
          std::fill(current->emissive, current->emissive + 3, 1.0f);
      } else {
        if (!std::isfinite(bm)) return Status::error(here + ": " + std::string(key) + " -bm needs a finite number");
        current->normal_texture = uri;
        current->normal_scale = bm;
      }
    } else {
      skipped.insert(std::string(key));
    }
  }
  for (const auto& [index, maps] : pbr_maps) {
    const bool packed = maps.metallic == maps.roughness && (maps.metallic_channel.empty() || maps.metallic_channel == "b") &&
                        (maps.roughness_channel.empty() || maps.roughness_channel == "g");
    if (packed) {
      materials[index].metallic_roughness_texture = maps.metallic;
      continue;
    }
    warnings.push_back(what + ":" + std::to_string(maps.line) + ": material '" + names[index] +
                       "': map_Pm and map_Pr not imported: glTF's metallic-roughness texture is one image with "
                       "metalness in B and roughness in G (map_Pm -imfchan b and map_Pr -imfchan g naming it)");
  }
  if (!skipped.empty()) {
    std::string list;
    for (const std::string& k : skipped) list += (list.empty() ? "" : ", ") + k;
    warnings.push_back(what + ": not imported (no place in the levels' material): " + list);
  }
  return Status::success();
}

}  // namespace lod::detail
