// Textured test fixtures made in code: a minimal PNG (stored deflate blocks, real CRC and
// Adler checksums, so decoders and the glTF validator accept it) and a latitude-longitude
// sphere with a uv seam whose northern and southern halves have two materials, written as
// .gltf with its texture next to it.
#pragma once
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "preprocess/gltf_write.h"
#include "preprocess/mesh.h"
#include "test_support.h"

namespace lod::test {

inline uint32_t png_crc(const uint8_t* p, size_t n, uint32_t c = 0xffffffffu) {
  for (size_t i = 0; i < n; ++i) {
    c ^= p[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1)));
  }
  return c;
}

// An RGB checkerboard of `cells` x `cells` squares, `size` pixels wide and high.
inline std::vector<uint8_t> checker_png(uint32_t size, uint32_t cells) {
  std::vector<uint8_t> raw;  // filter byte 0 + RGB per row
  for (uint32_t y = 0; y < size; ++y) {
    raw.push_back(0);
    for (uint32_t x = 0; x < size; ++x) {
      const bool dark = ((x * cells / size) + (y * cells / size)) % 2;
      raw.insert(raw.end(), {uint8_t(dark ? 40 : 230), uint8_t(dark ? 90 : 200), uint8_t(dark ? 160 : 60)});
    }
  }
  std::vector<uint8_t> z = {0x78, 0x01};  // zlib, stored blocks
  for (size_t at = 0; at < raw.size() || at == 0;) {
    const size_t n = std::min<size_t>(65535, raw.size() - at);
    const bool last = at + n == raw.size();
    z.insert(z.end(), {uint8_t(last), uint8_t(n), uint8_t(n >> 8), uint8_t(~n), uint8_t(~n >> 8)});
    z.insert(z.end(), raw.begin() + std::ptrdiff_t(at), raw.begin() + std::ptrdiff_t(at + n));
    at += n;
    if (last) break;
  }
  uint32_t a = 1, b = 0;
  for (uint8_t c : raw) a = (a + c) % 65521, b = (b + a) % 65521;
  const uint32_t adler = b << 16 | a;
  z.insert(z.end(), {uint8_t(adler >> 24), uint8_t(adler >> 16), uint8_t(adler >> 8), uint8_t(adler)});
  std::vector<uint8_t> out = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
  auto chunk = [&](const char* type, const std::vector<uint8_t>& data) {
    const uint32_t n = uint32_t(data.size());
    out.insert(out.end(), {uint8_t(n >> 24), uint8_t(n >> 16), uint8_t(n >> 8), uint8_t(n)});
    const size_t start = out.size();
    out.insert(out.end(), type, type + 4);
    out.insert(out.end(), data.begin(), data.end());
    const uint32_t crc = ~png_crc(out.data() + start, out.size() - start);
    out.insert(out.end(), {uint8_t(crc >> 24), uint8_t(crc >> 16), uint8_t(crc >> 8), uint8_t(crc)});
  };
  chunk("IHDR", {uint8_t(size >> 24), uint8_t(size >> 16), uint8_t(size >> 8), uint8_t(size), uint8_t(size >> 24),
                 uint8_t(size >> 16), uint8_t(size >> 8), uint8_t(size), 8, 2, 0, 0, 0});
  chunk("IDAT", z);
  chunk("IEND", {});
  return out;
}

// Latitude-longitude sphere: (rings + 1) x (segments + 1) vertices, u = longitude / 2 pi, the
// meridian u = 0 / 1 a seam (one position, two uvs); the poles are left open. Triangles of
// the northern rings (r < rings / 2) are material 0, the southern ones material 1: the
// equator ring is where they meet, shared by both.
inline MeshData two_material_sphere(int rings, int segments) {
  MeshData m;
  for (int r = 0; r <= rings; ++r) {
    const float theta = std::numbers::pi_v<float> * (0.02f + 0.96f * float(r) / float(rings));
    for (int s = 0; s <= segments; ++s) {
      const float phi = s == segments ? 0.f : 2 * std::numbers::pi_v<float> * float(s) / float(segments);
      m.positions.insert(m.positions.end(), {std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)});
      m.uvs.insert(m.uvs.end(), {float(s) / float(segments), float(r) / float(rings)});
    }
  }
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const uint32_t a = uint32_t(r * (segments + 1) + s), b = a + 1, c = a + uint32_t(segments + 1), d = c + 1;
      m.indices.insert(m.indices.end(), {a, c, b, b, c, d});
    }
  const uint32_t north = uint32_t(rings / 2 * segments * 2);
  m.submeshes = {{0, north, 0}, {north, uint32_t(m.triangle_count()) - north, 1}};
  MeshMaterial top, bottom;
  top.name = "cap";
  top.base_color_texture = "checker.png";
  top.metallic = 0;
  top.roughness = 0.5f;
  bottom.name = "base";
  bottom.base_color[0] = 0.8f, bottom.base_color[1] = 0.2f, bottom.base_color[2] = 0.1f;
  bottom.double_sided = true;
  m.materials = {top, bottom};
  return m;
}

// two_material_sphere winds its triangles inward (clockwise seen from outside). The bake does
// not care, but glTF's front faces are counter-clockwise, and a viewer culls the back faces of
// single-sided materials: pictures of it need the faces turned outward.
enum class SphereFaces { inward, outward };
inline void turn_faces_outward(MeshData& m) {
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3) std::swap(m.indices[t + 1], m.indices[t + 2]);
}

// The sphere as <dir>/<name>.gltf (+ .bin) with its texture as <name>-image0.png next to it
// (material 0's base colour texture, named by URI); returns the .gltf, empty on failure.
// With `every_texture`, material 0 also has metallic-roughness, normal (scale 0.625),
// occlusion (strength 0.375) and emissive textures (<name>-image1..4.png, each a different
// image) and emissive factor (0.5, 0.25, 0.125), and the sphere has normals. `faces`: the
// winding (SphereFaces above).
inline std::filesystem::path write_two_material_gltf(const std::filesystem::path& dir, const std::string& name,
                                                    int rings = 24, int segments = 48, bool every_texture = false,
                                                    SphereFaces faces = SphereFaces::inward) {
  MeshData m = two_material_sphere(rings, segments);
  if (faces == SphereFaces::outward) turn_faces_outward(m);
  std::filesystem::create_directories(dir);
  write_bytes(dir / "checker.png", checker_png(64, 8));
  GltfMeshView view;
  view.name = name;
  view.positions = m.positions.data();
  view.vertex_count = m.vertex_count();
  view.uvs = m.uvs.data();
  const std::vector<float> normals = m.positions;  // a unit sphere's normals are its positions
  if (every_texture) view.normals = normals.data();
  view.indices = m.indices.data();
  view.index_count = m.indices.size();
  for (const MeshMaterial& src : m.materials) {
    GltfMaterialView g;
    g.name = src.name;
    std::copy(src.base_color, src.base_color + 4, g.base_color);
    g.metallic = src.metallic;
    g.roughness = src.roughness;
    g.double_sided = src.double_sided;
    view.materials.push_back(g);
  }
  for (const Submesh& s : m.submeshes) view.submeshes.push_back({3 * size_t(s.first_triangle), 3 * size_t(s.triangle_count), s.material});
  const std::filesystem::path file = dir / (name + ".gltf");
  view.materials[0].base_color_image = dir / "checker.png";
  if (every_texture) {
    GltfMaterialView& g = view.materials[0];
    const char* files[] = {"mr.png", "normal.png", "occlusion.png", "emissive.png"};
    for (int k = 0; k < 4; ++k) write_bytes(dir / files[k], checker_png(uint32_t(8 + 8 * k), 2));
    g.metallic_roughness_image = dir / files[0];
    g.normal_image = dir / files[1];
    g.occlusion_image = dir / files[2];
    g.emissive_image = dir / files[3];
    g.normal_scale = 0.625f;
    g.occlusion_strength = 0.375f;
    g.emissive[0] = 0.5f, g.emissive[1] = 0.25f, g.emissive[2] = 0.125f;
  }
  if (!save_gltf(file, view).ok) return {};
  return file;
}

// The sphere of two_material_sphere as one surface with vertex colours and a second uv set:
// the northern half red (1, v, 0, 1: green follows the latitude v), the southern half blue
// (0, 0, 1, 0.5); the equator ring is doubled, one copy per half, so it is a colour seam (one
// position, two colours) and nothing else; TEXCOORD_1 = (0.25 + u / 2, v / 2), a lightmap-style
// set with TEXCOORD_0's seam.
inline MeshData coloured_sphere(int rings, int segments) {
  MeshData m = two_material_sphere(rings, segments);
  m.submeshes.clear();
  m.materials.clear();
  const uint32_t row = uint32_t(segments + 1), equator = uint32_t(rings / 2) * row;
  const uint32_t copies = uint32_t(m.vertex_count());
  for (uint32_t v = equator; v < equator + row; ++v) {
    m.positions.insert(m.positions.end(), {m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]});
    m.uvs.insert(m.uvs.end(), {m.uvs[2 * v], m.uvs[2 * v + 1]});
  }
  const size_t north = size_t(rings / 2) * size_t(segments) * 2;
  for (size_t t = north; t < m.triangle_count(); ++t)
    for (int c = 0; c < 3; ++c) {
      uint32_t& v = m.indices[3 * t + size_t(c)];
      if (v >= equator && v < equator + row) v = copies + (v - equator);
    }
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    const float vv = m.uvs[2 * v + 1];
    const bool south = v >= copies || v > equator + row - 1;
    if (south) m.colors.insert(m.colors.end(), {0, 0, 1, 0.5f});
    else m.colors.insert(m.colors.end(), {1, vv, 0, 1});
    m.uvs1.insert(m.uvs1.end(), {0.25f + m.uvs[2 * v] / 2, vv / 2});
  }
  return m;
}

// coloured_sphere as <dir>/<name>.gltf (+ .bin) with one material: base colour texture
// <name>-image0.png on TEXCOORD_0, occlusion texture <name>-image1.png on TEXCOORD_1.
inline std::filesystem::path write_coloured_gltf(const std::filesystem::path& dir, const std::string& name,
                                                int rings = 24, int segments = 48) {
  const MeshData m = coloured_sphere(rings, segments);
  std::filesystem::create_directories(dir);
  write_bytes(dir / "checker.png", checker_png(64, 8));
  write_bytes(dir / "light.png", checker_png(16, 2));
  GltfMeshView view;
  view.name = name;
  view.positions = m.positions.data();
  view.vertex_count = m.vertex_count();
  view.uvs = m.uvs.data();
  view.uvs1 = m.uvs1.data();
  view.colors = m.colors.data();
  view.indices = m.indices.data();
  view.index_count = m.indices.size();
  GltfMaterialView g;
  g.name = "painted";
  g.base_color_image = dir / "checker.png";
  g.occlusion_image = dir / "light.png";
  g.occlusion_strength = 0.75f;
  g.tex_coords[3] = 1;  // occlusion reads TEXCOORD_1
  view.materials.push_back(g);
  view.submeshes.push_back({0, m.indices.size(), 0});
  const std::filesystem::path file = dir / (name + ".gltf");
  if (!save_gltf(file, view).ok) return {};
  return file;
}

}  // namespace lod::test
