// The .hlod file, version 3. All integers and floats little-endian; sections 8-byte aligned.
//
//   head:
//     magic "LODHLOD\n" (8) | u32 version | u32 head bytes H (everything before the head checksum)
//     u64 source_hash | u64 source_triangles | f32 box centre xyz, f32 box half (the root cube)
//     u64 vertices (all nodes' layers and patches) | u64 boundary triangles (all patches)
//     u32 material count | u32 min_verts | u32 node count | u32 inner node count
//     u32 name bytes | u32 flags (bit 0: the payloads have uvs (TEXCOORD_0), bit 1: colours
//     (COLOR_0), bit 2: a second uv set (TEXCOORD_1); the rest 0) |
//     u32 materials section bytes M | u32 images section bytes I | name
//     materials (M bytes, 0 = none described): the .lod's MATL section (runtime/material_section.h)
//       with the texture base and no submeshes; when present, exactly `material count` of them
//       (a subtree entry of the distributed bake carries the count alone)
//     images (I bytes, 0 = none; only with materials): the .lod's IMGS section, the PNG/JPEG
//       files the materials embed ("embedded:<k>" names image k), 8-byte aligned after M
//     OctreeCode: one byte per inner node, breadth-first: bit i = octant i is non-empty
//     NodeDescription: one bit per node but the root, breadth-first: 1 = leaf, 0 = inner
//     node records: 80 bytes each, 12 more with uv1 and 12 more with colours (see put_record),
//       breadth-first
//     offset table: u64 offset, u64 size per node
//   u64 head checksum = hash_bytes(bytes [0, H))
//   payloads, one per node in node order, back to back up to the end of the file: per layer
//   positions (3 f32 per vertex), normals (same), uvs (2 f32 per vertex, with the flag), uv1
//   (2 f32 per vertex, with its flag), colours (4 f32 linear RGBA per vertex, with theirs),
//   indices (3 u32 per triangle, layer-local), then the boundary patch the same way, then the
//   node's material runs (16 bytes each: u32 range (layer, or layer count for the patch),
//   u32 first index (range-local), u32 index count, i32 material), then u64 checksum =
//   hash_bytes(the payload before it)
//
// Version 2 is version 3 without the colour and uv1 flags (a file without them differs only in
// its version word) and is read as such. Version 1 (positions and normals only, no materials) is
// refused with a message to rebake.
// The tree's structure (parents, child ranges, depths, cells) is not stored: it follows from
// the bits and the root cube, as Zhou and Tian rebuild their octree from OctreeCode and NodeDescription.
#include "runtime/hlod_asset.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <numeric>

#include "runtime/byte_order.h"
#include "runtime/file_write.h"
#include "runtime/lod_asset.h"  // hash_bytes
#include "runtime/lod_chain.h"
#include "runtime/material_section.h"
#include "runtime/regular_file.h"
#include "runtime/vertex_tree.h"  // kMaxTreeMagnitude

namespace lod {
namespace {

constexpr char kMagic[8] = {'L', 'O', 'D', 'H', 'L', 'O', 'D', '\n'};
constexpr uint64_t kFixedBytes = 96;
constexpr uint64_t kRecordBytes = 80;
constexpr uint64_t kRunBytes = 16;
constexpr uint32_t kFlagUvs = 1;
constexpr uint32_t kFlagColors = 2;
constexpr uint32_t kFlagUvs1 = 4;
constexpr uint32_t kOldestReadable = 2;  // version 2: no colour or uv1 flags
constexpr uint64_t kOffsetBytes = 16;
constexpr uint64_t kChecksumBytes = 8;

uint64_t align8(uint64_t v) { return (v + 7) & ~uint64_t{7}; }

using detail::load_f32;
using detail::load_u32;
using detail::load_u64;

using Writer = detail::ByteWriter;

Status refuse(const std::string& what, const std::string& why) { return Status::error(what + ": " + why); }

// A record's size: the per-layer errors of each attribute the tree has follow the 80 bytes.
uint64_t record_bytes(uint32_t flags) {
  return kRecordBytes + ((flags & kFlagUvs1) ? 4 * kHlodMaxLayers : 0) + ((flags & kFlagColors) ? 4 * kHlodMaxLayers : 0);
}

uint32_t tree_flags(const HlodTree& t) {
  return (t.uvs ? kFlagUvs : 0) | (t.colors ? kFlagColors : 0) | (t.uvs1 ? kFlagUvs1 : 0);
}

// The head's size from its counts (all u32, so no overflow in u64).
uint64_t head_bytes(uint64_t name_bytes, uint64_t material_bytes, uint64_t image_bytes, uint64_t nodes, uint64_t inner,
                    uint32_t flags) {
  const uint64_t description = nodes > 0 ? (nodes - 1 + 7) / 8 : 0;
  return align8(kFixedBytes + name_bytes) + align8(material_bytes) + align8(image_bytes) + align8(inner) +
         align8(description) +
         nodes * (record_bytes(flags) + kOffsetBytes);
}

// A payload holds exactly what it takes in memory, plus its checksum.
uint64_t payload_data_bytes(const HlodNode& n) { return hlod_resident_bytes(n); }

void put_record(Writer& w, const HlodNode& n) {
  w.u8(n.layer_count);
  w.u8(0), w.u8(0), w.u8(0);
  w.u32(n.boundary_triangles);
  w.u32(n.boundary_vertices);
  w.f32(n.bounds.center[0]), w.f32(n.bounds.center[1]), w.f32(n.bounds.center[2]), w.f32(n.bounds.radius);
  for (uint32_t k = 0; k < kHlodMaxLayers; ++k) {
    const bool used = k < n.layer_count;
    w.u32(used ? n.layers[k].triangles : 0);
    w.u32(used ? n.layers[k].vertices : 0);
    w.f32(used ? n.layers[k].error : 0.0f);
  }
  for (uint32_t k = 0; k < kHlodMaxLayers; ++k) w.f32(k < n.layer_count ? n.layers[k].uv_error : 0.0f);
  w.u32(n.material_runs);
  if (n.uvs1)
    for (uint32_t k = 0; k < kHlodMaxLayers; ++k) w.f32(k < n.layer_count ? n.layers[k].uv1_error : 0.0f);
  if (n.colors)
    for (uint32_t k = 0; k < kHlodMaxLayers; ++k) w.f32(k < n.layer_count ? n.layers[k].color_error : 0.0f);
}

bool finite_in_range(float v) { return std::isfinite(v) && std::fabs(v) <= kMaxTreeMagnitude; }

// Per-layer attribute errors (`name`: uv, uv1, colour) at p: finite distances within the layer
// count, zero beyond it.
bool get_attribute_errors(const uint8_t* p, HlodNode& n, float HlodLayerInfo::*error, const char* name, std::string& why) {
  for (uint32_t k = 0; k < kHlodMaxLayers; ++k) {
    const float e = load_f32(p + 4 * k);
    if (k >= n.layer_count ? std::bit_cast<uint32_t>(e) != 0 : !(finite_in_range(e) && e >= 0))
      return why = "layer " + std::to_string(k) + " " + name +
                   " error is not a finite distance (or set beyond the layer count)",
             false;
    n.layers[k].*error = e;
  }
  return true;
}

// One record's own fields (the attribute errors that `flags` says follow); "node N: ..." on failure.
bool get_record(const uint8_t* p, uint32_t flags, HlodNode& n, std::string& why) {
  n.layer_count = p[0];
  if (p[1] || p[2] || p[3]) return why = "reserved bytes are not zero", false;
  n.boundary_triangles = load_u32(p + 4);
  n.boundary_vertices = load_u32(p + 8);
  for (int k = 0; k < 3; ++k) n.bounds.center[k] = load_f32(p + 12 + 4 * k);
  n.bounds.radius = load_f32(p + 24);
  if (n.layer_count < 1 || n.layer_count > kHlodMaxLayers)
    return why = "layer count " + std::to_string(n.layer_count) + " is outside 1.." + std::to_string(kHlodMaxLayers), false;
  for (uint32_t k = 0; k < kHlodMaxLayers; ++k) {
    const uint8_t* l = p + 28 + 12 * k;
    HlodLayerInfo& info = n.layers[k];
    info.triangles = load_u32(l);
    info.vertices = load_u32(l + 4);
    info.error = load_f32(l + 8);
    const std::string name = "layer " + std::to_string(k);
    if (k >= n.layer_count) {
      if (info.triangles || info.vertices || std::bit_cast<uint32_t>(info.error))
        return why = name + " is beyond the layer count but not empty", false;
      continue;
    }
    if (info.triangles == 0) return why = name + " has no triangles", false;
    if (info.vertices == 0 || info.vertices > 3ull * info.triangles)
      return why = name + " has " + std::to_string(info.vertices) + " vertices for " + std::to_string(info.triangles) +
                   " triangles",
             false;
    if (!finite_in_range(info.error) || info.error < 0)
      return why = name + " error " + std::to_string(info.error) + " is not a finite distance", false;
    if (k > 0 && !(info.triangles < n.layers[k - 1].triangles))
      return why = name + " has " + std::to_string(info.triangles) + " triangles, not fewer than the layer before", false;
    if (k > 0 && info.error < n.layers[k - 1].error) return why = name + " error is below the finer layer's", false;
  }
  if (!get_attribute_errors(p + 64, n, &HlodLayerInfo::uv_error, "uv", why)) return false;
  n.material_runs = load_u32(p + 76);
  const uint8_t* more = p + kRecordBytes;
  if (flags & kFlagUvs1) {
    if (!get_attribute_errors(more, n, &HlodLayerInfo::uv1_error, "uv1", why)) return false;
    more += 4 * kHlodMaxLayers;
  }
  if ((flags & kFlagColors) && !get_attribute_errors(more, n, &HlodLayerInfo::color_error, "colour", why)) return false;
  if (n.boundary_vertices > 3ull * n.boundary_triangles || (n.boundary_triangles > 0 && n.boundary_vertices == 0))
    return why = "boundary has " + std::to_string(n.boundary_vertices) + " vertices for " +
                 std::to_string(n.boundary_triangles) + " triangles",
           false;
  for (int k = 0; k < 3; ++k)
    if (!finite_in_range(n.bounds.center[k])) return why = "bounding sphere centre is not finite", false;
  if (!finite_in_range(n.bounds.radius) || n.bounds.radius < 0) return why = "bounding sphere radius is invalid", false;
  return true;
}

// Parents, child ranges, depths and cells from the bits, breadth-first (Zhou and Tian's rebuild).
bool rebuild_structure(const uint8_t* code, uint32_t inner, const uint8_t* description, HlodTree& t, std::string& why) {
  const uint32_t count = uint32_t(t.nodes.size());
  HlodNode& root = t.nodes[0];
  root.parent = -1;
  root.depth = 0;
  for (int k = 0; k < 3; ++k) root.box_center[k] = t.box_center[k];
  root.box_half = t.box_half;
  std::vector<uint8_t> is_inner(count, 0);
  is_inner[0] = inner > 0;
  uint32_t next = 1, codes = 0, described = 0, inner_seen = is_inner[0];
  for (uint32_t i = 0; i < count; ++i) {
    if (i >= next) return why = "node " + std::to_string(i) + " is not reached from the root", false;
    HlodNode& n = t.nodes[i];
    if (!is_inner[i]) continue;
    if (codes >= inner) return why = "more inner nodes than OctreeCode bytes", false;
    const uint8_t mask = code[codes++];
    if (mask == 0) return why = "node " + std::to_string(i) + " is inner but its OctreeCode has no child", false;
    if (n.depth >= kHlodMaxDepth)
      return why = "node " + std::to_string(i) + " has children below depth " + std::to_string(kHlodMaxDepth), false;
    n.child_mask = mask;
    n.first_child = next;
    n.child_count = uint8_t(std::popcount(mask));
    for (int o = 0; o < 8; ++o) {
      if (!((mask >> o) & 1)) continue;
      if (next >= count) return why = "OctreeCode names more children than the " + std::to_string(count) + " nodes", false;
      HlodNode& c = t.nodes[next];
      c.parent = int32_t(i);
      c.depth = uint8_t(n.depth + 1);
      c.box_half = n.box_half / 2;
      for (int k = 0; k < 3; ++k) c.box_center[k] = n.box_center[k] + ((o >> k) & 1 ? c.box_half : -c.box_half);
      const bool leaf = (description[described / 8] >> (described % 8)) & 1;
      ++described;
      is_inner[next] = !leaf;
      inner_seen += !leaf;
      ++next;
    }
  }
  if (next != count || codes != inner || inner_seen != inner)
    return why = "OctreeCode and NodeDescription describe " + std::to_string(next) + " nodes and " +
                 std::to_string(inner_seen) + " inner ones, the header " + std::to_string(count) + " and " +
                 std::to_string(inner),
           false;
  const uint64_t description_bytes = (count - 1 + 7) / 8;
  for (uint64_t b = described; b < 8 * description_bytes; ++b)
    if ((description[b / 8] >> (b % 8)) & 1) return why = "NodeDescription padding bits are not zero", false;
  for (uint32_t i = 0; i < count; ++i)
    if (!is_inner[i]) t.nodes[i].first_child = 0, t.nodes[i].child_count = 0, t.nodes[i].child_mask = 0;
  return true;
}

// What the tree says of itself beyond one record: leaves have no patch, errors grow upwards.
bool check_tree(const HlodTree& t, std::string& why) {
  for (size_t i = 1; i < t.nodes.size(); ++i) {
    const HlodNode& n = t.nodes[i];
    const HlodNode& p = t.nodes[size_t(n.parent)];
    if (p.layers[0].error < n.layers[n.layer_count - 1].error)
      return why = "node " + std::to_string(i) + ": coarsest error " + std::to_string(n.layers[n.layer_count - 1].error) +
                   " exceeds its parent's finest " + std::to_string(p.layers[0].error) + " (errors must grow upwards)",
             false;
  }
  for (size_t i = 0; i < t.nodes.size(); ++i)
    if (t.nodes[i].leaf() && (t.nodes[i].boundary_triangles || t.nodes[i].boundary_vertices))
      return why = "node " + std::to_string(i) + " is a leaf with a boundary patch", false;
  return true;
}

template <class T>
void get_words(const uint8_t* p, size_t count, T* out) {
  static_assert(sizeof(T) == 4);
  if constexpr (std::endian::native == std::endian::little) {
    if (count) std::memcpy(out, p, count * 4);
  } else {
    for (size_t i = 0; i < count; ++i) out[i] = std::bit_cast<T>(load_u32(p + 4 * i));
  }
}

// One per-vertex attribute column (`per` floats a vertex) of a range, appended to `out` and
// checked finite.
bool get_column(const uint8_t*& p, uint32_t vertices, size_t per, const char* name, std::vector<float>& out,
                std::string& why) {
  const size_t at = out.size();
  out.resize(at + per * size_t(vertices));
  get_words(p, per * size_t(vertices), out.data() + at);
  p += 4 * per * size_t(vertices);
  for (size_t i = at; i < out.size(); ++i)
    if (!finite_in_range(out[i]))
      return why = "vertex " + std::to_string((i - at) / per) + " has a non-finite " + name, false;
  return true;
}

// One range (a layer or the patch): positions, normals, uvs, uv1, colours (each when the node
// has them), indices, each checked. The caller checked the payload's size against the counts.
bool get_range(const uint8_t*& p, uint32_t vertices, uint32_t triangles, const HlodNode& node, HlodPayload& out,
               LodLevel& range, std::string& why) {
  range.first_vertex = uint32_t(out.positions.size() / 3);
  range.vertex_count = vertices;
  range.first_index = uint32_t(out.indices.size());
  range.index_count = 3 * triangles;
  range.level = level_of_triangles(triangles);
  const size_t v0 = out.positions.size(), i0 = out.indices.size();
  out.positions.resize(v0 + 3 * size_t(vertices));
  out.normals.resize(v0 + 3 * size_t(vertices));
  out.indices.resize(i0 + 3 * size_t(triangles));
  get_words(p, 3 * size_t(vertices), out.positions.data() + v0);
  p += 12 * size_t(vertices);
  get_words(p, 3 * size_t(vertices), out.normals.data() + v0);
  p += 12 * size_t(vertices);
  for (size_t i = v0; i < out.positions.size(); ++i)
    if (!finite_in_range(out.positions[i]) || !finite_in_range(out.normals[i]))
      return why = "vertex " + std::to_string((i - v0) / 3) + " is not finite", false;
  if (node.uvs && !get_column(p, vertices, 2, "uv", out.uvs, why)) return false;
  if (node.uvs1 && !get_column(p, vertices, 2, "uv1", out.uvs1, why)) return false;
  if (node.colors && !get_column(p, vertices, 4, "colour", out.colors, why)) return false;
  get_words(p, 3 * size_t(triangles), out.indices.data() + i0);
  p += 12 * size_t(triangles);
  for (size_t i = i0; i < out.indices.size(); ++i)
    if (out.indices[i] >= vertices)
      return why = "triangle " + std::to_string((i - i0) / 3) + " references vertex " + std::to_string(out.indices[i]) +
                   " of " + std::to_string(vertices),
             false;
  return true;
}

// The node's material runs: in range order, each range's covering its indices back to back in
// whole triangles, every material below `materials` (or -1). A range with triangles has runs.
bool get_runs(const uint8_t* p, const HlodNode& node, uint32_t materials, HlodPayload& out, std::string& why) {
  out.runs.resize(node.material_runs);
  const uint32_t ranges = uint32_t(out.layers.size()) + 1;
  uint32_t range = 0;
  uint64_t covered = 0;
  auto range_count = [&](uint32_t r) { return r < out.layers.size() ? out.layers[r].index_count : out.boundary.index_count; };
  auto close_ranges_before = [&](uint32_t r) {  // every range before r fully covered
    for (; range < r; ++range, covered = 0)
      if (covered != range_count(range))
        return why = "material runs cover " + std::to_string(covered) + " of range " + std::to_string(range) + "'s " +
                     std::to_string(range_count(range)) + " indices",
               false;
    return true;
  };
  for (uint32_t i = 0; i < node.material_runs; ++i) {
    LevelSubmesh& s = out.runs[i];
    s.level = load_u32(p + kRunBytes * i);
    s.first_index = load_u32(p + kRunBytes * i + 4);
    s.index_count = load_u32(p + kRunBytes * i + 8);
    s.material = int32_t(load_u32(p + kRunBytes * i + 12));
    const std::string at = "material run " + std::to_string(i);
    if (s.level >= ranges || s.level < range)
      return why = at + " names range " + std::to_string(s.level) + " out of order or of " + std::to_string(ranges), false;
    if (!close_ranges_before(s.level)) return false;
    if (s.first_index != covered || s.index_count == 0 || s.index_count % 3 != 0 ||
        s.index_count > range_count(range) - covered)
      return why = at + " (indices " + std::to_string(s.first_index) + "+" + std::to_string(s.index_count) +
                   ") does not continue range " + std::to_string(range) + "'s runs in whole triangles",
             false;
    covered += s.index_count;
    if (s.material < -1 || (s.material >= 0 && uint32_t(s.material) >= materials))
      return why = at + " names material " + std::to_string(s.material) + " of " + std::to_string(materials), false;
  }
  if (materials == 0 && node.material_runs == 0) return true;
  return close_ranges_before(ranges);
}

}  // namespace

uint64_t hlod_resident_bytes(const HlodNode& n) {
  const uint64_t per_vertex = detail::hlod_vertex_bytes(n.uvs, n.uvs1, n.colors);
  uint64_t b = 0;
  for (uint32_t k = 0; k < n.layer_count && k < kHlodMaxLayers; ++k)
    b += per_vertex * n.layers[k].vertices + 12ull * n.layers[k].triangles;
  return b + per_vertex * n.boundary_vertices + 12ull * n.boundary_triangles + kRunBytes * n.material_runs;
}

uint64_t hlod_payload_bytes(const HlodNode& n) { return payload_data_bytes(n) + kChecksumBytes; }

std::vector<uint8_t> encode_hlod_head(const HlodTree& tree, std::span<const uint64_t> payload_sizes) {
  Writer w;
  const uint32_t count = uint32_t(tree.nodes.size());
  uint32_t inner = 0;
  uint64_t vertices = 0, boundary = 0;
  for (const HlodNode& n : tree.nodes) {
    inner += !n.leaf();
    for (uint32_t k = 0; k < n.layer_count; ++k) vertices += n.layers[k].vertices;
    vertices += n.boundary_vertices;
    boundary += n.boundary_triangles;
  }
  for (char c : kMagic) w.u8(uint8_t(c));
  w.u32(kHlodAssetVersion);
  w.u32(0);  // head bytes, patched below
  w.u64(tree.source_hash);
  w.u64(tree.source_triangles);
  w.f32(tree.box_center[0]), w.f32(tree.box_center[1]), w.f32(tree.box_center[2]), w.f32(tree.box_half);
  w.u64(vertices);
  w.u64(boundary);
  LodChain surfaces;  // the materials in the .lod's MATL layout, when the tree describes them
  surfaces.materials = tree.materials;
  surfaces.texture_base = tree.texture_base;
  const std::vector<uint8_t> materials = tree.materials.empty() ? std::vector<uint8_t>() : encode_material_section(surfaces);
  const std::vector<uint8_t> images = tree.images.empty() ? std::vector<uint8_t>() : encode_image_section(tree.images);
  w.u32(tree.material_count);
  w.u32(tree.min_verts);
  w.u32(count);
  w.u32(inner);
  w.u32(uint32_t(tree.name.size()));
  w.u32(tree_flags(tree));
  w.u32(uint32_t(materials.size()));
  w.u32(uint32_t(images.size()));
  w.bytes.insert(w.bytes.end(), tree.name.begin(), tree.name.end());
  w.align8();
  w.bytes.insert(w.bytes.end(), materials.begin(), materials.end());
  w.align8();
  w.bytes.insert(w.bytes.end(), images.begin(), images.end());
  w.align8();
  for (const HlodNode& n : tree.nodes)
    if (!n.leaf()) w.u8(n.child_mask);
  w.align8();
  std::vector<uint8_t> description((count > 0 ? count - 1 + 7 : 0) / 8, 0);
  for (uint32_t i = 1; i < count; ++i)
    if (tree.nodes[i].leaf()) description[(i - 1) / 8] |= uint8_t(1u << ((i - 1) % 8));
  w.bytes.insert(w.bytes.end(), description.begin(), description.end());
  w.align8();
  for (HlodNode n : tree.nodes) {
    n.uvs1 = tree.uvs1, n.colors = tree.colors;  // the records' size follows the tree's flags
    put_record(w, n);
  }
  const uint64_t head = w.bytes.size() + kOffsetBytes * count;
  w.patch_u32(12, uint32_t(head));
  uint64_t at = head + kChecksumBytes;
  for (uint32_t i = 0; i < count; ++i) {
    const uint64_t size = i < payload_sizes.size() ? payload_sizes[i] : 0;
    w.u64(at);
    w.u64(size);
    at += size;
  }
  w.u64(hash_bytes(w.bytes.data(), head));
  return std::move(w.bytes);
}

namespace {

uint64_t range_bytes(const HlodPayload& p, const LodLevel& r) {
  const uint64_t per_vertex = detail::hlod_vertex_bytes(!p.uvs.empty(), !p.uvs1.empty(), !p.colors.empty());
  return per_vertex * r.vertex_count + 4ull * r.index_count;
}

// What put_payload appends: the buffer is sized once from these before anything is written.
uint64_t encoded_payload_bytes(const HlodPayload& p) {
  uint64_t b = range_bytes(p, p.boundary) + kRunBytes * p.runs.size() + kChecksumBytes;
  for (const LodLevel& r : p.layers) b += range_bytes(p, r);
  return b;
}

void put_payload(Writer& w, const HlodPayload& p) {
  const size_t start = w.bytes.size();
  auto put_range = [&](const LodLevel& r) {
    w.words(p.positions.data() + 3 * size_t(r.first_vertex), 3 * size_t(r.vertex_count));
    w.words(p.normals.data() + 3 * size_t(r.first_vertex), 3 * size_t(r.vertex_count));
    if (!p.uvs.empty()) w.words(p.uvs.data() + 2 * size_t(r.first_vertex), 2 * size_t(r.vertex_count));
    if (!p.uvs1.empty()) w.words(p.uvs1.data() + 2 * size_t(r.first_vertex), 2 * size_t(r.vertex_count));
    if (!p.colors.empty()) w.words(p.colors.data() + 4 * size_t(r.first_vertex), 4 * size_t(r.vertex_count));
    w.words(p.indices.data() + r.first_index, r.index_count);
  };
  for (const LodLevel& r : p.layers) put_range(r);
  put_range(p.boundary);
  for (const LevelSubmesh& r : p.runs) {
    w.u32(r.level);
    w.u32(r.first_index);
    w.u32(r.index_count);
    w.u32(uint32_t(r.material));
  }
  w.u64(hash_bytes(w.bytes.data() + start, w.bytes.size() - start));
}

}  // namespace

std::vector<uint8_t> encode_hlod_payload(const HlodPayload& p) {
  Writer w;
  w.bytes.reserve(encoded_payload_bytes(p));
  put_payload(w, p);
  return std::move(w.bytes);
}

uint64_t append_hlod_asset(const HlodTree& tree, std::span<const HlodPayload> payloads, std::vector<uint8_t>& out) {
  const size_t count = tree.nodes.size();
  std::vector<uint64_t> sizes(count);
  for (size_t i = 0; i < count; ++i) sizes[i] = encoded_payload_bytes(payloads[i]);
  const std::vector<uint8_t> head = encode_hlod_head(tree, sizes);
  Writer w;
  w.bytes.swap(out);
  const size_t start = w.bytes.size();
  w.bytes.reserve(start + std::accumulate(sizes.begin(), sizes.end(), uint64_t(head.size())));
  w.raw(head.data(), head.size());
  for (size_t i = 0; i < count; ++i) put_payload(w, payloads[i]);
  w.bytes.swap(out);
  return out.size() - start;
}

std::vector<uint8_t> encode_hlod_asset(const HlodTree& tree, std::span<const HlodPayload> payloads) {
  std::vector<uint8_t> bytes;
  append_hlod_asset(tree, payloads, bytes);
  return bytes;
}

Status decode_hlod_tree(std::span<const uint8_t> bytes, uint64_t file_size, const std::string& what, HlodTree& out) {
  const uint8_t* p = bytes.data();
  if (bytes.size() < kFixedBytes || file_size < kFixedBytes + kChecksumBytes)
    return refuse(what, "file is " + std::to_string(std::min<uint64_t>(bytes.size(), file_size)) +
                            " bytes, too short for an .hlod file (truncated?)");
  if (std::memcmp(p, kMagic, 8) != 0) return refuse(what, "not an .hlod file (bad magic bytes)");
  const uint32_t version = load_u32(p + 8);
  if (version < kOldestReadable || version > kHlodAssetVersion)
    return refuse(what, "hlod version " + std::to_string(version) + " is not supported (this build reads versions " +
                            std::to_string(kOldestReadable) + " to " + std::to_string(kHlodAssetVersion) +
                            (version < kOldestReadable ? ", which add texture coordinates and materials" : "") +
                            "); rebake it with lod bake --hlod");
  const uint64_t head = load_u32(p + 12);
  const uint32_t materials = load_u32(p + 64), min_verts = load_u32(p + 68);
  const uint32_t count = load_u32(p + 72), inner = load_u32(p + 76), name_bytes = load_u32(p + 80);
  const uint32_t flags = load_u32(p + 84), material_bytes = load_u32(p + 88), image_bytes = load_u32(p + 92);
  // Counts against the head size before anything is allocated.
  if (head + kChecksumBytes > file_size || head + kChecksumBytes > bytes.size())
    return refuse(what, "truncated: the head needs " + std::to_string(head + kChecksumBytes) + " bytes, the file has " +
                            std::to_string(file_size));
  const uint32_t known_flags = version >= 3 ? kFlagUvs | kFlagColors | kFlagUvs1 : kFlagUvs;
  if (count == 0 || inner >= count ||
      head != head_bytes(name_bytes, material_bytes, image_bytes, count, inner, flags & known_flags))
    return refuse(what, "head of " + std::to_string(head) + " bytes does not match its counts (" + std::to_string(count) +
                            " nodes, " + std::to_string(inner) + " inner, name of " + std::to_string(name_bytes) + ")");
  if (load_u64(p + head) != hash_bytes(p, head)) return refuse(what, "head checksum mismatch (file is corrupted)");
  if (min_verts == 0 || (flags & ~known_flags) != 0 || (image_bytes != 0 && material_bytes == 0))
    return refuse(what, "header fields min_verts / flags / image bytes are invalid");
  if (materials > kMaxMaterials)
    return refuse(what, std::to_string(materials) + " materials, at most " + std::to_string(kMaxMaterials));

  HlodTree t;
  t.source_hash = load_u64(p + 16);
  t.source_triangles = load_u64(p + 24);
  for (int k = 0; k < 3; ++k) t.box_center[k] = load_f32(p + 32 + 4 * k);
  t.box_half = load_f32(p + 44);
  t.min_verts = min_verts;
  for (int k = 0; k < 3; ++k)
    if (!finite_in_range(t.box_center[k])) return refuse(what, "root box centre is not finite");
  if (!finite_in_range(t.box_half) || !(t.box_half > 0)) return refuse(what, "root box size is not positive");
  t.name.assign(reinterpret_cast<const char*>(p + kFixedBytes), name_bytes);
  t.uvs = (flags & kFlagUvs) != 0;
  t.uvs1 = (flags & kFlagUvs1) != 0;
  t.colors = (flags & kFlagColors) != 0;
  t.material_count = materials;
  const uint64_t materials_at = align8(kFixedBytes + name_bytes);
  const uint64_t images_at = materials_at + align8(material_bytes);
  if (material_bytes > 0) {
    LodChain surfaces;  // images first: the materials' embedded:<k> are checked against them
    if (image_bytes > 0)
      if (Status s = decode_image_section({p + images_at, image_bytes}, what, surfaces.images); !s) return s;
    if (Status s = decode_material_section({p + materials_at, material_bytes}, what, surfaces); !s) return s;
    if (surfaces.materials.size() != materials || !surfaces.submeshes.empty())
      return refuse(what, "the header counts " + std::to_string(materials) + " materials, its MATL section holds " +
                              std::to_string(surfaces.materials.size()) + " (and " +
                              std::to_string(surfaces.submeshes.size()) + " runs, which belong in the payloads)");
    t.materials = std::move(surfaces.materials);
    t.texture_base = std::move(surfaces.texture_base);
    t.images = std::move(surfaces.images);
  }
  const uint64_t code_at = images_at + align8(image_bytes);
  const uint64_t description_at = code_at + align8(inner);
  const uint64_t records_at = description_at + align8((uint64_t(count) - 1 + 7) / 8);
  const uint64_t record = record_bytes(flags);
  const uint64_t table_at = records_at + record * count;
  t.nodes.resize(count);
  std::string why;
  for (uint32_t i = 0; i < count; ++i)
    if (!get_record(p + records_at + record * i, flags, t.nodes[i], why))
      return refuse(what, "node " + std::to_string(i) + ": " + why);
  if (!rebuild_structure(p + code_at, inner, p + description_at, t, why)) return refuse(what, "octree: " + why);
  if (!check_tree(t, why)) return refuse(what, why);
  for (uint32_t i = 0; i < count; ++i) {
    HlodNode& n = t.nodes[i];
    n.uvs = t.uvs, n.uvs1 = t.uvs1, n.colors = t.colors;
    // A tree with materials has runs over every range with triangles (at most one per
    // triangle), one without has none.
    uint64_t triangles = n.boundary_triangles, ranges = n.boundary_triangles > 0;
    for (uint32_t k = 0; k < n.layer_count; ++k) triangles += n.layers[k].triangles, ++ranges;
    if (materials == 0 ? n.material_runs != 0 : (n.material_runs < ranges || n.material_runs > triangles))
      return refuse(what, "node " + std::to_string(i) + ": " + std::to_string(n.material_runs) +
                              " material runs for " + std::to_string(ranges) + " ranges of " +
                              std::to_string(triangles) + " triangles and " + std::to_string(materials) + " materials");
  }

  uint64_t vertices = 0, boundary = 0, end = head + kChecksumBytes;
  for (uint32_t i = 0; i < count; ++i) {
    HlodNode& n = t.nodes[i];
    n.payload_offset = load_u64(p + table_at + kOffsetBytes * i);
    n.payload_size = load_u64(p + table_at + kOffsetBytes * i + 8);
    const uint64_t want = payload_data_bytes(n) + kChecksumBytes;
    const std::string name = "node " + std::to_string(i) + " payload [" + std::to_string(n.payload_offset) + ", +" +
                             std::to_string(n.payload_size) + ")";
    if (n.payload_size != want)
      return refuse(what, name + " should be " + std::to_string(want) + " bytes for its counts");
    if (n.payload_offset != end || n.payload_offset > file_size || n.payload_size > file_size - n.payload_offset)
      return refuse(what, name + " does not follow the " + (i ? "payload before it" : "head") + " at " +
                              std::to_string(end) + " (it overlaps it or leaves a gap) or lies outside the file's " +
                              std::to_string(file_size) + " bytes");
    end = n.payload_offset + n.payload_size;
    uint64_t own = n.boundary_vertices;
    for (uint32_t k = 0; k < n.layer_count; ++k) own += n.layers[k].vertices;
    if (own > UINT32_MAX / 3) return refuse(what, "node " + std::to_string(i) + " has too many vertices");
    vertices += own;
    boundary += n.boundary_triangles;
    n.resident_bytes = hlod_resident_bytes(n);
  }
  if (end != file_size)
    return refuse(what, "the payloads end at " + std::to_string(end) + ", the file at " + std::to_string(file_size));
  if (vertices != load_u64(p + 48) || boundary != load_u64(p + 56))
    return refuse(what, "header counts " + std::to_string(load_u64(p + 48)) + " vertices, " +
                            std::to_string(load_u64(p + 56)) + " boundary triangles; the nodes hold " +
                            std::to_string(vertices) + " and " + std::to_string(boundary));
  out = std::move(t);
  return Status::success();
}

Status decode_hlod_payload(std::span<const uint8_t> bytes, const HlodNode& node, uint32_t materials,
                           const std::string& what, HlodPayload& out) {
  if (bytes.size() != node.payload_size || bytes.size() != payload_data_bytes(node) + kChecksumBytes)
    return refuse(what, "node payload is " + std::to_string(bytes.size()) + " bytes, its counts need " +
                            std::to_string(payload_data_bytes(node) + kChecksumBytes) + " (truncated?)");
  const uint64_t body = bytes.size() - kChecksumBytes;
  if (load_u64(bytes.data() + body) != hash_bytes(bytes.data(), body))
    return refuse(what, "payload checksum mismatch (the file is damaged)");
  HlodPayload p;
  const uint8_t* q = bytes.data();
  std::string why;
  for (uint32_t k = 0; k < node.layer_count; ++k) {
    LodLevel range;
    if (!get_range(q, node.layers[k].vertices, node.layers[k].triangles, node, p, range, why))
      return refuse(what, "layer " + std::to_string(k) + ": " + why);
    range.error = node.layers[k].error;
    range.bounds = node.bounds;
    p.layers.push_back(range);
  }
  if (!get_range(q, node.boundary_vertices, node.boundary_triangles, node, p, p.boundary, why))
    return refuse(what, "boundary: " + why);
  p.boundary.bounds = node.bounds;
  if (!get_runs(q, node, materials, p, why)) return refuse(what, why);
  out = std::move(p);
  return Status::success();
}

Status decode_hlod_asset(std::span<const uint8_t> file, const std::string& what, HlodTree& tree,
                         std::vector<HlodPayload>& payloads) {
  HlodTree t;
  if (Status s = decode_hlod_tree(file, file.size(), what, t); !s) return s;
  std::vector<HlodPayload> all(t.nodes.size());
  for (size_t i = 0; i < t.nodes.size(); ++i) {
    const HlodNode& n = t.nodes[i];
    if (Status s = decode_hlod_payload(file.subspan(n.payload_offset, n.payload_size), n, t.material_count,
                                       what + ": node " + std::to_string(i), all[i]);
        !s)
      return s;
  }
  tree = std::move(t);
  payloads = std::move(all);
  return Status::success();
}

Status write_hlod_asset(const std::filesystem::path& path, const HlodTree& tree, std::span<const HlodPayload> payloads) {
  const std::vector<uint8_t> bytes = encode_hlod_asset(tree, payloads);
  return write_file_atomic(path, bytes);
}

// ---- reading from a file -----------------------------------------------------------------

namespace {

Status read_exactly(int fd, uint64_t offset, uint64_t size, std::vector<uint8_t>& out, const std::string& what) {
  out.resize(size_t(size));
  uint64_t got = 0;
  while (got < size) {
    const ssize_t n = ::pread(fd, out.data() + got, size_t(size - got), off_t(offset + got));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return refuse(what, std::string("read failed: ") + std::strerror(errno));
    if (n == 0) return refuse(what, "truncated: " + std::to_string(got) + " of " + std::to_string(size) +
                                        " bytes at offset " + std::to_string(offset));
    got += uint64_t(n);
  }
  return Status::success();
}

}  // namespace

HlodFile::~HlodFile() {
  if (fd_ >= 0) ::close(fd_);
}
HlodFile::HlodFile(HlodFile&& other) noexcept
    : fd_(other.fd_), size_(other.size_), materials_(other.materials_), path_(std::move(other.path_)) {
  other.fd_ = -1;
}
HlodFile& HlodFile::operator=(HlodFile&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = other.fd_, size_ = other.size_, materials_ = other.materials_, path_ = std::move(other.path_);
    other.fd_ = -1;
  }
  return *this;
}

Status HlodFile::open(const std::filesystem::path& path, HlodTree& tree) {
  const std::string what = path.string();
  RegularFile file;  // a regular file only, checked before and after the open
  if (Status s = open_regular_file(path, kInputFileLimit, file); !s) return s;
  HlodFile f;
  const int fd = f.fd_ = std::exchange(file.fd, -1);
  f.path_ = what;
  f.size_ = file.size;
  if (f.size_ < kFixedBytes + kChecksumBytes)
    return refuse(what, "file is " + std::to_string(f.size_) + " bytes, too short for an .hlod file (truncated?)");
  std::vector<uint8_t> fixed;
  if (Status s = read_exactly(fd, 0, kFixedBytes, fixed, what); !s) return s;
  // The head's size as the file states it, bounded by the file before it is allocated.
  const uint64_t head = std::memcmp(fixed.data(), kMagic, 8) == 0 ? load_u32(fixed.data() + 12) : 0;
  std::vector<uint8_t> bytes;
  if (head + kChecksumBytes <= f.size_ && head >= kFixedBytes) {
    if (Status s = read_exactly(fd, 0, head + kChecksumBytes, bytes, what); !s) return s;
  } else {
    bytes = std::move(fixed);  // decode names what is wrong with it
  }
  HlodTree t;
  if (Status s = decode_hlod_tree(bytes, f.size_, what, t); !s) return s;
  f.materials_ = t.material_count;
  tree = std::move(t);
  *this = std::move(f);
  return Status::success();
}

Status HlodFile::read_node(const HlodNode& node, HlodPayload& out) const { return read_node_as(node, path_, out); }

Status HlodFile::read_node(uint32_t index, const HlodNode& node, HlodPayload& out) const {
  return read_node_as(node, path_ + ": node " + std::to_string(index), out);
}

Status HlodFile::read_node_as(const HlodNode& node, const std::string& what, HlodPayload& out) const {
  if (fd_ < 0) return Status::error("hlod: no file open");
  if (node.payload_offset > size_ || node.payload_size > size_ - node.payload_offset)
    return refuse(what, "node payload lies outside the file");
  std::vector<uint8_t> bytes;
  if (Status s = read_exactly(fd_, node.payload_offset, node.payload_size, bytes, what); !s) return s;
  return decode_hlod_payload(bytes, node, materials_, what, out);
}

Status read_hlod_tree(const std::filesystem::path& path, HlodTree& out) {
  HlodFile f;
  return f.open(path, out);
}

Status read_hlod_node(const std::filesystem::path& path, const HlodNode& node, HlodPayload& out) {
  HlodFile f;
  HlodTree tree;
  if (Status s = f.open(path, tree); !s) return s;
  return f.read_node(node, out);
}

Status read_hlod_node(const std::filesystem::path& path, uint32_t index, const HlodNode& node, HlodPayload& out) {
  HlodFile f;
  HlodTree tree;
  if (Status s = f.open(path, tree); !s) return s;
  return f.read_node(index, node, out);
}

}  // namespace lod
