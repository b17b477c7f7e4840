// 3D Tiles 1.1 export of an .hlod file (OGC 3D Tiles 1.1, "Tile", "Bounding volumes",
// "Refinement", "glTF transforms"):
//
//   resolve_destination -> check_destination -> open the .hlod -> make_staging
//   -> write_node_contents (each node read, its ranges checked, its layers and patch as GLBs)
//   -> subtree_boxes (bottom-up) -> tileset_json -> tileset.json -> publish (rename into DIR)
#include "preprocess/tiles3d_export.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "preprocess/gltf_write.h"
#include "preprocess/texture_uri.h"
#include "runtime/embedded_image.h"
#include "runtime/file_write.h"
#include "runtime/hlod_asset.h"

namespace lod {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kTilesFolder = "tiles";
constexpr const char* kTexturesFolder = "textures";

// With shared images: each image (a file, or one the tree carries) written once into the staging
// folder's textures/, named by the order it was first met, and the URI a tile's GLB names it by.
struct SharedImages {
  struct Written {
    fs::path file;                       // the source file, or empty for
    const EmbeddedImage* embedded;       // one of the tree's own images
    std::string uri;                     // from tiles/
  };
  fs::path staging;
  std::vector<Written> written;
  TilesetExportReport* rep = nullptr;
  std::string uri_of(const fs::path& file, const EmbeddedImage* embedded) {
    for (const Written& w : written)
      if (w.file == file && w.embedded == embedded) return w.uri;
    std::error_code ec;
    fs::create_directories(staging / kTexturesFolder, ec);
    // A tree's image is written with the extension of its type (its bytes were checked).
    const std::string name = "image" + std::to_string(written.size()) +
                             (embedded ? std::string(file_extension(embedded->type)) : file.extension().string());
    const fs::path to = staging / kTexturesFolder / name;
    if (ec) return {};  // embedded instead
    if (embedded ? !write_file_atomic(to, embedded->bytes) : (!fs::copy_file(file, to, ec) || ec)) return {};
    rep->bytes += fs::file_size(to, ec);
    ++rep->shared_images;
    written.push_back({file, embedded, std::string("../") + kTexturesFolder + "/" + name});
    return written.back().uri;
  }
};

// An axis-aligned box in the model's (glTF, y-up) coordinates, in double so that the written
// centre and half sizes reproduce the float extremes.
struct Box {
  double lo[3] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                  std::numeric_limits<double>::infinity()};
  double hi[3] = {-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                  -std::numeric_limits<double>::infinity()};
  bool empty() const { return !(lo[0] <= hi[0]); }
  void add_point(const float* p) {
    for (int c = 0; c < 3; ++c) lo[c] = std::min(lo[c], double(p[c])), hi[c] = std::max(hi[c], double(p[c]));
  }
  void add(const Box& b) {
    if (b.empty()) return;
    for (int c = 0; c < 3; ++c) lo[c] = std::min(lo[c], b.lo[c]), hi[c] = std::max(hi[c], b.hi[c]);
  }
  double diagonal() const {
    if (empty()) return 0;
    double s = 0;
    for (int c = 0; c < 3; ++c) s += (hi[c] - lo[c]) * (hi[c] - lo[c]);
    return std::sqrt(s);
  }
};

// What was written for one node: a GLB per layer with triangles, one for its boundary patch.
struct NodeContent {
  std::string layer_uri[kHlodMaxLayers];  // empty: the layer has no triangles
  Box layer_box[kHlodMaxLayers];
  std::string boundary_uri;
  Box boundary_box;
  Box subtree;  // everything the node and its descendants draw
};

// ---- destination --------------------------------------------------------------------------

// DIR as an absolute path without a trailing separator ("out/" and "out/." name "out").
Status resolve_destination(const fs::path& dir, fs::path& out) {
  std::error_code ec;
  fs::path p = fs::absolute(dir, ec).lexically_normal();
  if (ec) return Status::error(dir.string() + ": cannot be resolved (" + ec.message() + ")");
  if (p.filename().empty()) p = p.parent_path();
  if (p.filename().empty() || p == p.root_path() || p.filename() == "..")
    return Status::error(dir.string() + ": name a folder to write the tileset into");
  out = p;
  return Status::success();
}

// A missing or empty DIR is written; a non-empty one only with `replace` and only when it
// holds an earlier export's tileset.json (never an arbitrary folder).
Status check_destination(const fs::path& dir, bool replace, bool& replaces_earlier) {
  replaces_earlier = false;
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(dir, ec);
  if (st.type() == fs::file_type::not_found) return Status::success();
  if (ec) return Status::error(dir.string() + ": cannot be examined (" + ec.message() + ")");
  if (st.type() == fs::file_type::symlink)
    return Status::error(dir.string() + ": is a symbolic link; name the folder itself");
  if (st.type() != fs::file_type::directory) return Status::error(dir.string() + ": exists and is not a folder");
  const bool empty = fs::is_empty(dir, ec);
  if (ec) return Status::error(dir.string() + ": cannot be listed (" + ec.message() + ")");
  if (empty) return Status::success();
  if (!replace) return Status::error(dir.string() + ": is not empty (--force replaces an earlier export)");
  if (!fs::is_regular_file(fs::symlink_status(dir / "tileset.json", ec)))
    return Status::error(dir.string() + ": is not empty and holds no tileset.json; not replacing it");
  replaces_earlier = true;
  return Status::success();
}

// ".<DIR's name><suffix>" beside DIR (appended piecewise: GCC 12 warns falsely on "." + s).
fs::path hidden_sibling(const fs::path& dir, const std::string& suffix) {
  std::string name(1, '.');
  name += dir.filename().string();
  name += suffix;
  return dir.parent_path() / name;
}

// A fresh hidden folder beside DIR (same file system, so the final rename is atomic).
Status make_staging(const fs::path& dir, fs::path& staging) {
  std::error_code ec;
  fs::create_directories(dir.parent_path(), ec);
  if (ec) return Status::error(dir.parent_path().string() + ": cannot be created (" + ec.message() + ")");
  for (int attempt = 0; attempt < 100; ++attempt) {
    const fs::path p = hidden_sibling(dir, ".partial-" + std::to_string(::getpid()) + "-" + std::to_string(attempt));
    if (fs::create_directory(p, ec)) {
      fs::create_directory(p / kTilesFolder, ec);
      if (ec) {
        fs::remove_all(p, ec);
        return Status::error(p.string() + ": cannot be created (" + ec.message() + ")");
      }
      staging = p;
      return Status::success();
    }
    if (ec) return Status::error(p.string() + ": cannot be created (" + ec.message() + ")");
  }
  return Status::error(dir.string() + ": no staging folder could be made beside it");
}

// Renames the complete staging folder to DIR. An earlier export is moved aside first and
// removed only once the new one is in place (put back if that fails).
Status publish(const fs::path& staging, const fs::path& dir, bool replaces_earlier) {
  std::error_code ec;
  if (!replaces_earlier) {
    fs::rename(staging, dir, ec);  // replaces a missing or empty DIR
    if (ec) return Status::error(dir.string() + ": the tileset cannot be moved into place (" + ec.message() + ")");
    return Status::success();
  }
  const fs::path old = hidden_sibling(dir, ".old-" + std::to_string(::getpid()));
  fs::rename(dir, old, ec);
  if (ec) return Status::error(dir.string() + ": the earlier export cannot be moved aside (" + ec.message() + ")");
  fs::rename(staging, dir, ec);
  if (ec) {
    std::error_code back;
    fs::rename(old, dir, back);
    return Status::error(dir.string() + ": the tileset cannot be moved into place (" + ec.message() + ")");
  }
  fs::remove_all(old, ec);
  return Status::success();
}

// ---- contents -----------------------------------------------------------------------------

// A layer's or the patch's range inside the payload's arrays, checked again here.
Status check_range(const std::string& what, const LodLevel& r, const HlodPayload& p) {
  const uint64_t vertices = p.positions.size() / 3, indices = p.indices.size();
  if (uint64_t(r.first_vertex) + r.vertex_count > vertices || uint64_t(r.first_index) + r.index_count > indices ||
      r.index_count % 3 != 0)
    return Status::error(what + ": range (vertices " + std::to_string(r.first_vertex) + "+" +
                         std::to_string(r.vertex_count) + ", indices " + std::to_string(r.first_index) + "+" +
                         std::to_string(r.index_count) + ") is outside the node's arrays");
  return Status::success();
}

Status check_payload(const std::string& what, const HlodNode& n, const HlodPayload& p) {
  if (p.layers.size() != n.layer_count || p.layers.empty() || p.layers.size() > kHlodMaxLayers)
    return Status::error(what + ": " + std::to_string(p.layers.size()) + " layers, the tree says " +
                         std::to_string(n.layer_count));
  const size_t vertices = p.positions.size() / 3;
  if (p.positions.size() % 3 != 0 || p.normals.size() != p.positions.size() ||
      (!p.uvs.empty() && p.uvs.size() != 2 * vertices) || (!p.uvs1.empty() && p.uvs1.size() != 2 * vertices) ||
      (!p.colors.empty() && p.colors.size() != 4 * vertices))
    return Status::error(what + ": positions, normals, uvs and colours do not match");
  for (size_t k = 0; k < p.layers.size(); ++k)
    if (Status s = check_range(what + " layer " + std::to_string(k), p.layers[k], p); !s) return s;
  return check_range(what + " boundary", p.boundary, p);
}

// A tree material for the GLB writer, its images the tree's own (embedded:<k>) or files resolved
// against the texture base (one missing at export time is left out by the writer and said).
GltfMaterialView gltf_material(const ChainMaterial& m, const HlodTree& tree) {
  return gltf_material_view(m, tree.images, tree.texture_base);
}

// The range's runs as primitives, with only the materials they use (renumbered in order of
// first use, so that no GLB carries unused materials); ids were checked by the reader and are
// checked again against the tree's materials here.
Status add_surfaces(const std::string& what, const HlodTree& tree, std::span<const LevelSubmesh> runs,
                    GltfMeshView& view) {
  std::vector<int32_t> renumbered(tree.materials.size(), -1);
  for (const LevelSubmesh& s : runs) {
    int32_t id = -1;
    if (s.material >= 0) {
      if (size_t(s.material) >= tree.materials.size())
        return Status::error(what + ": a material run names material " + std::to_string(s.material) + " of " +
                             std::to_string(tree.materials.size()));
      int32_t& slot = renumbered[size_t(s.material)];
      if (slot < 0) {
        slot = int32_t(view.materials.size());
        view.materials.push_back(gltf_material(tree.materials[size_t(s.material)], tree));
      }
      id = slot;
    }
    view.submeshes.push_back({s.first_index, s.index_count, id});
  }
  return Status::success();
}

// One GLB of the range `r` (range index `range`): writes it (unless it has no triangles) and its box.
Status write_range(const fs::path& staging, const std::string& file, const std::string& mesh_name, const HlodTree& tree,
                   uint32_t range, const LodLevel& r, const HlodPayload& p, SharedImages* shared, std::string& uri,
                   Box& box, TilesetExportReport& rep) {
  if (r.index_count == 0) return Status::success();
  GltfMeshView view;
  view.name = mesh_name;
  view.positions = p.positions.data() + 3 * size_t(r.first_vertex);
  view.normals = p.normals.data() + 3 * size_t(r.first_vertex);
  view.uvs = p.uvs.empty() ? nullptr : p.uvs.data() + 2 * size_t(r.first_vertex);
  view.uvs1 = p.uvs1.empty() ? nullptr : p.uvs1.data() + 2 * size_t(r.first_vertex);
  view.colors = p.colors.empty() ? nullptr : p.colors.data() + 4 * size_t(r.first_vertex);
  view.vertex_count = r.vertex_count;
  view.indices = p.indices.data() + r.first_index;
  view.index_count = r.index_count;
  view.notes = &rep.notes;
  if (shared) view.image_uri = [shared](const fs::path& image, const EmbeddedImage* embedded) {
      return shared->uri_of(image, embedded);
    };
  if (Status s = add_surfaces(mesh_name, tree, hlod_range_runs(p, range), view); !s) return s;
  const std::string rel = std::string(kTilesFolder) + "/" + file;
  if (Status s = save_gltf(staging / rel, view); !s) return s;
  for (size_t v = 0; v < r.vertex_count; ++v) box.add_point(view.positions + 3 * v);
  std::error_code ec;
  rep.bytes += fs::file_size(staging / rel, ec);
  ++rep.glb_files;
  uri = rel;
  return Status::success();
}

Status write_node_contents(const HlodFile& file, const HlodTree& tree, const std::string& what, const fs::path& staging,
                           bool shared_images, std::vector<NodeContent>& out, TilesetExportReport& rep) {
  out.assign(tree.nodes.size(), {});
  SharedImages shared{staging, {}, &rep};
  for (size_t i = 0; i < tree.nodes.size(); ++i) {
    const HlodNode& n = tree.nodes[i];
    const std::string node_what = what + ": node " + std::to_string(i);
    HlodPayload p;
    if (Status s = file.read_node(n, p); !s) return s;
    if (Status s = check_payload(node_what, n, p); !s) return s;
    NodeContent& c = out[i];
    const std::string id = std::to_string(i);
    for (size_t k = 0; k < p.layers.size(); ++k)
      if (Status s = write_range(staging, id + "-" + std::to_string(k) + ".glb", "node " + id + " layer " + std::to_string(k),
                                 tree, uint32_t(k), p.layers[k], p, shared_images ? &shared : nullptr, c.layer_uri[k],
                                 c.layer_box[k], rep);
          !s)
        return s;
    if (Status s = write_range(staging, id + "-boundary.glb", "node " + id + " boundary", tree, uint32_t(p.layers.size()),
                               p.boundary, p, shared_images ? &shared : nullptr, c.boundary_uri, c.boundary_box, rep);
        !s)
      return s;
  }
  return Status::success();
}

// Children come after their parent in breadth-first order: one backward sweep unions every
// subtree. The tree's links are checked again here before they are followed.
Status subtree_boxes(const HlodTree& tree, const std::string& what, std::vector<NodeContent>& c) {
  for (size_t i = tree.nodes.size(); i-- > 0;) {
    const HlodNode& n = tree.nodes[i];
    if (n.child_count && (n.first_child <= i || uint64_t(n.first_child) + n.child_count > tree.nodes.size()))
      return Status::error(what + ": node " + std::to_string(i) + " has children outside the tree");
    for (uint32_t k = 0; k < n.layer_count && k < kHlodMaxLayers; ++k) c[i].subtree.add(c[i].layer_box[k]);
    c[i].subtree.add(c[i].boundary_box);
    for (uint32_t ch = 0; ch < n.child_count; ++ch) c[i].subtree.add(c[n.first_child + ch].subtree);
  }
  return Status::success();
}

// ---- tileset.json -------------------------------------------------------------------------

// The box in the tileset's z-up frame: glTF (x, y, z) is 3D Tiles (x, -z, y). `pad` keeps
// flat boxes from having a zero axis and absorbs rounding of centre +- half.
json box_json(const Box& b, double pad) {
  double c[3], h[3];
  for (int k = 0; k < 3; ++k) c[k] = 0.5 * (b.lo[k] + b.hi[k]), h[k] = 0.5 * (b.hi[k] - b.lo[k]) + pad;
  return {{"box", {c[0], -c[2], c[1], h[0], 0.0, 0.0, 0.0, h[2], 0.0, 0.0, 0.0, h[1]}}};
}

// The node's chain, coarsest layer first; its finest layer's tile has the children's chains
// and the boundary patch as children.
json node_tiles(const HlodTree& tree, const std::vector<NodeContent>& contents, size_t i, double pad, size_t& tiles) {
  const HlodNode& n = tree.nodes[i];
  const NodeContent& c = contents[i];
  json children = json::array();
  for (uint32_t ch = 0; ch < n.child_count; ++ch)
    if (!contents[n.first_child + ch].subtree.empty())
      children.push_back(node_tiles(tree, contents, n.first_child + ch, pad, tiles));
  if (!c.boundary_uri.empty()) {
    children.push_back({{"boundingVolume", box_json(c.boundary_box, pad)},
                        {"geometricError", 0.0},
                        {"content", {{"uri", c.boundary_uri}, {"boundingVolume", box_json(c.boundary_box, pad)}}}});
    ++tiles;
  }
  json below;
  for (uint32_t k = 0; k < n.layer_count && k < kHlodMaxLayers; ++k) {
    json t = {{"boundingVolume", box_json(c.subtree, pad)}, {"geometricError", double(n.layers[k].error)}};
    if (!c.layer_uri[k].empty())
      t["content"] = {{"uri", c.layer_uri[k]}, {"boundingVolume", box_json(c.layer_box[k], pad)}};
    if (!below.is_null()) t["children"] = json::array({std::move(below)});
    else if (!children.empty()) t["children"] = std::move(children);
    below = std::move(t);
    ++tiles;
  }
  return below;
}

json tileset_json(const HlodTree& tree, const std::vector<NodeContent>& contents, TilesetExportReport& rep) {
  const Box& all = contents[0].subtree;
  const double pad = 1e-6 * std::max(all.diagonal(), 1e-30) + 1e-12;
  json root = node_tiles(tree, contents, 0, pad, rep.tiles);
  root["refine"] = "REPLACE";
  rep.root_error = root["geometricError"].get<double>();
  char hash[32];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(tree.source_hash));
  // Drawing nothing misses the whole model: the tileset's error is its size.
  const double nothing = std::max(all.diagonal(), rep.root_error);
  return {{"asset", {{"version", "1.1"}, {"tilesetVersion", hash}, {"extras", {{"generator", "lodkit"}, {"model", tree.name}}}}},
          {"geometricError", nothing},
          {"root", std::move(root)}};
}

Status export_into(const fs::path& hlod_file, const fs::path& staging, bool shared_images, TilesetExportReport& rep) {
  const std::string what = hlod_file.string();
  HlodFile file;
  HlodTree tree;
  if (Status s = file.open(hlod_file, tree); !s) return s;
  if (tree.nodes.empty()) return Status::error(what + ": the tree has no nodes");
  rep.nodes = tree.nodes.size();
  std::vector<NodeContent> contents;
  if (Status s = write_node_contents(file, tree, what, staging, shared_images, contents, rep); !s) return s;
  if (Status s = subtree_boxes(tree, what, contents); !s) return s;
  if (contents[0].subtree.empty()) return Status::error(what + ": no node has any triangles");
  const std::string text = tileset_json(tree, contents, rep).dump(-1, ' ', false, json::error_handler_t::replace);
  rep.bytes += text.size();
  return write_file_atomic(staging / "tileset.json", text);
}

}  // namespace

Status export_3d_tiles(const fs::path& hlod_file, const fs::path& dir, const TilesetExportOptions& options,
                       TilesetExportReport* report) {
  fs::path target;
  if (Status s = resolve_destination(dir, target); !s) return s;
  bool replaces_earlier = false;
  if (Status s = check_destination(target, options.replace, replaces_earlier); !s) return s;
  fs::path staging;
  if (Status s = make_staging(target, staging); !s) return s;
  TilesetExportReport rep;
  Status s = export_into(hlod_file, staging, options.shared_images, rep);
  if (s) s = publish(staging, target, replaces_earlier);
  if (!s) {
    std::error_code ec;
    fs::remove_all(staging, ec);
    return s;
  }
  if (report) *report = rep;
  return Status::success();
}

}  // namespace lod
