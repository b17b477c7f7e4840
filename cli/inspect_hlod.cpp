// lod inspect FILE.hlod: the tree, per depth and node by node (--json: every node); --verify:
// every node's payload checked.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/embedded_images_report.h"
#include "cli/names.h"
#include "runtime/hlod_asset.h"
#include "runtime/regular_file.h"

namespace lod::cli {
namespace {

// Outside programs read these names: id, parent, depth, leaf, boundary_triangles, layers
// (triangles, error). Keep them.
nlohmann::json node_json(const HlodTree& tree, size_t i) {
  const HlodNode& n = tree.nodes[i];
  nlohmann::json layers = nlohmann::json::array();
  for (uint32_t k = 0; k < n.layer_count; ++k) {
    layers.push_back({{"triangles", n.layers[k].triangles}, {"error", n.layers[k].error}, {"uv_error", n.layers[k].uv_error}});
    if (tree.uvs1) layers.back()["uv1_error"] = n.layers[k].uv1_error;
    if (tree.colors) layers.back()["color_error"] = n.layers[k].color_error;
  }
  return {{"id", i},      {"parent", n.parent},
          {"depth", n.depth}, {"leaf", n.leaf()},
          {"boundary_triangles", n.boundary_triangles}, {"layers", layers}, {"material_runs", n.material_runs}};
}

// The header's materials (Zhou and Tian: the HLOD file's header holds them), texture URIs as stored.
nlohmann::json materials_json(const HlodTree& tree) {
  nlohmann::json out = nlohmann::json::array();
  for (const ChainMaterial& m : tree.materials) {
    nlohmann::json textures = nlohmann::json::object();
    const auto uris = texture_slots(m);
    for (size_t k = 0; k < kTextureSlots; ++k)
      if (!uris[k]->empty()) textures[kTextureSlotNames[k]] = *uris[k];
    out.push_back({{"name", m.name},
                   {"base_color", {m.base_color[0], m.base_color[1], m.base_color[2], m.base_color[3]}},
                   {"metallic", m.metallic},
                   {"roughness", m.roughness},
                   {"double_sided", m.double_sided},
                   {"textures", textures}});
  }
  return out;
}

void print_materials(const HlodTree& tree) {
  std::printf("materials: %zu (texture base %s); texture coordinates: %s; TEXCOORD_1: %s; vertex colours: %s\n",
              tree.materials.size(), printable(tree.texture_base).c_str(), tree.uvs ? "yes" : "no",
              tree.uvs1 ? "yes" : "no", tree.colors ? "yes" : "no");
  for (size_t i = 0; i < tree.materials.size(); ++i) {
    const ChainMaterial& m = tree.materials[i];
    std::printf("  %zu '%s': base colour %.3g %.3g %.3g %.3g, metallic %.3g, roughness %.3g", i, printable(m.name).c_str(),
                m.base_color[0], m.base_color[1], m.base_color[2], m.base_color[3], m.metallic, m.roughness);
    const auto uris = texture_slots(m);
    for (size_t k = 0; k < kTextureSlots; ++k)
      if (!uris[k]->empty()) std::printf(", %s texture %s", kTextureSlotNames[k], printable(*uris[k]).c_str());
    std::printf("\n");
  }
}

void print_depth_table(const HlodTree& tree) {
  uint32_t deepest = 0;
  for (const HlodNode& n : tree.nodes) deepest = std::max<uint32_t>(deepest, n.depth);
  std::printf("%5s %7s %7s %12s %12s %10s %12s %12s\n", "depth", "nodes", "leaves", "finest tris", "coarsest tris",
              "boundary", "max error", "payload MB");
  for (uint32_t d = 0; d <= deepest; ++d) {
    size_t nodes = 0, leaves = 0;
    uint64_t finest = 0, coarsest = 0, boundary = 0, bytes = 0;
    float error = 0;
    for (const HlodNode& n : tree.nodes) {
      if (n.depth != d) continue;
      ++nodes, leaves += n.leaf();
      finest += n.layers[0].triangles;
      coarsest += n.layers[n.layer_count - 1].triangles;
      boundary += n.boundary_triangles;
      bytes += n.payload_size;
      error = std::max(error, n.layers[n.layer_count - 1].error);
    }
    std::printf("%5u %7zu %7zu %12llu %12llu %10llu %12.6g %12.3f\n", d, nodes, leaves, (unsigned long long)finest,
                (unsigned long long)coarsest, (unsigned long long)boundary, error, double(bytes) / 1e6);
  }
}

// The top of the tree, indented (the whole tree would be thousands of lines).
void print_tree_top(const HlodTree& tree, size_t i, uint32_t max_depth) {
  const HlodNode& n = tree.nodes[i];
  std::printf("%*snode %zu%s: layers", 2 * int(n.depth), "", i, n.leaf() ? " (leaf)" : "");
  for (uint32_t k = 0; k < n.layer_count; ++k) std::printf(" %u/%.3g", n.layers[k].triangles, n.layers[k].error);
  if (!n.leaf()) std::printf(", boundary %u, %u children", n.boundary_triangles, n.child_count);
  std::printf("\n");
  if (n.depth >= max_depth) return;
  for (uint32_t c = 0; c < n.child_count; ++c) print_tree_top(tree, n.first_child + c, max_depth);
}

// Every node's payload read and checked; each damaged one named. 2 when any is, 0 when none,
// 1 when the file cannot be opened at all.
int verify_hlod(const InspectArgs& args) {
  HlodFile file;
  HlodTree tree;
  if (Status st = file.open(args.file, tree); !st) {
    // The magic matched (is_hlod_file): a head that does not check out is damage too.
    std::fprintf(stderr, "lod inspect --verify: %s\n", printable(st.message).c_str());
    if (args.json) {
      nlohmann::json j = {{"file", args.file}, {"verified", false}, {"head", st.message}};
      std::printf("%s\n", j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
    }
    return 2;
  }
  nlohmann::json damaged = nlohmann::json::array();
  HlodPayload payload;
  for (uint32_t i = 0; i < tree.nodes.size(); ++i) {
    const Status st = file.read_node(i, tree.nodes[i], payload);
    if (st) continue;
    std::fprintf(stderr, "lod inspect --verify: %s\n", printable(st.message).c_str());
    damaged.push_back({{"node", i}, {"message", st.message}});
  }
  if (args.json) {
    nlohmann::json j = {{"file", args.file}, {"verified", damaged.empty()}, {"nodes", tree.nodes.size()},
                        {"damaged", damaged}};
    std::printf("%s\n", j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  } else if (damaged.empty()) {
    std::printf("%s: all %zu node payloads verified\n", printable(args.file).c_str(), tree.nodes.size());
  } else {
    std::printf("%s: %zu of %zu node payloads damaged\n", printable(args.file).c_str(), damaged.size(),
                tree.nodes.size());
  }
  return damaged.empty() ? 0 : 2;
}

}  // namespace

bool is_hlod_file(const std::string& file) {
  // Regular files only: opening a FIFO to peek at it would block (the .lod reader then says
  // what the path is).
  RegularFile f;
  std::vector<uint8_t> magic;
  return open_regular_file(file, kInputFileLimit, f) && f.read_head(8, magic) && magic.size() == 8 &&
         std::memcmp(magic.data(), "LODHLOD\n", 8) == 0;
}

int inspect_hlod_command(const InspectArgs& args) {
  if (!args.export_dir.empty()) {
    std::fprintf(stderr, "lod inspect: --export writes .lod levels; %s is an .hlod file\n", printable(args.file).c_str());
    return 1;
  }
  if (args.verify) return verify_hlod(args);
  HlodTree tree;
  if (Status st = read_hlod_tree(args.file, tree); !st) {
    std::fprintf(stderr, "lod inspect: %s\n", printable(st.message).c_str());
    return 1;
  }
  std::error_code size_error;
  const auto bytes = std::filesystem::file_size(args.file, size_error);
  char hash[32];
  std::snprintf(hash, sizeof hash, "%016llx", (unsigned long long)tree.source_hash);
  if (args.json) {
    nlohmann::json j;
    j["file"] = args.file;
    j["name"] = tree.name;
    j["version"] = kHlodAssetVersion;
    j["bytes"] = bytes;
    j["source_hash"] = hash;
    j["source_triangles"] = tree.source_triangles;
    j["min_verts"] = tree.min_verts;
    j["box"] = {{"center", {tree.box_center[0], tree.box_center[1], tree.box_center[2]}}, {"half", tree.box_half}};
    j["texcoords"] = tree.uvs;
    j["texcoords1"] = tree.uvs1;
    j["colors"] = tree.colors;
    j["texture_base"] = tree.texture_base;
    j["materials"] = materials_json(tree);
    j["images"] = images_json(tree.images);
    j["nodes"] = nlohmann::json::array();
    for (size_t i = 0; i < tree.nodes.size(); ++i) j["nodes"].push_back(node_json(tree, i));
    std::printf("%s\n", j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
    return 0;
  }
  size_t leaves = 0;
  for (const HlodNode& n : tree.nodes) leaves += n.leaf();
  std::printf("%s: model '%s', hlod v%u, %llu bytes, source hash %s, %llu source triangles, min_verts %u\n",
              printable(args.file).c_str(), printable(tree.name).c_str(), kHlodAssetVersion, (unsigned long long)bytes,
              hash, (unsigned long long)tree.source_triangles, tree.min_verts);
  std::printf("%zu nodes, %zu leaves; root cube centre (%g, %g, %g), half size %g\n", tree.nodes.size(), leaves,
              tree.box_center[0], tree.box_center[1], tree.box_center[2], tree.box_half);
  print_materials(tree);
  if (!tree.images.empty()) print_images(tree.images);
  print_depth_table(tree);
  std::printf("top of the tree (layers: triangles/error):\n");
  print_tree_top(tree, 0, 2);
  return 0;
}

}  // namespace lod::cli
