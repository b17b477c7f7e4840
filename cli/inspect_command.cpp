// lod inspect: what a .lod asset holds, level by level; --export writes each level as PLY
// (default), OBJ, GLB or glTF (--format).
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <vector>

#include "cli/commands.h"
#include "cli/embedded_images_report.h"
#include "cli/names.h"
#include "preprocess/gltf_write.h"
#include "preprocess/mesh_io.h"
#include "preprocess/texture_uri.h"
#include "runtime/lod_asset.h"

namespace lod::cli {
namespace {

const char* alpha_name(AlphaMode a) {
  return a == AlphaMode::mask ? "MASK" : a == AlphaMode::blend ? "BLEND" : "OPAQUE";
}

nlohmann::json materials_json(const LodChain& chain) {
  nlohmann::json out = nlohmann::json::array();
  for (const ChainMaterial& m : chain.materials)
    out.push_back({{"name", m.name},
                   {"tex_coords", m.tex_coords},  // uv set per texture slot
                   {"base_color", {m.base_color[0], m.base_color[1], m.base_color[2], m.base_color[3]}},
                   {"metallic", m.metallic},
                   {"roughness", m.roughness},
                   {"alpha_mode", alpha_name(m.alpha_mode)},
                   {"alpha_cutoff", m.alpha_cutoff},
                   {"double_sided", m.double_sided},
                   {"base_color_texture", m.base_color_texture},
                   {"metallic_roughness_texture", m.metallic_roughness_texture},
                   {"normal_texture", m.normal_texture},
                   {"normal_scale", m.normal_scale},
                   {"occlusion_texture", m.occlusion_texture},
                   {"occlusion_strength", m.occlusion_strength},
                   {"emissive", {m.emissive[0], m.emissive[1], m.emissive[2]}},
                   {"emissive_texture", m.emissive_texture}});
  return out;
}

// Level k's runs as {material, triangles} (material -1: the default).
nlohmann::json level_runs_json(const LodChain& chain, uint32_t k) {
  nlohmann::json out = nlohmann::json::array();
  for (const LevelSubmesh& s : level_submeshes(chain, k)) out.push_back({{"material", s.material}, {"triangles", s.index_count / 3}});
  return out;
}

void print_materials(const LodChain& chain) {
  std::printf("materials: %zu (texture base %s)\n", chain.materials.size(), printable(chain.texture_base).c_str());
  for (size_t i = 0; i < chain.materials.size(); ++i) {
    const ChainMaterial& m = chain.materials[i];
    std::printf("  %zu '%s': base colour %.3g %.3g %.3g %.3g, metallic %.3g, roughness %.3g, %s%s%s%s", i,
                printable(m.name).c_str(), m.base_color[0], m.base_color[1], m.base_color[2], m.base_color[3], m.metallic,
                m.roughness, alpha_name(m.alpha_mode), m.double_sided ? ", double-sided" : "",
                m.base_color_texture.empty() ? "" : ", texture ", printable(m.base_color_texture).c_str());
    if (m.emissive[0] > 0 || m.emissive[1] > 0 || m.emissive[2] > 0)
      std::printf(", emissive %.3g %.3g %.3g", m.emissive[0], m.emissive[1], m.emissive[2]);
    if (!m.metallic_roughness_texture.empty())
      std::printf(", metallic-roughness texture %s", printable(m.metallic_roughness_texture).c_str());
    if (!m.normal_texture.empty())
      std::printf(", normal texture %s (scale %.3g)", printable(m.normal_texture).c_str(), m.normal_scale);
    if (!m.occlusion_texture.empty())
      std::printf(", occlusion texture %s (strength %.3g)", printable(m.occlusion_texture).c_str(), m.occlusion_strength);
    if (!m.emissive_texture.empty()) std::printf(", emissive texture %s", printable(m.emissive_texture).c_str());
    const auto uris = texture_slots(m);
    for (size_t k = 0; k < kTextureSlots; ++k)
      if (!uris[k]->empty() && m.tex_coords[k] != 0)
        std::printf(", %s texture reads TEXCOORD_%u", kTextureSlotNames[k], unsigned(m.tex_coords[k]));
    std::printf("\n");
  }
  for (uint32_t k = 0; k < chain.levels.size(); ++k) {
    const auto runs = level_submeshes(chain, k);
    if (runs.empty()) continue;
    std::printf("  level %u:", k);
    for (const LevelSubmesh& s : runs) std::printf(" material %d x %u", s.material, s.index_count / 3);
    std::printf("\n");
  }
}

// The level's materials and runs for the writers; images resolved against the texture base.
void export_surfaces(const LodChain& chain, uint32_t k, GltfMeshView& view) {
  for (const ChainMaterial& m : chain.materials)
    view.materials.push_back(gltf_material_view(m, chain.images, chain.texture_base));
  for (const LevelSubmesh& s : level_submeshes(chain, k)) view.submeshes.push_back({s.first_index, s.index_count, s.material});
}

ObjSurfaces obj_surfaces(const GltfMeshView& view) {
  ObjSurfaces s;
  for (const GltfMaterialView& m : view.materials) {
    ObjMaterialView o;
    o.name = m.name;
    std::copy(m.base_color, m.base_color + 4, o.base_color);
    o.base_color_image = m.base_color_image;
    o.metallic = m.metallic;
    o.roughness = m.roughness;
    o.metallic_roughness_image = m.metallic_roughness_image;
    o.normal_image = m.normal_image;
    o.normal_scale = m.normal_scale;
    o.occlusion_image = m.occlusion_image;
    o.emissive_image = m.emissive_image;
    o.embedded_images = m.embedded_images;
    std::copy(m.emissive, m.emissive + 3, o.emissive);
    s.materials.push_back(std::move(o));
  }
  for (const GltfSubmeshView& r : view.submeshes) s.submeshes.push_back({r.first_index, r.index_count, r.material});
  s.notes = view.notes;
  return s;
}

// One level in the chosen format: positions and triangles, plus normals and texture
// coordinates where the format has them (PLY: positions only).
Status export_level(const std::filesystem::path& out, const std::string& format, const LodChain& chain,
                    uint32_t k, const std::string& name, std::vector<std::string>& notes) {
  const LodLevel& l = chain.levels[k];
  const float* positions = chain.positions.data() + size_t(l.first_vertex) * 3;
  const float* normals = chain.normals.size() == chain.positions.size() ? chain.normals.data() + size_t(l.first_vertex) * 3
                                                                        : nullptr;
  const float* uvs = chain.uvs.empty() ? nullptr : chain.uvs.data() + size_t(l.first_vertex) * 2;
  const float* uvs1 = chain.uvs1.empty() ? nullptr : chain.uvs1.data() + size_t(l.first_vertex) * 2;
  const float* colors = chain.colors.empty() ? nullptr : chain.colors.data() + size_t(l.first_vertex) * 4;
  const uint32_t* indices = chain.indices.data() + l.first_index;
  GltfMeshView view;
  view.notes = &notes;
  if (!chain.materials.empty()) export_surfaces(chain, k, view);
  if (format == "obj" && uvs1) notes.push_back(out.string() + ": OBJ has one uv set; TEXCOORD_1 is not written (glb or gltf keep it)");
  if (format == "obj" && view.submeshes.empty())
    return save_obj(out, positions, normals, l.vertex_count, indices, l.index_count, uvs, colors);
  if (format == "obj")
    return save_obj(out, positions, normals, l.vertex_count, indices, l.index_count, uvs, obj_surfaces(view), colors);
  if (format == "glb" || format == "gltf") {
    view.name = name;
    view.positions = positions;
    view.normals = normals;
    view.uvs = uvs;
    view.uvs1 = uvs1;
    view.colors = colors;
    view.vertex_count = l.vertex_count;
    view.indices = indices;
    view.index_count = l.index_count;
    return save_gltf(out, view);
  }
  return save_ply(out, positions, l.vertex_count, indices, l.index_count);
}

}  // namespace

int inspect_command(const InspectArgs& args) {
  if (is_hlod_file(args.file)) return inspect_hlod_command(args);
  const std::string shown_file = printable(args.file);
  LodChain chain;
  if (auto st = read_lod_asset(args.file, chain); !st) {
    std::fprintf(stderr, "lod inspect: %s\n", printable(st.message).c_str());
    return 1;
  }
  std::error_code size_error;
  const auto bytes = std::filesystem::file_size(args.file, size_error);
  const double full = chain.levels.empty() ? 1.0 : double(std::max(1u, chain.levels[0].triangles()));
  if (args.json) {
    nlohmann::json j;
    j["file"] = args.file;
    j["name"] = chain.name;
    j["version"] = kLodAssetVersion;
    j["bytes"] = bytes;
    char hash[32];
    std::snprintf(hash, sizeof hash, "%016llx", (unsigned long long)chain.source_hash);
    j["source_hash"] = hash;
    j["morph_targets"] = chain.morph_targets.size();  // 0 = level changes cannot blend
    j["hierarchy_nodes"] = chain.hierarchy.node_count();
    j["hierarchy_uvs"] = !chain.hierarchy.uvs.empty();
    j["hierarchy_uvs1"] = !chain.hierarchy.uvs1.empty();
    j["hierarchy_colors"] = !chain.hierarchy.colors.empty();
    j["hierarchy_normals"] = !chain.hierarchy.normals.empty();
    j["hierarchy_seams_pinned"] = chain.hierarchy.seams_pinned;
    j["texcoords"] = !chain.uvs.empty();
    j["texcoords1"] = !chain.uvs1.empty();
    j["colors"] = !chain.colors.empty();
    j["materials"] = materials_json(chain);
    j["images"] = images_json(chain.images);
    j["levels"] = nlohmann::json::array();
    for (size_t i = 0; i < chain.levels.size(); ++i) {
      const auto& l = chain.levels[i];
      j["levels"].push_back({{"index", i},
                             {"triangles", l.triangles()},
                             {"vertices", l.vertex_count},
                             {"ratio", l.triangles() / full},
                             {"l", l.level},
                             {"error", l.error},
                             {"error_rms", l.error_rms},
                             {"bounds", {l.bounds.center[0], l.bounds.center[1], l.bounds.center[2], l.bounds.radius}},
                             {"bytes", l.vertex_count * 24ull + l.index_count * 4ull}});
      if (!chain.uvs.empty()) j["levels"].back()["uv_error"] = chain.uv_errors[i];
      if (!chain.uvs1.empty()) j["levels"].back()["uv1_error"] = chain.uv1_errors[i];
      if (!chain.colors.empty()) j["levels"].back()["color_error"] = chain.color_errors[i];
      if (!chain.materials.empty()) j["levels"].back()["submeshes"] = level_runs_json(chain, uint32_t(i));
    }
    // Names and paths are bytes: invalid UTF-8 is replaced (U+FFFD) rather than aborting the
    // dump; JSON escapes control characters itself.
    std::printf("%s\n", j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  } else {
    std::printf("%s: model '%s', asset v%u, %llu bytes, source hash %016llx\n", shown_file.c_str(),
                printable(chain.name).c_str(),
                kLodAssetVersion, (unsigned long long)bytes, (unsigned long long)chain.source_hash);
    std::printf("%5s %10s %9s %8s %4s %12s %12s %10s %10s\n", "level", "triangles", "vertices", "ratio", "l",
                "error", "error_rms", "radius", "bytes");
    for (size_t i = 0; i < chain.levels.size(); ++i) {
      const auto& l = chain.levels[i];
      std::printf("%5zu %10u %9u %7.2f%% %4d %12.6g %12.6g %10.4g %10llu\n", i, l.triangles(), l.vertex_count,
                  100.0 * l.triangles() / full, l.level, l.error, l.error_rms, l.bounds.radius,
                  (unsigned long long)(l.vertex_count * 24ull + l.index_count * 4ull));
    }
    if (can_morph_levels(chain))
      std::printf("morph targets: %zu (level changes blend; %llu bytes)\n", chain.morph_targets.size(),
                  (unsigned long long)(chain.morph_targets.size() * 4ull));
    else if (chain.levels.size() > 1)
      std::printf("morph targets: none (level changes pop; re-bake to add them)\n");
    if (!chain.hierarchy.empty())
      std::printf(
          "vertex hierarchy: %zu nodes%s%s%s%s%s\n", size_t(chain.hierarchy.node_count()),
          chain.hierarchy.uvs.empty() ? "" : ", uvs per node",
          chain.hierarchy.uvs1.empty() ? "" : ", TEXCOORD_1 per node",
          chain.hierarchy.colors.empty() ? "" : ", colours per node",
          chain.hierarchy.normals.empty() ? "" : ", authored normals per node",
          chain.hierarchy.seams_pinned ? ", attribute seams pinned" : " (built before seams were pinned)");
    if (!chain.uvs.empty()) {
      std::printf("texture coordinates: every level (uv seams kept); uv error per level:");
      for (float e : chain.uv_errors) std::printf(" %.4g", e);
      std::printf("\n");
    }
    if (!chain.uvs1.empty()) {
      std::printf("second texture coordinates (TEXCOORD_1): every level (seams kept); uv1 error per level:");
      for (float e : chain.uv1_errors) std::printf(" %.4g", e);
      std::printf("\n");
    }
    if (!chain.colors.empty()) {
      std::printf("vertex colours (COLOR_0, linear RGBA): every level (colour seams kept); colour error per level:");
      for (float e : chain.color_errors) std::printf(" %.4g", e);
      std::printf("\n");
    }
    if (!chain.materials.empty()) print_materials(chain);
    if (!chain.images.empty()) print_images(chain.images);
  }
  if (!args.export_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(args.export_dir, ec);
    if (ec || !std::filesystem::is_directory(args.export_dir)) {
      std::fprintf(stderr, "lod inspect: --export %s: cannot create the folder%s%s\n", printable(args.export_dir).c_str(),
                   ec ? ": " : " (a file is in the way)", ec ? ec.message().c_str() : "");
      return 1;
    }
    // The model name is data from the asset, never a path: only a sanitised form of it names
    // the files, and always directly inside the export folder.
    const std::string stem = export_stem(chain.name);
    for (size_t i = 0; i < chain.levels.size(); ++i) {
      const auto out = std::filesystem::path(args.export_dir) / (stem + "-level" + std::to_string(i) + "." + args.format);
      // Never written through a link planted under the export name (it could point anywhere);
      // a .gltf also writes its .bin, an .obj with materials its .mtl. (Images are written
      // through a temporary file renamed over the name, which replaces a link, never follows it.)
      auto bin = out;
      bin.replace_extension(args.format == "obj" ? ".mtl" : ".bin");
      for (const auto& written : args.format == "gltf" || args.format == "obj" ? std::vector{out, bin} : std::vector{out})
        if (std::filesystem::is_symlink(std::filesystem::symlink_status(written, ec))) {
          std::fprintf(stderr, "lod inspect: %s is a symbolic link; not writing through it\n",
                       printable(written.string()).c_str());
          return 1;
        }
      std::vector<std::string> notes;
      const Status st = export_level(out, args.format, chain, uint32_t(i), stem + "-level" + std::to_string(i), notes);
      for (const std::string& n : notes) std::fprintf(stderr, "lod inspect: note: %s\n", printable(n).c_str());
      if (!st) {
        std::fprintf(stderr, "lod inspect: %s\n", printable(st.message).c_str());
        return 1;
      }
      if (!args.json) std::printf("exported %s\n", printable(out.string()).c_str());
    }
  }
  return 0;
}

}  // namespace lod::cli
