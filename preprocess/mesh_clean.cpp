// Input cleaning as a chain of passes over flat arrays: weld bit-identical vertices, drop
// degenerate faces, drop faces whose vertex set repeats an earlier face, drop vertices that
// nothing references. Every pass keeps the first occurrence and the input order, so the
// result depends only on the input.
#include "preprocess/mesh_clean.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <unordered_map>

namespace lod {
namespace {

struct PositionKey {
  std::array<uint32_t, 3> bits;
  bool operator==(const PositionKey&) const = default;
};
struct PositionKeyHash {
  size_t operator()(const PositionKey& k) const {
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (uint32_t b : k.bits) h = (h ^ b) * 0xFF51AFD7ED558CCDull;
    return size_t(h ^ (h >> 29));
  }
};

PositionKey key_of(const float* p) {
  PositionKey k;
  for (int i = 0; i < 3; ++i) {
    const float v = p[i] == 0.0f ? 0.0f : p[i];  // -0 and +0 are the same point
    std::memcpy(&k.bits[i], &v, 4);
  }
  return k;
}

struct FaceKey {
  std::array<uint32_t, 3> v;  // sorted
  bool operator==(const FaceKey&) const = default;
};
struct FaceKeyHash {
  size_t operator()(const FaceKey& k) const {
    uint64_t h = 0xC2B2AE3D27D4EB4Full;
    for (uint32_t x : k.v) h = (h ^ x) * 0x9E3779B97F4A7C15ull;
    return size_t(h ^ (h >> 31));
  }
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
  const size_t nv = mesh.vertex_count();
  const bool has_normals = mesh.normals.size() == mesh.positions.size();
  const bool has_uvs = mesh.uvs.size() == 2 * nv;

  // Pass 1: weld exactly duplicated positions onto their first occurrence.
  std::vector<uint32_t> weld(nv);
  {
    std::unordered_map<PositionKey, uint32_t, PositionKeyHash> first;
    first.reserve(nv);
    for (size_t v = 0; v < nv; ++v) {
      auto [it, inserted] = first.emplace(key_of(&mesh.positions[3 * v]), uint32_t(v));
      weld[v] = it->second;
      if (!inserted) ++report.duplicate_vertices;
    }
  }

  // Pass 2: faces, in order; degenerate ones first, then repeats of an earlier vertex set.
  std::vector<uint32_t> kept;
  kept.reserve(mesh.indices.size());
  std::vector<uint32_t> kept_before(mesh.triangle_count() + 1, 0);  // kept triangles before t: re-ranges submeshes
  {
    std::unordered_map<FaceKey, uint32_t, FaceKeyHash> seen;
    seen.reserve(mesh.triangle_count());
    for (size_t t = 0; t < mesh.triangle_count(); ++t) {
      kept_before[t] = uint32_t(kept.size() / 3);
      const uint32_t a = weld[mesh.indices[3 * t]], b = weld[mesh.indices[3 * t + 1]], c = weld[mesh.indices[3 * t + 2]];
      if (a == b || b == c || a == c ||
          zero_area(&mesh.positions[3 * a], &mesh.positions[3 * b], &mesh.positions[3 * c])) {
        ++report.degenerate_faces;
        continue;
      }
      FaceKey key{{a, b, c}};
      std::sort(key.v.begin(), key.v.end());
      if (!seen.emplace(key, uint32_t(t)).second) {
        ++report.duplicate_faces;
        continue;
      }
      kept.insert(kept.end(), {a, b, c});
    }
    kept_before[mesh.triangle_count()] = uint32_t(kept.size() / 3);
  }

  // Pass 3: compact to the referenced vertices, in their original order. Vertices welded
  // away in pass 1 are never referenced and were already counted there.
  std::vector<uint8_t> used(nv, 0);
  for (uint32_t v : kept) used[v] = 1;
  std::vector<uint32_t> remap(nv, UINT32_MAX);
  std::vector<float> positions, normals, uvs;
  positions.reserve(mesh.positions.size());
  if (has_normals) normals.reserve(mesh.normals.size());
  if (has_uvs) uvs.reserve(mesh.uvs.size());
  uint32_t next = 0;
  for (size_t v = 0; v < nv; ++v) {
    if (weld[v] != v) continue;
    if (!used[v]) {
      ++report.unreferenced_vertices;
      continue;
    }
    remap[v] = next++;
    positions.insert(positions.end(), &mesh.positions[3 * v], &mesh.positions[3 * v] + 3);
    if (has_normals) normals.insert(normals.end(), &mesh.normals[3 * v], &mesh.normals[3 * v] + 3);
    if (has_uvs) uvs.insert(uvs.end(), &mesh.uvs[2 * v], &mesh.uvs[2 * v] + 2);
  }
  for (uint32_t& v : kept) v = remap[v];

  mesh.positions = std::move(positions);
  mesh.normals = has_normals ? std::move(normals) : std::vector<float>{};
  mesh.uvs = has_uvs ? std::move(uvs) : std::vector<float>{};
  mesh.indices = std::move(kept);
  resubmesh(mesh.submeshes, kept_before);
  return report;
}

}  // namespace lod
