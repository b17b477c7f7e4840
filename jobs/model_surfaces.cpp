// ModelSurfaces: a chain's material runs and materials in the public API's layout.
#include "jobs/model_surfaces.h"

#include "runtime/embedded_image.h"
#include "runtime/texture_uri.h"

namespace lod {

namespace {

MaterialAlpha alpha_of(AlphaMode mode) {
  switch (mode) {
    case AlphaMode::mask:
      return MaterialAlpha::mask;
    case AlphaMode::blend:
      return MaterialAlpha::blend;
    case AlphaMode::opaque:
      break;
  }
  return MaterialAlpha::opaque;
}

}  // namespace

std::shared_ptr<const ModelSurfaces> build_model_surfaces(std::shared_ptr<const LodChain> chain) {
  auto out = std::make_shared<ModelSurfaces>();
  const LodChain& c = *chain;
  out->chain = std::move(chain);

  const uint32_t levels = static_cast<uint32_t>(c.levels.size());
  out->submeshes.reserve(c.submeshes.size());
  out->first_submesh.reserve(levels + 1);
  for (uint32_t k = 0; k < levels; ++k) {
    out->first_submesh.push_back(static_cast<uint32_t>(out->submeshes.size()));
    for (const LevelSubmesh& run : level_submeshes(c, k))
      out->submeshes.push_back({run.first_index, run.index_count, run.material});
  }
  out->first_submesh.push_back(static_cast<uint32_t>(out->submeshes.size()));

  // Every string first (name, then one path per texture slot), views after: the vector is
  // never resized once a view into it exists.
  constexpr size_t kPerMaterial = 1 + kTextureSlots;
  out->strings.reserve(c.materials.size() * kPerMaterial);
  for (const ChainMaterial& m : c.materials) {
    out->strings.push_back(m.name);
    for (const std::string* uri : texture_slots(m)) out->strings.push_back(texture_file(c.texture_base, *uri).string());
  }
  out->materials.reserve(c.materials.size());
  for (size_t i = 0; i < c.materials.size(); ++i) {
    const ChainMaterial& m = c.materials[i];
    const std::string* strings = out->strings.data() + i * kPerMaterial;
    Material& to = out->materials.emplace_back();
    to.name = strings[0];
    for (int k = 0; k < 4; ++k) to.base_color[k] = m.base_color[k];
    to.metallic = m.metallic;
    to.roughness = m.roughness;
    for (int k = 0; k < 3; ++k) to.emissive[k] = m.emissive[k];
    to.alpha_mode = alpha_of(m.alpha_mode);
    to.alpha_cutoff = m.alpha_cutoff;
    to.double_sided = m.double_sided;
    MaterialTexture* slots[kTextureSlots] = {&to.base_color_texture, &to.metallic_roughness_texture, &to.normal_texture,
                                        &to.occlusion_texture, &to.emissive_texture};
    const auto uris = texture_slots(m);
    for (size_t s = 0; s < kTextureSlots; ++s) {
      MaterialTexture& t = *slots[s];
      uint32_t image = 0;
      if (is_embedded_image_uri(*uris[s], &image)) {
        if (image < c.images.size()) {  // validate_chain guarantees it; a bad index gives no texture
          t.bytes = c.images[image].bytes;
          t.mime = mime_type(c.images[image].type);
        }
      } else {
        t.path = strings[1 + s];
      }
      if (!t.empty()) t.texcoord = m.tex_coords[s];
    }
  }
  return out;
}

LevelMeshView level_mesh_view(const ModelSurfaces& surfaces, uint32_t model, uint32_t level) {
  const LodChain& c = *surfaces.chain;
  const LodLevel& l = c.levels[level];
  LevelMeshView v;
  v.id = level_mesh_id(model, level);
  v.vertex_count = l.vertex_count;
  if (l.vertex_count == 0 || l.index_count == 0) return v;  // the culled level: nothing to draw
  const size_t first = l.first_vertex, n = l.vertex_count;
  auto per_vertex = [&](const std::vector<float>& a, size_t width) {
    return a.size() >= (first + n) * width ? std::span<const float>(a.data() + first * width, n * width)
                                           : std::span<const float>();
  };
  v.positions = per_vertex(c.positions, 3);
  v.normals = per_vertex(c.normals, 3);
  v.uvs = per_vertex(c.uvs, 2);
  v.uvs1 = per_vertex(c.uvs1, 2);
  v.colors = per_vertex(c.colors, 4);
  v.indices = std::span<const uint32_t>(c.indices.data() + l.first_index, l.index_count);
  v.submeshes = std::span<const MeshSubmesh>(surfaces.submeshes.data() + surfaces.first_submesh[level],
                                         surfaces.first_submesh[level + 1] - surfaces.first_submesh[level]);
  return v;
}

}  // namespace lod
