// A GLB whose texture is inside it, built by hand (not by lodkit's exporter), for the tests of
// every path that must keep an embedded image: the .lod bake, the HLOD bake (local and
// distributed), the 3D Tiles export.
#pragma once
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <vector>

#include "gltf_fixture.h"
#include "textured_fixture.h"

namespace lod::test {

// two_material_sphere(rings, segments) as glTF: one primitive per material, material 0 ('cap')
// with base colour texture 0 whose image is `image` (a JSON image object: a buffer view, made
// from `image_in_buffer` when given, or a data URI), material 1 ('base') plain and double-sided.
inline GltfFixture embedded_texture_sphere(nlohmann::json image, const std::vector<uint8_t>* image_in_buffer,
                                           int rings = 16, int segments = 32) {
  const MeshData m = two_material_sphere(rings, segments);
  GltfFixture f;
  const int pos = f.add_accessor(f.add_view(m.positions), kFloat, m.vertex_count(), "VEC3");
  const int uv = f.add_accessor(f.add_view(m.uvs), kFloat, m.vertex_count(), "VEC2");
  std::vector<nlohmann::json> primitives;
  for (const Submesh& s : m.submeshes) {
    const std::vector<uint32_t> part(m.indices.begin() + 3 * std::ptrdiff_t(s.first_triangle),
                                     m.indices.begin() + 3 * std::ptrdiff_t(s.first_triangle + s.triangle_count));
    const int ind = f.add_accessor(f.add_view(part), kUInt, part.size(), "SCALAR");
    primitives.push_back({{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv}}}, {"indices", ind}, {"material", s.material}});
  }
  f.add_mesh(primitives);
  f.set_scene({f.add_node({{"mesh", 0}})});
  if (image_in_buffer) image["bufferView"] = f.add_view(*image_in_buffer);
  f.j["images"] = nlohmann::json::array({image});
  f.j["textures"] = nlohmann::json::array({{{"source", 0}}});
  f.j["materials"] = nlohmann::json::array(
      {{{"name", "cap"}, {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"metallicFactor", 0.0}}}},
       {{"name", "base"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.8, 0.2, 0.1, 1.0}}}}, {"doubleSided", true}}});
  return f;
}

}  // namespace lod::test
