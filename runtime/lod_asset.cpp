// The .lod asset, version 1 (optional sections added since; see each). All integers and floats little-endian:
//
//   magic "LODKIT\x1a\n" (8) | u32 version | u32 section count
//   section table: count x {u32 tag, u32 flags, u64 offset, u64 size}
//   sections, each 8-byte aligned: META, LEVL, POSN, NRML, INDX
//   u64 checksum = hash_bytes(everything before it)
//
// VHIE (optional, flag 0; written only when the chain has a vertex hierarchy): u32 leaf
//       count, u32 face count, u64 nodes, u64 dependencies, u64 incident faces, then 4-byte
//       words: positions (3n), parent, radius, cone axis (3n), cone cos, error, leaf_lo,
//       leaf_hi (n each), leaf_rank (leaves), face leaves (3f), face owner (f), children,
//       split faces, wings (2i each, i = n - leaves), dep offsets (i + 1), deps, incidence
//       offsets (i + 1), incident faces. Readers that predate it skip it (version stays 1).
// VHAT (optional, flag 0; written with VHIE when its tree pins attribute seams or has uvs):
//       u32 layout (1), u32 flags (bit 0: VertexTree::seams_pinned; the rest 0), u64 uv nodes
//       (0, or VHIE's node count), then 2 f32 per node (VertexTree::uvs). The count is checked
//       against the section's bytes before anything is allocated, the layout and flags against
//       what this build knows, the uvs by validate_vertex_tree and, at the leaves, against
//       level 0's TEX0 uvs bit for bit. A reader that predates it skips it (a tree without
//       uvs, as before); a tree without it was built before seams were pinned, which
//       jobs/bake_jobs rebuilds when level 0 has seams or uvs.
//       Layout 2 (since bake format 11, written only when the tree has one of them): flags bit 1
//       (VertexTree::uvs1), bit 2 (colors), bit 3 (normals); after the uvs, with each bit, one
//       column per VHIE node in that order: 2 f32, 4 f32 (linear RGBA), 3 f32. Layout 1 (no
//       such bits) is written otherwise and read as before; a reader of layout 1 only refuses
//       layout 2 as newer ("re-bake"). Sizes are checked against the section's bytes first, the
//       columns by validate_vertex_tree_attributes, the leaves' uv1s and colours against level
//       0's TEX1 / COL0 bit for bit.
// MRPH (optional, flag 0; written only when the chain has morph targets): u32 per vertex of
//       every level but the last (LodChain::morph_targets), checked like the levels' indices.
// TEX0 (optional, flag 0; written only when the chain has texture coordinates): u32 level
//       count, f32 uv error per level, then 2 f32 per vertex (LodChain::uvs).
// TEX1 (optional, flag 0; since bake format 9, when the chain has a second uv set): TEX0's
//       layout for LodChain::uvs1 / uv1_errors.
// COL0 (optional, flag 0; since bake format 9, when the chain has vertex colours): u32 level
//       count, f32 colour error per level, then 4 f32 (linear RGBA) per vertex (LodChain::colors).
// MATL (optional, flag 0; written only when the chain has materials): u32 material count,
//       u32 submesh count, u32 texture base bytes, u32 layout; the texture base (UTF-8); 16
//       bytes per submesh (u32 level, u32 first index, u32 index count, i32 material); then per
//       material a fixed record and its strings. Layout 1 (written since bake format 8): 76
//       bytes (u32 name bytes, u32 base colour URI bytes, f32 base colour[4], f32 metallic, f32
//       roughness, f32 alpha cutoff, u8 alpha mode, u8 double-sided, u16 0, u32 URI bytes of
//       the metallic-roughness, normal, occlusion and emissive textures, f32 normal scale, f32
//       occlusion strength, f32 emissive[3]), then its name and five URIs in that order.
//       Layout 2 (since bake format 9): 84 bytes, layout 1's then u8 texCoord per texture slot
//       (0 or 1, in the five slots' order) and 3 zero bytes. Layout 1 (bake format 8) reads as
//       texCoord 0 everywhere. Layout 0 (bake format 7, read as before): the first 40 bytes only, name and base
//       colour URI. Every count and length is checked against the section's bytes before
//       anything is allocated or copied; the values by validate_chain.
// IMGS (optional, flag 0; since bake format 10, when the chain has embedded images): u32 image
//       count, u32 layout (1), u64 image bytes in all; per image 16 bytes (u64 byte length, u8
//       type: 1 PNG, 2 JPEG, 7 zero bytes); then every image's bytes back to back (the PNG or
//       JPEG file as embedded, never decoded). The count, each length and their sum are checked
//       against the section's bytes and kMaxEmbeddedImages / kMaxEmbeddedImageBytes /
//       kMaxEmbeddedBytes before anything is allocated; each image's signature against its type
//       by validate_chain. MATL names image k as the texture URI "embedded:<k>". This build
//       refuses a chain whose "embedded:<k>" names an image it lacks (validate_chain); a reader
//       that predates the section skips it and finds no file by that URI, so it draws and
//       exports those textures' materials without them, saying so.
// META: u64 source_hash, u32 level count, u32 name bytes, u64 vertices, u64 normal vertices,
//       u64 indices, name. LEVL: 44 bytes per level (see put_level). POSN/NRML: 3 f32 per
//       vertex; NRML flag bit 1 (since bake format 11): level 0's normals are the source's own
//       (LodChain::authored_normals; each unit or zero), older readers ignore it. INDX: u32 per
//       index. Flag bit 0 marks a section a reader must understand; unknown optional sections
//       are skipped, so later versions can add data compatibly.
// The \x1a\n in the magic catches text-mode transfers that rewrite line endings.
#include "runtime/lod_asset.h"

#include "runtime/bytes_hasher.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <new>
#include <string_view>
#include <system_error>

#include "runtime/byte_order.h"
#include "runtime/file_write.h"
#include "runtime/material_section.h"
#include "runtime/regular_file.h"

namespace lod {

namespace {

constexpr char kMagic[8] = {'L', 'O', 'D', 'K', 'I', 'T', '\x1a', '\n'};
constexpr size_t kHeaderBytes = 16;
constexpr size_t kTableEntryBytes = 24;
constexpr size_t kChecksumBytes = 8;
constexpr size_t kMetaFixedBytes = 40;
constexpr size_t kLevelBytes = 44;
constexpr uint32_t kFlagRequired = 1;
// NRML only: level 0's normals are the source's (LodChain::authored_normals).
constexpr uint32_t kNrmlAuthored = 2;
constexpr uint32_t kMaxSections = 64;

constexpr uint32_t fourcc(const char (&s)[5]) {
  return uint32_t(uint8_t(s[0])) | uint32_t(uint8_t(s[1])) << 8 | uint32_t(uint8_t(s[2])) << 16 |
         uint32_t(uint8_t(s[3])) << 24;
}
constexpr uint32_t kMeta = fourcc("META");
constexpr uint32_t kLevl = fourcc("LEVL");
constexpr uint32_t kPosn = fourcc("POSN");
constexpr uint32_t kNrml = fourcc("NRML");
constexpr uint32_t kIndx = fourcc("INDX");
constexpr uint32_t kVhie = fourcc("VHIE");
constexpr uint32_t kMrph = fourcc("MRPH");
constexpr uint32_t kTex0 = fourcc("TEX0");
constexpr uint32_t kMatl = fourcc("MATL");
constexpr uint32_t kTex1 = fourcc("TEX1");
constexpr uint32_t kCol0 = fourcc("COL0");
constexpr size_t kMatlFixedBytes = 16;
constexpr size_t kSubmeshBytes = 16;
constexpr size_t kMaterialFixedBytes = 40;     // layout 0's record
constexpr size_t kMaterialTexturedBytes = 76;  // layout 1's
constexpr size_t kMaterialTexCoordBytes = 84;  // layout 2's
constexpr uint32_t kMatlLayout = 2;
constexpr uint32_t kImgs = fourcc("IMGS");
constexpr size_t kImgsFixedBytes = 16;
constexpr size_t kImageEntryBytes = 16;
constexpr uint32_t kImgsLayout = 1;
constexpr size_t kVhieFixedBytes = 32;
constexpr uint32_t kVhat = fourcc("VHAT");
constexpr size_t kVhatFixedBytes = 16;
constexpr uint32_t kVhatLayout = 2;
constexpr uint32_t kVhatSeamsPinned = 1;
constexpr uint32_t kVhatUvs1 = 2, kVhatColors = 4, kVhatNormals = 8;  // layout 2 only
constexpr uint32_t kKnownTags[] = {kMeta, kLevl, kPosn, kNrml, kIndx};

std::string tag_name(uint32_t tag) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((tag >> (8 * i)) & 0xff);
    s += (c >= 0x20 && c < 0x7f) ? c : '?';
  }
  return s;
}

using detail::load_f32;
using detail::load_u32;
using detail::load_u64;

using Writer = detail::ByteWriter;

void put_level(Writer& w, const LodLevel& lv) {
  w.u32(lv.first_index);
  w.u32(lv.index_count);
  w.u32(lv.first_vertex);
  w.u32(lv.vertex_count);
  w.u32(static_cast<uint32_t>(lv.level));
  w.f32(lv.error);
  w.f32(lv.error_rms);
  w.f32(lv.bounds.center[0]);
  w.f32(lv.bounds.center[1]);
  w.f32(lv.bounds.center[2]);
  w.f32(lv.bounds.radius);
}

LodLevel get_level(const uint8_t* p) {
  LodLevel lv;
  lv.first_index = load_u32(p);
  lv.index_count = load_u32(p + 4);
  lv.first_vertex = load_u32(p + 8);
  lv.vertex_count = load_u32(p + 12);
  lv.level = static_cast<int32_t>(load_u32(p + 16));
  lv.error = load_f32(p + 20);
  lv.error_rms = load_f32(p + 24);
  lv.bounds.center[0] = load_f32(p + 28);
  lv.bounds.center[1] = load_f32(p + 32);
  lv.bounds.center[2] = load_f32(p + 36);
  lv.bounds.radius = load_f32(p + 40);
  return lv;
}

void put_floats(Writer& w, const std::vector<float>& v) {
  if constexpr (std::endian::native == std::endian::little) {
    w.raw(v.data(), v.size() * sizeof(float));
  } else {
    for (float f : v) w.f32(f);
  }
}

template <class T>
void get_words(const uint8_t* p, size_t count, std::vector<T>& out) {
  static_assert(sizeof(T) == 4);
  out.resize(count);
  if constexpr (std::endian::native == std::endian::little) {
    if (count) std::memcpy(out.data(), p, count * 4);
  } else {
    for (size_t i = 0; i < count; ++i) out[i] = std::bit_cast<T>(load_u32(p + 4 * i));
  }
}

template <class T>
void put_words(Writer& w, const std::vector<T>& v) {
  static_assert(sizeof(T) == 4);
  if constexpr (std::endian::native == std::endian::little) {
    w.raw(v.data(), v.size() * 4);
  } else {
    for (T x : v) w.u32(std::bit_cast<uint32_t>(x));
  }
}

void put_hierarchy(Writer& w, const VertexTree& t) {
  w.u32(t.leaf_count);
  w.u32(t.face_count);
  w.u64(t.node_count());
  w.u64(t.deps.size());
  w.u64(t.inc_faces.size());
  put_words(w, t.positions);
  put_words(w, t.parent);
  put_words(w, t.radius);
  put_words(w, t.cone_axis);
  put_words(w, t.cone_cos);
  put_words(w, t.error);
  put_words(w, t.leaf_lo);
  put_words(w, t.leaf_hi);
  put_words(w, t.leaf_rank);
  put_words(w, t.face_leaves);
  put_words(w, t.face_owner);
  put_words(w, t.children);
  put_words(w, t.split_faces);
  put_words(w, t.wings);
  put_words(w, t.dep_offsets);
  put_words(w, t.deps);
  put_words(w, t.inc_offsets);
  put_words(w, t.inc_faces);
}

// Layout 1 while the tree has nothing past uvs (so older readers still read it), else 2.
void put_hierarchy_attributes(Writer& w, const VertexTree& t) {
  const uint32_t flags = (t.seams_pinned ? kVhatSeamsPinned : 0) | (t.uvs1.empty() ? 0 : kVhatUvs1) |
                         (t.colors.empty() ? 0 : kVhatColors) | (t.normals.empty() ? 0 : kVhatNormals);
  w.u32(flags & ~kVhatSeamsPinned ? 2 : 1);
  w.u32(flags);
  w.u64(t.uvs.size() / 2);
  put_words(w, t.uvs);
  put_words(w, t.uvs1);
  put_words(w, t.colors);
  put_words(w, t.normals);
}

struct SectionRef {
  uint64_t offset = 0;
  uint64_t size = 0;
  bool present = false;
};

Status refuse(const std::string& what, const std::string& why) { return Status::error(what + ": " + why); }

// VHAT: structure only (layout, flags, count against bytes); `nodes` is VHIE's node count.
Status get_hierarchy_attributes(const uint8_t* p, uint64_t size, uint64_t nodes, const std::string& what,
                                VertexTree& t) {
  auto bad = [&](const std::string& why) { return refuse(what, "VHAT section: " + why); };
  if (size < kVhatFixedBytes)
    return bad(std::to_string(size) + " bytes, needs " + std::to_string(kVhatFixedBytes) + " at least");
  const uint32_t layout = load_u32(p), flags = load_u32(p + 4);
  const uint64_t count = load_u64(p + 8);
  if (layout > kVhatLayout)
    return bad("layout " + std::to_string(layout) + " is newer than this build reads (" + std::to_string(kVhatLayout) +
               "); use a newer lodkit or re-bake it");
  if (layout == 0) return bad("layout 0 does not exist");
  const uint32_t known =
      layout == 1 ? kVhatSeamsPinned : kVhatSeamsPinned | kVhatUvs1 | kVhatColors | kVhatNormals;
  if (flags & ~known)
    return bad("unknown flags " + std::to_string(flags) + " for layout " + std::to_string(layout));
  if (count != 0 && count != nodes)
    return bad("uvs for " + std::to_string(count) + " nodes, the hierarchy has " + std::to_string(nodes));
  // Bytes per node of the layout-2 columns; nodes is bounded by VHIE's bytes, so no overflow.
  const uint64_t per_node =
      (flags & kVhatUvs1 ? 8 : 0) + (flags & kVhatColors ? 16 : 0) + (flags & kVhatNormals ? 12 : 0);
  if (count > (size - kVhatFixedBytes) / 8 || per_node * nodes > size - kVhatFixedBytes - 8 * count ||
      size != kVhatFixedBytes + 8 * count + per_node * nodes)
    return bad(std::to_string(size) + " bytes but " + std::to_string(count) + " uv nodes need " +
               std::to_string(kVhatFixedBytes) + " + 8 each" +
               (per_node
                    ? " and its flags " + std::to_string(per_node) + " per node of " + std::to_string(nodes)
                    : "") +
               " (truncated?)");
  const uint8_t* q = p + kVhatFixedBytes;
  get_words(q, 2 * count, t.uvs);
  q += 8 * count;
  auto take = [&](uint32_t flag, uint64_t width, std::vector<float>& column) {
    if (!(flags & flag)) return;
    get_words(q, width * nodes, column);
    q += 4 * width * nodes;
  };
  take(kVhatUvs1, 2, t.uvs1);
  take(kVhatColors, 4, t.colors);
  take(kVhatNormals, 3, t.normals);
  t.seams_pinned = (flags & kVhatSeamsPinned) != 0;
  return Status::success();
}

// Leaves are level 0's vertices: their uvs (either set) and colours must be its, bit for bit.
Status check_leaf_column(const LodChain& chain, const std::vector<float>& tree_values,
                         const std::vector<float>& level_values, size_t width, const char* what,
                         const char* section, const std::string& where) {
  const VertexTree& t = chain.hierarchy;
  if (tree_values.empty()) return Status::success();
  if (level_values.empty() || chain.levels.empty())
    return refuse(where, std::string("VHAT section: the hierarchy has ") + what +
                             "s but the levels have none (" + section + ")");
  const size_t first = width * size_t(chain.levels[0].first_vertex);
  const size_t bytes = 4 * width;
  if (std::memcmp(tree_values.data(), level_values.data() + first, bytes * t.leaf_count) == 0)
    return Status::success();
  for (uint32_t v = 0; v < t.leaf_count; ++v)
    if (std::memcmp(&tree_values[width * v], &level_values[first + width * v], bytes) != 0)
      return refuse(where, "VHAT section: leaf " + std::to_string(v) + " " + what +
                               " differs from level 0 vertex " + std::to_string(v) + "'s");
  return Status::success();
}

// Authored normals at level 0 (what a tree's leaves carry): unit or zero, as the tree's are.
Status check_authored_normals(const LodChain& chain, const std::string& what) {
  if (chain.levels.empty()) return Status::success();
  const LodLevel& l0 = chain.levels[0];
  for (uint32_t v = 0; v < l0.vertex_count; ++v) {
    const float* n = &chain.normals[3 * (size_t(l0.first_vertex) + v)];
    const double len = std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
    if (len != 0 && std::abs(len - 1) > kTreeNormalTolerance)
      return refuse(what, "NRML section: level 0 vertex " + std::to_string(v) +
                              " authored normal has length " + std::to_string(len) + ", not 1 or 0");
  }
  return Status::success();
}

Status check_leaf_attributes(const LodChain& chain, const std::string& what) {
  const VertexTree& t = chain.hierarchy;
  if (!t.normals.empty()) {
    if (!chain.authored_normals)
      return refuse(what,
                    "VHAT section: the hierarchy has normals but level 0's are not authored (NRML flags)");
    if (Status st = check_leaf_column(chain, t.normals, chain.normals, 3, "normal", "NRML", what); !st)
      return st;
  }
  if (Status st = check_leaf_column(chain, t.uvs, chain.uvs, 2, "uv", "TEX0", what); !st) return st;
  if (Status st = check_leaf_column(chain, t.uvs1, chain.uvs1, 2, "uv1", "TEX1", what); !st) return st;
  return check_leaf_column(chain, t.colors, chain.colors, 4, "colour", "COL0", what);
}

Status get_hierarchy(const uint8_t* p, uint64_t size, const std::string& what, VertexTree& out,
                     const SectionRef* attributes, const uint8_t* file) {
  if (size < kVhieFixedBytes)
    return refuse(what, "VHIE section is " + std::to_string(size) + " bytes, needs " + std::to_string(kVhieFixedBytes));
  VertexTree t;
  t.leaf_count = load_u32(p);
  t.face_count = load_u32(p + 4);
  const uint64_t nodes = load_u64(p + 8), deps = load_u64(p + 16), inc = load_u64(p + 24);
  const uint64_t words = (size - kVhieFixedBytes) / 4;
  // Every count is bounded by the section before anything is multiplied or allocated.
  if (nodes > words || deps > words || inc > words || t.leaf_count > nodes || t.face_count > words)
    return refuse(what, "VHIE counts do not fit its " + std::to_string(size) + " bytes");
  const uint64_t inner = nodes - t.leaf_count;
  const uint64_t need = 12 * nodes + t.leaf_count + 4 * uint64_t(t.face_count) + 6 * inner + 2 * (inner + 1) + deps + inc;
  if (need != words || (size - kVhieFixedBytes) % 4 != 0)
    return refuse(what, "VHIE section is " + std::to_string(size) + " bytes but its counts need " +
                            std::to_string(kVhieFixedBytes + 4 * need));
  const uint8_t* q = p + kVhieFixedBytes;
  auto take = [&](auto& v, uint64_t count) {
    get_words(q, count, v);
    q += 4 * count;
  };
  take(t.positions, 3 * nodes);
  take(t.parent, nodes);
  take(t.radius, nodes);
  take(t.cone_axis, 3 * nodes);
  take(t.cone_cos, nodes);
  take(t.error, nodes);
  take(t.leaf_lo, nodes);
  take(t.leaf_hi, nodes);
  take(t.leaf_rank, t.leaf_count);
  take(t.face_leaves, 3 * uint64_t(t.face_count));
  take(t.face_owner, t.face_count);
  take(t.children, 2 * inner);
  take(t.split_faces, 2 * inner);
  take(t.wings, 2 * inner);
  take(t.dep_offsets, inner + 1);
  take(t.deps, deps);
  take(t.inc_offsets, inner + 1);
  take(t.inc_faces, inc);
  if (attributes)
    if (Status st = get_hierarchy_attributes(file + attributes->offset, attributes->size, nodes, what, t); !st)
      return st;
  std::string message;
  VertexTree columns;  // validated apart, so a bad one is named as VHAT's
  columns.uvs.swap(t.uvs), columns.uvs1.swap(t.uvs1), columns.colors.swap(t.colors);
  columns.normals.swap(t.normals);
  if (!validate_vertex_tree(t, &message)) return refuse(what, "VHIE section: " + message);
  t.uvs.swap(columns.uvs), t.uvs1.swap(columns.uvs1), t.colors.swap(columns.colors);
  t.normals.swap(columns.normals);
  if (!validate_vertex_tree_attributes(t, &message)) return refuse(what, "VHAT section: " + message);
  pack_vertex_bounds(t);
  out = std::move(t);
  return Status::success();
}

void put_materials(Writer& w, const LodChain& c) {
  w.u32(static_cast<uint32_t>(c.materials.size()));
  w.u32(static_cast<uint32_t>(c.submeshes.size()));
  w.u32(static_cast<uint32_t>(c.texture_base.size()));
  w.u32(kMatlLayout);
  w.raw(c.texture_base.data(), c.texture_base.size());
  for (const LevelSubmesh& s : c.submeshes) {
    w.u32(s.level);
    w.u32(s.first_index);
    w.u32(s.index_count);
    w.u32(static_cast<uint32_t>(s.material));
  }
  for (const ChainMaterial& m : c.materials) {
    w.u32(static_cast<uint32_t>(m.name.size()));
    w.u32(static_cast<uint32_t>(m.base_color_texture.size()));
    for (float f : m.base_color) w.f32(f);
    w.f32(m.metallic);
    w.f32(m.roughness);
    w.f32(m.alpha_cutoff);
    w.u8(static_cast<uint8_t>(m.alpha_mode));
    w.u8(m.double_sided ? 1 : 0);
    w.u8(0);
    w.u8(0);
    const auto uris = texture_slots(m);
    for (size_t k = 1; k < kTextureSlots; ++k) w.u32(static_cast<uint32_t>(uris[k]->size()));
    w.f32(m.normal_scale);
    w.f32(m.occlusion_strength);
    for (float f : m.emissive) w.f32(f);
    for (uint8_t t : m.tex_coords) w.u8(t);
    for (size_t k = kTextureSlots; k < 8; ++k) w.u8(0);
    w.raw(m.name.data(), m.name.size());
    for (const std::string* uri : uris) w.raw(uri->data(), uri->size());
  }
}

// Structure only (counts, lengths, what fits where); the values are validate_chain's.
Status get_materials(const uint8_t* p, uint64_t size, const std::string& what, LodChain& chain) {
  auto bad = [&](const std::string& why) { return refuse(what, "MATL section: " + why); };
  if (size < kMatlFixedBytes)
    return bad(std::to_string(size) + " bytes, needs " + std::to_string(kMatlFixedBytes) + " at least");
  const uint64_t materials = load_u32(p), submeshes = load_u32(p + 4), base_bytes = load_u32(p + 8);
  const uint32_t layout = load_u32(p + 12);
  if (layout > kMatlLayout)
    return bad("layout " + std::to_string(layout) + " is newer than this build reads (" + std::to_string(kMatlLayout) +
               "); use a newer lodkit or re-bake it");
  const uint64_t record = layout == 0 ? kMaterialFixedBytes : layout == 1 ? kMaterialTexturedBytes : kMaterialTexCoordBytes;
  if (materials > kMaxMaterials)
    return bad(std::to_string(materials) + " materials, at most " + std::to_string(kMaxMaterials));
  if (base_bytes > kMaxMaterialString) return bad("texture base of " + std::to_string(base_bytes) + " bytes is too long");
  uint64_t at = kMatlFixedBytes;
  const uint64_t fixed = base_bytes + submeshes * kSubmeshBytes + materials * record;
  if (fixed > size - at)
    return bad(std::to_string(materials) + " materials and " + std::to_string(submeshes) + " submeshes need " +
               std::to_string(at + fixed) + " bytes at least, the section has " + std::to_string(size));
  chain.texture_base.assign(reinterpret_cast<const char*>(p + at), base_bytes);
  at += base_bytes;
  chain.submeshes.resize(submeshes);
  for (LevelSubmesh& s : chain.submeshes) {
    s.level = load_u32(p + at);
    s.first_index = load_u32(p + at + 4);
    s.index_count = load_u32(p + at + 8);
    s.material = static_cast<int32_t>(load_u32(p + at + 12));
    at += kSubmeshBytes;
  }
  chain.materials.resize(materials);
  for (uint64_t i = 0; i < materials; ++i) {
    const std::string where = "material " + std::to_string(i);
    if (record > size - at) return bad(where + " is cut off at byte " + std::to_string(at));
    ChainMaterial& m = chain.materials[i];
    const auto uris = texture_slots(m);
    uint64_t lengths[1 + kTextureSlots] = {load_u32(p + at), load_u32(p + at + 4)};  // name, then the URIs
    for (int c = 0; c < 4; ++c) m.base_color[c] = load_f32(p + at + 8 + 4 * c);
    m.metallic = load_f32(p + at + 24);
    m.roughness = load_f32(p + at + 28);
    m.alpha_cutoff = load_f32(p + at + 32);
    const uint8_t mode = p[at + 36], sided = p[at + 37];
    if (mode > uint8_t(AlphaMode::blend)) return bad(where + " has unknown alpha mode " + std::to_string(mode));
    if (sided > 1) return bad(where + " has double-sided flag " + std::to_string(sided));
    m.alpha_mode = static_cast<AlphaMode>(mode);
    m.double_sided = sided == 1;
    if (layout >= 1) {
      for (size_t k = 1; k < kTextureSlots; ++k) lengths[1 + k] = load_u32(p + at + 40 + 4 * (k - 1));
      m.normal_scale = load_f32(p + at + 56);
      m.occlusion_strength = load_f32(p + at + 60);
      for (int c = 0; c < 3; ++c) m.emissive[c] = load_f32(p + at + 64 + 4 * c);
    }
    if (layout >= 2) {
      for (size_t k = 0; k < kTextureSlots; ++k) m.tex_coords[k] = p[at + 76 + k];  // values: validate_chain
      for (size_t k = kTextureSlots; k < 8; ++k)
        if (p[at + 76 + k] != 0) return bad(where + " has non-zero padding byte " + std::to_string(76 + k));
    }
    at += record;
    // Each length bounded first, so their sum cannot overflow.
    uint64_t strings = 0;
    for (uint64_t n : lengths) {
      if (n > kMaxMaterialString)
        return bad(where + " has a name or URI of " + std::to_string(n) + " bytes, at most " + std::to_string(kMaxMaterialString));
      strings += n;
    }
    if (strings > size - at)
      return bad(where + " says its name and URIs take " + std::to_string(strings) + " bytes; " + std::to_string(size - at) +
                 " are left");
    m.name.assign(reinterpret_cast<const char*>(p + at), lengths[0]);
    at += lengths[0];
    for (size_t k = 0; k < kTextureSlots; ++k) {
      uris[k]->assign(reinterpret_cast<const char*>(p + at), lengths[1 + k]);
      at += lengths[1 + k];
    }
  }
  if (at != size) return bad(std::to_string(size - at) + " bytes left over after the last material");
  return Status::success();
}

void put_images(Writer& w, std::span<const EmbeddedImage> images) {
  uint64_t total = 0;
  for (const EmbeddedImage& img : images) total += img.bytes.size();
  w.u32(static_cast<uint32_t>(images.size()));
  w.u32(kImgsLayout);
  w.u64(total);
  for (const EmbeddedImage& img : images) {
    w.u64(img.bytes.size());
    w.u8(static_cast<uint8_t>(img.type));
    for (int k = 0; k < 7; ++k) w.u8(0);
  }
  for (const EmbeddedImage& img : images) w.raw(img.bytes.data(), img.bytes.size());
}

// Structure only (counts and lengths against the bytes and the bounds); each image's signature
// is validate_chain's.
Status get_images(const uint8_t* p, uint64_t size, const std::string& what, std::vector<EmbeddedImage>& out) {
  auto bad = [&](const std::string& why) { return refuse(what, "IMGS section: " + why); };
  if (size < kImgsFixedBytes)
    return bad(std::to_string(size) + " bytes, needs " + std::to_string(kImgsFixedBytes) + " at least");
  const uint64_t count = load_u32(p), total = load_u64(p + 8);
  const uint32_t layout = load_u32(p + 4);
  if (layout > kImgsLayout)
    return bad("layout " + std::to_string(layout) + " is newer than this build reads (" + std::to_string(kImgsLayout) +
               "); use a newer lodkit or re-bake it");
  if (layout == 0) return bad("layout 0 does not exist");
  if (count > kMaxEmbeddedImages)
    return bad(std::to_string(count) + " images, at most " + std::to_string(kMaxEmbeddedImages));
  if (total > kMaxEmbeddedBytes)
    return bad(std::to_string(total) + " image bytes, at most " + std::to_string(kMaxEmbeddedBytes));
  const uint64_t table = kImgsFixedBytes + count * kImageEntryBytes;  // both bounded: no overflow
  if (table > size || size - table != total)
    return bad(std::to_string(size) + " bytes, but " + std::to_string(count) + " images of " + std::to_string(total) +
               " bytes need " + std::to_string(table) + " + " + std::to_string(total) + " (truncated?)");
  uint64_t sum = 0;
  for (uint64_t k = 0; k < count; ++k) {
    const uint8_t* e = p + kImgsFixedBytes + k * kImageEntryBytes;
    const uint64_t length = load_u64(e);
    const std::string where = "image " + std::to_string(k);
    if (length > kMaxEmbeddedImageBytes)
      return bad(where + " is " + std::to_string(length) + " bytes, at most " + std::to_string(kMaxEmbeddedImageBytes));
    if (e[8] != uint8_t(ImageType::png) && e[8] != uint8_t(ImageType::jpeg))
      return bad(where + " has type " + std::to_string(e[8]) + " (1 PNG, 2 JPEG)");
    for (int b = 9; b < 16; ++b)
      if (e[b] != 0) return bad(where + " has non-zero padding byte " + std::to_string(b));
    sum += length;  // each <= 256 MiB, at most 4096 of them: no overflow
  }
  if (sum != total)
    return bad("images' lengths add up to " + std::to_string(sum) + " bytes, the section says " + std::to_string(total));
  std::vector<EmbeddedImage> images(count);
  const uint8_t* at = p + table;
  for (uint64_t k = 0; k < count; ++k) {
    const uint8_t* e = p + kImgsFixedBytes + k * kImageEntryBytes;
    images[k].type = static_cast<ImageType>(e[8]);
    images[k].bytes.assign(at, at + load_u64(e));
    at += load_u64(e);
  }
  out = std::move(images);
  return Status::success();
}

}  // namespace

uint64_t hash_bytes(const void* data, size_t size, uint64_t seed) {
  BytesHasher h(seed);  // one implementation for whole buffers and pieces (runtime/bytes_hasher.h)
  h.add(data, size);
  return h.finish();
}

std::vector<uint8_t> encode_lod_asset(const LodChain& chain) {
  Writer w;
  std::vector<uint32_t> tags = {kMeta, kLevl, kPosn, kNrml, kIndx};
  if (!chain.hierarchy.empty()) tags.push_back(kVhie);
  if (!chain.hierarchy.empty() &&
      (chain.hierarchy.seams_pinned || !chain.hierarchy.uvs.empty() || !chain.hierarchy.uvs1.empty() ||
       !chain.hierarchy.colors.empty() || !chain.hierarchy.normals.empty()))
    tags.push_back(kVhat);
  if (!chain.morph_targets.empty()) tags.push_back(kMrph);
  if (!chain.uvs.empty()) tags.push_back(kTex0);
  if (!chain.uvs1.empty()) tags.push_back(kTex1);
  if (!chain.colors.empty()) tags.push_back(kCol0);
  if (!chain.materials.empty() || !chain.submeshes.empty()) tags.push_back(kMatl);
  if (!chain.images.empty()) tags.push_back(kImgs);
  const uint32_t section_count = static_cast<uint32_t>(tags.size());
  w.raw(kMagic, sizeof(kMagic));
  w.u32(kLodAssetVersion);
  w.u32(section_count);
  const size_t table = w.bytes.size();
  for (uint32_t s = 0; s < section_count; ++s) {
    w.u32(tags[s]);
    w.u32(tags[s] == kVhie || tags[s] == kVhat || tags[s] == kMrph || tags[s] == kTex0 || tags[s] == kTex1 ||
                  tags[s] == kCol0 || tags[s] == kMatl || tags[s] == kImgs
              ? 0
          : tags[s] == kNrml && chain.authored_normals ? kFlagRequired | kNrmlAuthored
                                                       : kFlagRequired);
    w.u64(0);  // offset, patched below
    w.u64(0);  // size
  }
  auto section = [&](uint32_t s, auto&& body) {
    w.align8();
    const size_t begin = w.bytes.size();
    body();
    w.patch_u64(table + s * kTableEntryBytes + 8, begin);
    w.patch_u64(table + s * kTableEntryBytes + 16, w.bytes.size() - begin);
  };
  section(0, [&] {
    w.u64(chain.source_hash);
    w.u32(static_cast<uint32_t>(chain.levels.size()));
    w.u32(static_cast<uint32_t>(chain.name.size()));
    w.u64(chain.positions.size() / 3);
    w.u64(chain.normals.size() / 3);
    w.u64(chain.indices.size());
    w.raw(chain.name.data(), chain.name.size());
  });
  section(1, [&] {
    for (const LodLevel& lv : chain.levels) put_level(w, lv);
  });
  section(2, [&] { put_floats(w, chain.positions); });
  section(3, [&] { put_floats(w, chain.normals); });
  section(4, [&] {
    if constexpr (std::endian::native == std::endian::little) {
      w.raw(chain.indices.data(), chain.indices.size() * sizeof(uint32_t));
    } else {
      for (uint32_t v : chain.indices) w.u32(v);
    }
  });
  for (uint32_t s = 5; s < section_count; ++s) {
    if (tags[s] == kVhie) section(s, [&] { put_hierarchy(w, chain.hierarchy); });
    if (tags[s] == kVhat) section(s, [&] { put_hierarchy_attributes(w, chain.hierarchy); });
    if (tags[s] == kMrph) section(s, [&] { put_words(w, chain.morph_targets); });
    if (tags[s] == kTex0)
      section(s, [&] {
        w.u32(static_cast<uint32_t>(chain.uv_errors.size()));
        put_floats(w, chain.uv_errors);
        put_floats(w, chain.uvs);
      });
    if (tags[s] == kTex1)
      section(s, [&] {
        w.u32(static_cast<uint32_t>(chain.uv1_errors.size()));
        put_floats(w, chain.uv1_errors);
        put_floats(w, chain.uvs1);
      });
    if (tags[s] == kCol0)
      section(s, [&] {
        w.u32(static_cast<uint32_t>(chain.color_errors.size()));
        put_floats(w, chain.color_errors);
        put_floats(w, chain.colors);
      });
    if (tags[s] == kMatl) section(s, [&] { put_materials(w, chain); });
    if (tags[s] == kImgs) section(s, [&] { put_images(w, chain.images); });
  }
  w.align8();
  w.u64(hash_bytes(w.bytes.data(), w.bytes.size()));
  return std::move(w.bytes);
}

namespace {

// The fixed header of a `size`-byte file (`head`: at least its first kHeaderBytes when
// size allows): long enough, the magic bytes, this build's version, a sane section count.
Status check_fixed_header(const uint8_t* head, uint64_t size, const std::string& what, uint32_t& section_count) {
  if (size < kHeaderBytes + kChecksumBytes)
    return refuse(what, "file is " + std::to_string(size) + " bytes, too short for a lodkit asset (" +
                            std::to_string(kHeaderBytes + kChecksumBytes) + " at least; truncated?)");
  if (std::memcmp(head, kMagic, sizeof(kMagic)) != 0) return refuse(what, "not a lodkit asset (bad magic bytes)");
  const uint32_t version = load_u32(head + 8);
  if (version != kLodAssetVersion)
    return refuse(what, "asset version " + std::to_string(version) + " is not supported (this build reads version " +
                            std::to_string(kLodAssetVersion) + "); re-bake it");
  section_count = load_u32(head + 12);
  if (section_count > kMaxSections)
    return refuse(what, "section count " + std::to_string(section_count) + " exceeds " + std::to_string(kMaxSections) +
                            " (corrupted header)");
  return Status::success();
}

}  // namespace

Status decode_lod_asset(std::span<const uint8_t> bytes, const std::string& what, LodChain& out) {
  const uint8_t* p = bytes.data();
  const uint64_t size = bytes.size();
  uint32_t section_count = 0;
  if (Status st = check_fixed_header(p, size, what, section_count); !st) return st;
  const uint64_t table_end = kHeaderBytes + uint64_t{section_count} * kTableEntryBytes;
  if (table_end + kChecksumBytes > size)
    return refuse(what, "truncated: file is " + std::to_string(size) + " bytes, its section table alone needs " +
                            std::to_string(table_end + kChecksumBytes));
  // Where the sections say the file ends: a shorter file was cut off (reported as such
  // rather than as a checksum mismatch, which would also catch it).
  uint64_t sections_end = table_end;
  for (uint32_t s = 0; s < section_count; ++s) {
    const uint8_t* e = p + kHeaderBytes + s * kTableEntryBytes;
    const uint64_t off = load_u64(e + 8), sz = load_u64(e + 16);
    if (off <= size && sz <= size) sections_end = std::max(sections_end, off + sz);
    else sections_end = UINT64_MAX;
  }
  if (sections_end != UINT64_MAX && sections_end + kChecksumBytes > size)
    return refuse(what, "truncated: file is " + std::to_string(size) + " bytes, its sections need " +
                            std::to_string(sections_end + kChecksumBytes));
  const uint64_t body = size - kChecksumBytes;
  const uint64_t stored = load_u64(p + body);
  const uint64_t computed = hash_bytes(p, body);
  if (stored != computed)
    return refuse(what, "checksum mismatch (file is corrupted or truncated)");

  SectionRef sec[5];
  SectionRef vhie, vhat, mrph, tex0, tex1, col0, matl, imgs;
  uint32_t nrml_flags = 0;
  for (uint32_t s = 0; s < section_count; ++s) {
    const uint8_t* e = p + kHeaderBytes + s * kTableEntryBytes;
    const uint32_t tag = load_u32(e), flags = load_u32(e + 4);
    const uint64_t off = load_u64(e + 8), sz = load_u64(e + 16);
    const std::string name = "section " + std::to_string(s) + " '" + tag_name(tag) + "'";
    if (off < table_end || off > body || sz > body - off)
      return refuse(what, name + " [" + std::to_string(off) + ", +" + std::to_string(sz) +
                              ") lies outside the data area [" + std::to_string(table_end) + ", " +
                              std::to_string(body) + ")");
    if (tag == kVhie) {
      if (vhie.present) return refuse(what, name + " appears twice");
      vhie = {off, sz, true};
      continue;
    }
    if (tag == kVhat) {
      if (vhat.present) return refuse(what, name + " appears twice");
      vhat = {off, sz, true};
      continue;
    }
    if (tag == kMrph) {
      if (mrph.present) return refuse(what, name + " appears twice");
      mrph = {off, sz, true};
      continue;
    }
    if (tag == kTex0) {
      if (tex0.present) return refuse(what, name + " appears twice");
      tex0 = {off, sz, true};
      continue;
    }
    if (tag == kTex1 || tag == kCol0) {
      SectionRef& ref = tag == kTex1 ? tex1 : col0;
      if (ref.present) return refuse(what, name + " appears twice");
      ref = {off, sz, true};
      continue;
    }
    if (tag == kMatl || tag == kImgs) {
      SectionRef& ref = tag == kMatl ? matl : imgs;
      if (ref.present) return refuse(what, name + " appears twice");
      ref = {off, sz, true};
      continue;
    }
    size_t known = 0;
    while (known < 5 && kKnownTags[known] != tag) ++known;
    if (known == 5) {
      if (flags & kFlagRequired) return refuse(what, name + " is required but unknown to this build");
      continue;
    }
    if (sec[known].present) return refuse(what, name + " appears twice");
    sec[known] = {off, sz, true};
    if (tag == kNrml) nrml_flags = flags;
  }
  for (size_t k = 0; k < 5; ++k) {
    if (!sec[k].present) return refuse(what, "section '" + tag_name(kKnownTags[k]) + "' is missing");
  }

  const SectionRef& meta = sec[0];
  if (meta.size < kMetaFixedBytes)
    return refuse(what, "META section is " + std::to_string(meta.size) + " bytes, needs " +
                            std::to_string(kMetaFixedBytes));
  const uint8_t* m = p + meta.offset;
  LodChain chain;
  chain.source_hash = load_u64(m);
  const uint32_t level_count = load_u32(m + 8);
  const uint32_t name_bytes = load_u32(m + 12);
  const uint64_t vertices = load_u64(m + 16);
  const uint64_t normal_vertices = load_u64(m + 24);
  const uint64_t indices = load_u64(m + 32);
  if (meta.size != kMetaFixedBytes + uint64_t{name_bytes})
    return refuse(what, "META section is " + std::to_string(meta.size) + " bytes but its name needs " +
                            std::to_string(kMetaFixedBytes + uint64_t{name_bytes}));
  chain.name.assign(reinterpret_cast<const char*>(m + kMetaFixedBytes), name_bytes);
  // Counts are checked against section sizes before any multiplication can overflow.
  auto expect = [&](const SectionRef& s, const char* label, uint64_t count, uint64_t stride) -> Status {
    if (count > s.size || count * stride != s.size)
      return refuse(what, std::string(label) + " section is " + std::to_string(s.size) + " bytes but META says " +
                              std::to_string(count) + " x " + std::to_string(stride));
    return Status::success();
  };
  if (Status st = expect(sec[1], "LEVL", level_count, kLevelBytes); !st) return st;
  if (Status st = expect(sec[2], "POSN", vertices, 12); !st) return st;
  if (Status st = expect(sec[3], "NRML", normal_vertices, 12); !st) return st;
  if (Status st = expect(sec[4], "INDX", indices, 4); !st) return st;

  chain.levels.resize(level_count);
  for (uint32_t k = 0; k < level_count; ++k) chain.levels[k] = get_level(p + sec[1].offset + k * kLevelBytes);
  get_words(p + sec[2].offset, vertices * 3, chain.positions);
  get_words(p + sec[3].offset, normal_vertices * 3, chain.normals);
  get_words(p + sec[4].offset, indices, chain.indices);

  if (mrph.present) {
    const uint64_t want = morph_target_count(chain);
    if (mrph.size != 4 * want)
      return refuse(what, "MRPH section is " + std::to_string(mrph.size) + " bytes but the levels but the last have " +
                              std::to_string(want) + " vertices (4 bytes each)");
    get_words(p + mrph.offset, want, chain.morph_targets);
  }
  // TEX0, TEX1, COL0: u32 level count, f32 error per level, `per` f32 per vertex.
  auto get_column = [&](const SectionRef& ref, const char* tag, size_t per, std::vector<float>& errors,
                        std::vector<float>& values) -> Status {
    if (!ref.present) return Status::success();
    const uint64_t want = 4 + 4 * uint64_t{level_count} + 4 * per * vertices;  // vertices <= size / 12: no overflow
    if (ref.size != want || load_u32(p + ref.offset) != level_count)
      return refuse(what, std::string(tag) + " section is " + std::to_string(ref.size) + " bytes; " +
                              std::to_string(level_count) + " levels and " + std::to_string(vertices) + " vertices need " +
                              std::to_string(want) + " (u32 level count, f32 per level, " + std::to_string(per) +
                              " f32 per vertex)");
    get_words(p + ref.offset + 4, level_count, errors);
    get_words(p + ref.offset + 4 + 4 * uint64_t{level_count}, per * vertices, values);
    return Status::success();
  };
  if (Status st = get_column(tex0, "TEX0", 2, chain.uv_errors, chain.uvs); !st) return st;
  if (Status st = get_column(tex1, "TEX1", 2, chain.uv1_errors, chain.uvs1); !st) return st;
  if (Status st = get_column(col0, "COL0", 4, chain.color_errors, chain.colors); !st) return st;
  if (matl.present)
    if (Status st = get_materials(p + matl.offset, matl.size, what, chain); !st) return st;
  if (imgs.present)
    if (Status st = get_images(p + imgs.offset, imgs.size, what, chain.images); !st) return st;
  std::string message;
  const char* section = "LEVL";
  if (!validate_chain(chain, &message, &section)) return refuse(what, std::string(section) + " section: " + message);
  chain.authored_normals = (nrml_flags & kNrmlAuthored) != 0;
  if (chain.authored_normals)
    if (Status st = check_authored_normals(chain, what); !st) return st;
  if (vhat.present && !vhie.present) return refuse(what, "VHAT section without a hierarchy (VHIE)");
  if (vhie.present) {
    if (Status st = get_hierarchy(p + vhie.offset, vhie.size, what, chain.hierarchy, vhat.present ? &vhat : nullptr, p);
        !st)
      return st;
    if (!chain.levels.empty() && chain.hierarchy.leaf_count != chain.levels[0].vertex_count) {
      const std::string leaves = std::to_string(chain.hierarchy.leaf_count);
      chain.hierarchy = VertexTree{};
      return refuse(what, "VHIE section: hierarchy has " + leaves + " leaves but level 0 has " +
                              std::to_string(chain.levels[0].vertex_count) + " vertices");
    }
    if (Status st = check_leaf_attributes(chain, what); !st) return st;
  }
  out = std::move(chain);
  return Status::success();
}

Status write_lod_asset(const std::filesystem::path& path, const LodChain& chain) {
  return write_file_atomic(path, encode_lod_asset(chain));
}

namespace {

// The header and section table (`head`: the file's first bytes, up to the largest table)
// against the file's size, before the file is read whole: a file that is not an asset, or
// whose sections do not end where the file does, is refused from its first bytes.
Status check_lod_header(std::span<const uint8_t> head, uint64_t size, const std::string& what) {
  const uint8_t* p = head.data();
  uint32_t section_count = 0;
  if (Status st = check_fixed_header(p, size, what, section_count); !st) return st;
  const uint64_t table_end = kHeaderBytes + uint64_t{section_count} * kTableEntryBytes;
  if (table_end + kChecksumBytes > size || table_end > head.size())
    return refuse(what, "truncated: file is " + std::to_string(size) + " bytes, its section table alone needs " +
                            std::to_string(table_end + kChecksumBytes));
  uint64_t sections_end = table_end;
  for (uint32_t s = 0; s < section_count; ++s) {
    const uint8_t* e = p + kHeaderBytes + s * kTableEntryBytes;
    const uint64_t off = load_u64(e + 8), sz = load_u64(e + 16);
    if (off > size || sz > size - off)
      return refuse(what, "section " + std::to_string(s) + " '" + tag_name(load_u32(e)) + "' [" + std::to_string(off) +
                              ", +" + std::to_string(sz) + ") lies outside the " + std::to_string(size) + "-byte file");
    sections_end = std::max(sections_end, off + sz);
  }
  if (sections_end + kChecksumBytes > size)
    return refuse(what, "truncated: file is " + std::to_string(size) + " bytes, its sections need " +
                            std::to_string(sections_end + kChecksumBytes));
  // The writer aligns the checksum to 8 bytes: up to 7 bytes of padding come before it.
  const uint64_t end = (sections_end + 7) / 8 * 8 + kChecksumBytes;
  if (size > end)
    return refuse(what, "file is " + std::to_string(size) + " bytes, its sections and checksum end at " +
                            std::to_string(end) + " (bytes after them)");
  return Status::success();
}

}  // namespace

Status read_lod_asset(const std::filesystem::path& path, LodChain& out) {
  // Regular files only (a FIFO named like an asset must not hang the reader), and the header
  // first: what it declares must end where the file does before the file is read whole.
  RegularFile f;
  if (Status s = open_regular_file(path, kInputFileLimit, f); !s) return s;
  std::vector<uint8_t> bytes;
  if (Status s = f.read_head(kHeaderBytes + kMaxSections * kTableEntryBytes, bytes); !s) return s;
  if (Status s = check_lod_header(bytes, f.size, path.string()); !s) return s;
  if (Status s = f.read_all(bytes); !s) return s;
  return decode_lod_asset(bytes, path.string(), out);
}

// ---- the MATL layout for other files (runtime/material_section.h) ---------------------------

std::vector<uint8_t> encode_material_section(const LodChain& chain) {
  Writer w;
  put_materials(w, chain);
  return std::move(w.bytes);
}

Status decode_material_section(std::span<const uint8_t> bytes, const std::string& what, LodChain& out) {
  LodChain c;
  if (Status st = get_materials(bytes.data(), bytes.size(), what, c); !st) return st;
  // The embedded:<k> checks count out.images; they are lent, not copied (they may be large).
  c.images = std::move(out.images);
  std::string message;
  const bool valid = validate_chain_materials(c, &message);
  out.images = std::move(c.images);
  if (!valid) return refuse(what, "MATL section: " + message);
  out.materials = std::move(c.materials);
  out.texture_base = std::move(c.texture_base);
  out.submeshes = std::move(c.submeshes);
  return Status::success();
}

std::vector<uint8_t> encode_image_section(std::span<const EmbeddedImage> images) {
  Writer w;
  put_images(w, images);
  return std::move(w.bytes);
}

Status decode_image_section(std::span<const uint8_t> bytes, const std::string& what, std::vector<EmbeddedImage>& out) {
  LodChain c;
  if (Status st = get_images(bytes.data(), bytes.size(), what, c.images); !st) return st;
  std::string message;
  if (!validate_chain_images(c, &message)) return refuse(what, "IMGS section: " + message);
  out = std::move(c.images);
  return Status::success();
}

}  // namespace lod
