// Materials through the levels: split -> (simplify) -> group by material. See material_runs.h.
#include "preprocess/material_runs.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <unordered_map>

#include "preprocess/cluster_simplifier.h"

namespace lod {

std::vector<int32_t> triangle_materials(const MeshView& mesh) {
  std::vector<int32_t> out(mesh.triangle_count(), -1);
  for (const Submesh& s : mesh.submeshes) {
    const size_t end = std::min<size_t>(size_t(s.first_triangle) + s.triangle_count, out.size());
    for (size_t t = s.first_triangle; t < end; ++t) out[t] = s.material;
  }
  return out;
}

size_t split_vertices_by_material(MeshData& mesh) {
  if (mesh.submeshes.size() < 2) return 0;
  const std::vector<int32_t> tri = triangle_materials(mesh);
  const size_t nv = mesh.vertex_count();
  const bool normals = mesh.normals.size() == mesh.positions.size();
  const bool uvs = mesh.uvs.size() == 2 * nv;
  const bool uvs1 = mesh.uvs1.size() == 2 * nv, colors = mesh.colors.size() == 4 * nv;
  constexpr int64_t kNone = INT64_MIN;
  std::vector<int64_t> owner(nv, kNone);  // the material a vertex keeps
  std::unordered_map<uint64_t, uint32_t> copies;  // (vertex, material) -> copy
  for (size_t t = 0; t < tri.size(); ++t)
    for (int c = 0; c < 3; ++c) {
      uint32_t& v = mesh.indices[3 * t + size_t(c)];
      if (v >= nv) continue;  // cleaning drops such faces
      if (owner[v] == kNone) owner[v] = tri[t];
      if (owner[v] == tri[t]) continue;
      const uint64_t key = uint64_t(v) << 32 | uint32_t(tri[t]);
      auto [it, fresh] = copies.try_emplace(key, uint32_t(mesh.vertex_count()));
      if (fresh) {
        const uint32_t from = v;
        for (int k = 0; k < 3; ++k) mesh.positions.push_back(mesh.positions[3 * size_t(from) + size_t(k)]);
        if (normals)
          for (int k = 0; k < 3; ++k) mesh.normals.push_back(mesh.normals[3 * size_t(from) + size_t(k)]);
        if (uvs)
          for (int k = 0; k < 2; ++k) mesh.uvs.push_back(mesh.uvs[2 * size_t(from) + size_t(k)]);
        if (uvs1)
          for (int k = 0; k < 2; ++k) mesh.uvs1.push_back(mesh.uvs1[2 * size_t(from) + size_t(k)]);
        if (colors)
          for (int k = 0; k < 4; ++k) mesh.colors.push_back(mesh.colors[4 * size_t(from) + size_t(k)]);
      }
      v = it->second;
    }
  return copies.size();
}

std::vector<int32_t> vertex_materials(const MeshView& mesh) {
  std::vector<int32_t> out(mesh.vertex_count(), -1);
  if (mesh.submeshes.empty()) return out;  // no per-triangle array of -1s to go through
  const std::vector<int32_t> tri = triangle_materials(mesh);
  for (size_t t = 0; t < tri.size(); ++t)
    for (int c = 0; c < 3; ++c)
      if (mesh.indices[3 * t + size_t(c)] < out.size()) out[mesh.indices[3 * t + size_t(c)]] = tri[t];
  return out;
}

size_t distinct_materials(const std::vector<int32_t>& vertex_material) {
  std::vector<int32_t> m = vertex_material;
  std::sort(m.begin(), m.end());
  return size_t(std::unique(m.begin(), m.end()) - m.begin());
}

void group_by_material(std::vector<uint32_t>& indices, const std::vector<uint32_t>& source,
                       const std::vector<int32_t>& vertex_material, uint32_t level, std::vector<LevelSubmesh>& out) {
  const size_t nt = indices.size() / 3;
  std::vector<std::pair<int32_t, uint32_t>> order(nt);
  for (size_t t = 0; t < nt; ++t) order[t] = {vertex_material[source[indices[3 * t]]], uint32_t(t)};
  std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<uint32_t> sorted(indices.size());
  for (size_t i = 0; i < nt; ++i) {
    const uint32_t t = order[i].second;
    for (int c = 0; c < 3; ++c) sorted[3 * i + size_t(c)] = indices[3 * size_t(t) + size_t(c)];
    if (i == 0 || order[i].first != order[i - 1].first)
      out.push_back({level, uint32_t(3 * i), 0, order[i].first});
    out.back().index_count += 3;
  }
  indices = std::move(sorted);
}

void cluster_simplify_per_material(ChainLevelOut* levels, const MeshData& mesh, const std::vector<int32_t>& vertex_material,
                                   const size_t* target_triangles, size_t level_count, const float* attributes,
                                   size_t attribute_count) {
  const size_t ac = attributes ? attribute_count : 0;
  // Each material's triangles as a mesh of its own vertices.
  std::map<int32_t, std::vector<uint32_t>> faces;  // material -> input faces' corners
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    std::vector<uint32_t>& f = faces[vertex_material[mesh.indices[3 * t]]];
    f.insert(f.end(), &mesh.indices[3 * t], &mesh.indices[3 * t] + 3);
  }
  const double total = double(mesh.triangle_count());
  for (size_t l = 0; l < level_count; ++l) levels[l] = ChainLevelOut{}, levels[l].reached = true;
  float error = 0;
  for (const auto& [material, corners] : faces) {
    std::vector<uint32_t> local(mesh.vertex_count(), ~0u), inputs, part_indices;
    std::vector<float> part_positions, part_attributes;
    for (uint32_t v : corners) {
      if (local[v] == ~0u) {
        local[v] = uint32_t(inputs.size());
        inputs.push_back(v);
        part_positions.insert(part_positions.end(), &mesh.positions[3 * size_t(v)], &mesh.positions[3 * size_t(v)] + 3);
        if (ac) part_attributes.insert(part_attributes.end(), attributes + ac * v, attributes + ac * (v + 1));
      }
      part_indices.push_back(local[v]);
    }
    const double share = double(corners.size() / 3) / total;
    std::vector<size_t> targets(level_count);
    for (size_t l = 0; l < level_count; ++l)
      targets[l] = std::max<size_t>(1, size_t(std::llround(double(target_triangles[l]) * share)));
    std::vector<ChainLevelOut> part(level_count);
    ClusterOptions options;
    if (ac) options.attributes = part_attributes.data(), options.attribute_count = ac;
    cluster_simplify_chain(part.data(), part_positions.data(), inputs.size(), part_indices.data(), part_indices.size(),
                           targets.data(), level_count, options);
    for (size_t l = 0; l < level_count; ++l) {
      ChainLevelOut& out = levels[l];
      const uint32_t base = uint32_t(out.source_vertex.size());
      out.positions.insert(out.positions.end(), part[l].positions.begin(), part[l].positions.end());
      out.attributes.insert(out.attributes.end(), part[l].attributes.begin(), part[l].attributes.end());
      for (uint32_t i : part[l].indices) out.indices.push_back(base + i);
      for (uint32_t s : part[l].source_vertex) out.source_vertex.push_back(inputs[s]);
      error = std::max(error, part[l].error);
      out.error = std::max(out.error, error);
      out.reached = out.reached && part[l].reached;
    }
  }
  for (size_t l = 0; l < level_count; ++l) {
    levels[l].target_triangles = target_triangles[l];
    if (l > 0) levels[l].error = std::max(levels[l].error, levels[l - 1].error);
  }
}

namespace {

// Control bytes would end up in files, JSON and terminals: such a name is replaced.
bool storable(const std::string& s) {
  if (s.size() > kMaxMaterialString) return false;
  for (unsigned char c : s)
    if (c < 0x20 || c == 0x7f) return false;
  return true;
}

float unit(float x, bool& clamped, float fallback = 1.0f) {
  const float y = std::isfinite(x) ? std::clamp(x, 0.0f, 1.0f) : fallback;
  clamped = clamped || !(y == x);
  return y;
}

std::string number_text(float x) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", double(x));
  return b;
}

// The texture factors: normalTexture.scale >= 0 and finite (a negative one, which would turn
// the relief inside out, becomes 0 with a note: no viewer or exporter here flips normals),
// occlusion strength and emissive factor in [0, 1].
void keep_texture_factors(const MeshMaterial& m, const std::string& at, ChainMaterial& c, std::vector<std::string>& notes) {
  if (std::isfinite(m.normal_scale) && m.normal_scale >= 0 && m.normal_scale <= 1e6f) {
    c.normal_scale = m.normal_scale;
  } else {
    c.normal_scale = std::isfinite(m.normal_scale) ? std::clamp(m.normal_scale, 0.0f, 1e6f) : 1.0f;
    notes.push_back(at + ": normalTexture.scale " + number_text(m.normal_scale) + " is " +
                    (std::isfinite(m.normal_scale) ? "out of [0, 1e6]" : "not finite") + ", clamped to " +
                    number_text(c.normal_scale));
  }
  bool clamped = false;
  c.occlusion_strength = unit(m.occlusion_strength, clamped);
  if (clamped)
    notes.push_back(at + ": occlusionTexture.strength " + number_text(m.occlusion_strength) + " outside [0, 1], clamped to " +
                    number_text(c.occlusion_strength));
  clamped = false;
  for (int k = 0; k < 3; ++k) c.emissive[k] = unit(m.emissive[k], clamped, 0.0f);
  if (clamped)
    notes.push_back(at + ": emissive factor " + number_text(m.emissive[0]) + " " + number_text(m.emissive[1]) + " " +
                    number_text(m.emissive[2]) + " outside [0, 1] or not finite, clamped");
}

// The chain's URI for mesh image `k`, copied into the chain at its first use (so images no
// kept material names are not stored).
std::string keep_embedded_image(const EmbeddedImage& image, uint32_t k, std::vector<int64_t>& kept,
                                std::vector<EmbeddedImage>& out) {
  if (kept[k] < 0) {
    kept[k] = int64_t(out.size());
    out.push_back(image);
  }
  return embedded_image_uri(uint32_t(kept[k]));
}

}  // namespace

void add_chain_materials(const MeshData& mesh, const std::filesystem::path& source, LodChain& chain,
                         std::vector<std::string>& notes) {
  if (mesh.materials.empty()) return;
  std::error_code ec;
  const std::filesystem::path folder = std::filesystem::absolute(source, ec).lexically_normal().parent_path();
  chain.texture_base = storable(folder.string()) ? folder.string() : std::string();
  const size_t count = std::min<size_t>(mesh.materials.size(), kMaxMaterials);
  if (count < mesh.materials.size())
    notes.push_back(std::to_string(mesh.materials.size() - count) + " materials past the first " +
                    std::to_string(kMaxMaterials) + " are drawn with the default material (not kept)");
  std::vector<int64_t> kept(mesh.images.size(), -1);  // mesh image -> chain image
  for (size_t i = 0; i < count; ++i) {
    const MeshMaterial& m = mesh.materials[i];
    const std::string at = mesh.source + ": material " + std::to_string(i) + " ('" + (storable(m.name) ? m.name : "?") + "')";
    ChainMaterial c;
    c.name = storable(m.name) ? m.name : "material" + std::to_string(i);
    bool clamped = false;
    for (int k = 0; k < 4; ++k) c.base_color[k] = unit(m.base_color[k], clamped);
    c.metallic = unit(m.metallic, clamped);
    c.roughness = unit(m.roughness, clamped);
    if (clamped) notes.push_back(at + ": base colour, metallic or roughness factors outside [0, 1] clamped");
    c.alpha_mode = m.alpha_mode;
    c.alpha_cutoff = std::isfinite(m.alpha_cutoff) && m.alpha_cutoff >= 0 ? std::min(m.alpha_cutoff, 1e6f) : 0.5f;
    c.double_sided = m.double_sided;
    keep_texture_factors(m, at, c, notes);
    const auto from = texture_slots(m);
    const auto to = texture_slots(c);
    for (size_t k = 0; k < kTextureSlots; ++k) {
      const std::string& uri = *from[k].uri;
      const std::string slot = kTextureSlotNames[k];
      uint32_t image = 0;
      if (*from[k].embedded && is_embedded_image_uri(uri, &image) && image < mesh.images.size()) {
        *to[k] = keep_embedded_image(mesh.images[image], image, kept, chain.images);
        c.tex_coords[k] = std::min(m.tex_coords[k], kMaxTexCoord);
      } else if (*from[k].embedded || uri.rfind("data:", 0) == 0)
        notes.push_back(at + ": its " + slot + " texture is embedded in the file but was not kept (see the import warning); "
                        "the levels reference no texture for it");
      else if (!storable(uri))
        notes.push_back(at + ": " + slot + " texture URI is too long or has control bytes (not kept)");
      else if (is_embedded_image_uri(uri))
        notes.push_back(at + ": " + slot + " texture URI '" + uri +
                        "' has the scheme the asset keeps for its own images (not kept)");
      else if (chain.texture_base.empty() && !uri.empty())
        notes.push_back(at + ": the source's folder cannot be stored, so its " + slot + " texture '" + uri + "' is not kept");
      else
        *to[k] = uri, c.tex_coords[k] = std::min(m.tex_coords[k], kMaxTexCoord);
    }
    chain.materials.push_back(std::move(c));
  }
}

}  // namespace lod
