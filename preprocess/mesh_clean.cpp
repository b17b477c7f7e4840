// Input cleaning as a chain of passes over flat arrays: weld bit-identical vertices, drop
// degenerate faces, drop faces whose vertex set repeats an earlier face, drop vertices that
// nothing references. Every pass keeps the first occurrence and the input order, so the
// result depends only on the input.
#include "preprocess/mesh_clean.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <compare>
#include <cstring>
#include <utility>
#include <vector>

#include "preprocess/first_of_equal.h"
#include "preprocess/material_runs.h"

namespace lod {
namespace {

struct PositionKey {
  std::array<uint32_t, 4> bits;  // xyz, material
  auto operator<=>(const PositionKey&) const = default;
};

// Vertices weld only within one material: a material boundary stays two vertices, a seam.
PositionKey key_of(const float* p, int32_t material) {
  PositionKey k;
  for (int i = 0; i < 3; ++i) {
    const float v = p[i] == 0.0f ? 0.0f : p[i];  // -0 and +0 are the same point
    std::memcpy(&k.bits[i], &v, 4);
  }
  k.bits[3] = uint32_t(material);
  return k;
}

// Position and texture coordinate: with uvs, vertices weld only when both match, so a uv seam
// (one position, two uvs) stays two vertices and the simplifier keeps it.
struct TexturedKey {
  std::array<uint32_t, 6> bits;
  auto operator<=>(const TexturedKey&) const = default;
};

TexturedKey key_of(const float* p, const float* uv, int32_t material) {
  TexturedKey k;
  const PositionKey pk = key_of(p, material);
  std::copy(pk.bits.begin(), pk.bits.end(), k.bits.begin());
  for (int i = 0; i < 2; ++i) {
    const float v = uv[i] == 0.0f ? 0.0f : uv[i];
    std::memcpy(&k.bits[4 + i], &v, 4);
  }
  return k;
}

// With a second uv set or vertex colours: position, both uv sets and RGBA (absent ones as 0), so
// a colour or TEXCOORD_1 seam stays two vertices as a uv one does. Meshes without them keep the
// narrower keys above (fewer words to sort).
struct AttributeKey {
  std::array<uint32_t, 12> bits;
  auto operator<=>(const AttributeKey&) const = default;
};

AttributeKey key_of(const float* p, const float* uv, const float* uv1, const float* rgba, int32_t material) {
  AttributeKey k{};
  const PositionKey pk = key_of(p, material);
  std::copy(pk.bits.begin(), pk.bits.end(), k.bits.begin());
  auto put = [&k](const float* values, int count, int at) {
    for (int i = 0; values && i < count; ++i) {
      const float v = values[i] == 0.0f ? 0.0f : values[i];
      std::memcpy(&k.bits[size_t(at + i)], &v, 4);
    }
  };
  put(uv, 2, 4);
  put(uv1, 2, 6);
  put(rgba, 4, 8);
  return k;
}

struct FaceKey {
  std::array<uint32_t, 3> v;  // sorted
  auto operator<=>(const FaceKey&) const = default;
  // Word by word: the array's own == is a memcmp call per comparison, a tenth of the clean.
  bool operator==(const FaceKey& o) const { return v[0] == o.v[0] && v[1] == o.v[1] && v[2] == o.v[2]; }
};

bool zero_area(const float* a, const float* b, const float* c) {
  const double e0[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
  const double e1[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
  const double n[3] = {e0[1] * e1[2] - e0[2] * e1[1], e0[2] * e1[0] - e0[0] * e1[2], e0[0] * e1[1] - e0[1] * e1[0]};
  return n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0;
}

// Submesh ranges after faces were dropped: each keeps its surviving triangles, in order; an
// emptied one goes.
void resubmesh(std::vector<Submesh>& submeshes, const std::vector<uint32_t>& kept_before) {
  std::vector<Submesh> out;
  for (const Submesh& s : submeshes) {
    const size_t end = std::min<size_t>(size_t(s.first_triangle) + s.triangle_count, kept_before.size() - 1);
    const uint32_t first = kept_before[std::min<size_t>(s.first_triangle, end)], last = kept_before[end];
    if (last > first) out.push_back({first, last - first, s.material});
  }
  submeshes = std::move(out);
}

}  // namespace

CleanReport clean_mesh(MeshData& mesh) {
  CleanReport report;
  // Pass 0: a vertex shared by two materials becomes one per material.
  report.material_split_vertices = split_vertices_by_material(mesh);
  // Without submeshes every vertex is of no material (-1): no per-vertex array for it.
  const std::vector<int32_t> materials = mesh.submeshes.empty() ? std::vector<int32_t>{} : vertex_materials(mesh);
  auto material = [&materials](size_t v) { return materials.empty() ? -1 : materials[v]; };
  const size_t nv = mesh.vertex_count();
  const bool has_normals = mesh.normals.size() == mesh.positions.size();
  const bool has_uvs = mesh.uvs.size() == 2 * nv;
  const bool has_uvs1 = mesh.uvs1.size() == 2 * nv, has_colors = mesh.colors.size() == 4 * nv;
  const bool wide = has_uvs1 || has_colors;  // weld on every attribute (AttributeKey)
  auto wide_key = [&](size_t v, int32_t m) {
    return key_of(&mesh.positions[3 * v], has_uvs ? &mesh.uvs[2 * v] : nullptr, has_uvs1 ? &mesh.uvs1[2 * v] : nullptr,
                  has_colors ? &mesh.colors[4 * v] : nullptr, m);
  };

  // Pass 1: weld exactly duplicated positions (and uvs, when there are some) onto their first
  // occurrence.
  std::vector<uint32_t> weld(nv);
  report.duplicate_vertices =
      wide      ? detail::first_of_equal(nv, [&](size_t v) { return wide_key(v, material(v)); }, weld)
      : has_uvs ? detail::first_of_equal(nv, [&](size_t v) { return key_of(&mesh.positions[3 * v], &mesh.uvs[2 * v], material(v)); }, weld)
              : detail::first_of_equal(nv, [&](size_t v) { return key_of(&mesh.positions[3 * v], material(v)); }, weld);

  // Faces repeat each other by their corners' positions (and uvs) whatever their materials:
  // the same face twice in two materials would fight for the same pixels.
  std::vector<uint32_t> same_place;
  const bool split = report.material_split_vertices > 0;
  if (split)
    wide      ? detail::first_of_equal(nv, [&](size_t v) { return wide_key(v, 0); }, same_place)
    : has_uvs ? detail::first_of_equal(nv, [&](size_t v) { return key_of(&mesh.positions[3 * v], &mesh.uvs[2 * v], 0); }, same_place)
            : detail::first_of_equal(nv, [&](size_t v) { return key_of(&mesh.positions[3 * v], 0); }, same_place);
  // Weld the corners in place (what every kept face keeps); a corner's place, by which faces
  // repeat each other, is then its vertex, or with materials split its first same-place vertex
  // (a vertex welds only onto one of the same place).
  for (uint32_t& v : mesh.indices) v = weld[v];
  auto place = [&](uint32_t v) { return split ? same_place[v] : v; };

  // Normals are not part of the weld: say where that merged two that differ (a hard edge).
  if (has_normals) {
    const double min_cos = std::cos(kNormalWeldDegrees * 3.14159265358979323846 / 180);
    for (size_t v = 0; v < nv; ++v) {
      if (weld[v] == v) continue;
      const float *a = &mesh.normals[3 * v], *b = &mesh.normals[3 * size_t(weld[v])];
      const double d = double(a[0]) * b[0] + double(a[1]) * b[1] + double(a[2]) * b[2];
      const double la = double(a[0]) * a[0] + double(a[1]) * a[1] + double(a[2]) * a[2];
      const double lb = double(b[0]) * b[0] + double(b[1]) * b[1] + double(b[2]) * b[2];
      if (!(d >= min_cos * std::sqrt(la * lb))) ++report.normal_conflicts;
    }
  }

  // Kept faces are compacted into mesh.indices itself and kept vertices into their own arrays
  // (each writes at or before where it reads): a scan's cleaning allocates no second copy.
  size_t kept = 0;
  // Kept triangles before triangle t, to re-range submeshes (only when there are some).
  const bool has_submeshes = !mesh.submeshes.empty();
  std::vector<uint32_t> kept_before(has_submeshes ? mesh.triangle_count() + 1 : 0, 0);
  {
    // Per face: live, degenerate, or repeating an earlier face's corners.
    enum : uint8_t { kLive, kDegenerate, kRepeat };
    const size_t nt = mesh.triangle_count();
    std::vector<uint8_t> fate(nt, kLive);
    for (size_t t = 0; t < nt; ++t) {
      const uint32_t a = mesh.indices[3 * t], b = mesh.indices[3 * t + 1], c = mesh.indices[3 * t + 2];
      if (a == b || b == c || a == c || zero_area(&mesh.positions[3 * a], &mesh.positions[3 * b], &mesh.positions[3 * c])) {
        fate[t] = kDegenerate;
        ++report.degenerate_faces;
      }
    }
    // Repeats share their least corner: faces are grouped by it (no hash, no 8-byte items).
    auto face_key = [&](size_t t) {  // computed when asked: no array of 12-byte keys per face
      FaceKey key{{place(mesh.indices[3 * t]), place(mesh.indices[3 * t + 1]), place(mesh.indices[3 * t + 2])}};
      std::sort(key.v.begin(), key.v.end());
      return key;
    };
    auto least_corner = [&](size_t t) {
      if (fate[t] == kDegenerate) return detail::kNoGroup;
      const uint32_t* f = &mesh.indices[3 * t];
      return std::min({place(f[0]), place(f[1]), place(f[2])});
    };
    report.duplicate_faces = detail::first_of_equal_grouped(nt, nv, least_corner, face_key,
                                                            [&fate](uint32_t t, uint32_t) { fate[t] = kRepeat; },
                                                            [&](uint32_t t) { __builtin_prefetch(&mesh.indices[3 * size_t(t)]); });
    for (size_t t = 0; t < nt; ++t) {
      if (has_submeshes) kept_before[t] = uint32_t(kept);
      if (fate[t] != kLive) continue;
      for (int k = 0; k < 3; ++k) mesh.indices[3 * kept + k] = mesh.indices[3 * t + k];
      ++kept;
    }
    if (has_submeshes) kept_before[mesh.triangle_count()] = uint32_t(kept);
    mesh.indices.resize(3 * kept);
  }

  // Pass 3: compact to the referenced vertices, in their original order. Vertices welded
  // away in pass 1 are never referenced and were already counted there.
  std::vector<uint8_t> used(nv, 0);
  for (uint32_t v : mesh.indices) used[v] = 1;
  std::vector<uint32_t>& remap = weld;  // weld[v] is read only at v, before it is rewritten
  auto move_down = [](std::vector<float>& values, size_t per, size_t from, size_t to) {
    for (size_t k = 0; k < per && from != to; ++k) values[per * to + k] = values[per * from + k];  // no memmove call per vertex
  };
  uint32_t next = 0;
  for (size_t v = 0; v < nv; ++v) {
    const bool kept_vertex = weld[v] == v && used[v];
    if (weld[v] == v && !used[v]) ++report.unreferenced_vertices;
    remap[v] = kept_vertex ? next : UINT32_MAX;
    if (!kept_vertex) continue;
    move_down(mesh.positions, 3, v, next);
    if (has_normals) move_down(mesh.normals, 3, v, next);
    if (has_uvs) move_down(mesh.uvs, 2, v, next);
    if (has_uvs1) move_down(mesh.uvs1, 2, v, next);
    if (has_colors) move_down(mesh.colors, 4, v, next);
    ++next;
  }
  for (uint32_t& v : mesh.indices) v = remap[v];

  mesh.positions.resize(3 * size_t(next));
  mesh.normals.resize(has_normals ? 3 * size_t(next) : 0);
  mesh.uvs.resize(has_uvs ? 2 * size_t(next) : 0);
  mesh.uvs1.resize(has_uvs1 ? 2 * size_t(next) : 0);
  mesh.colors.resize(has_colors ? 4 * size_t(next) : 0);
  if (has_submeshes) resubmesh(mesh.submeshes, kept_before);
  return report;
}

}  // namespace lod
