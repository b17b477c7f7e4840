// The subtree entry, version 3 (the embedded asset is .hlod version 3: uvs, uv1, colours, material
// runs); little-endian:
//
//   magic "LODHSUB\n" (8) | u32 version | u32 root depth | u64 key | u64 short_layers |
//   u64 oversized_leaves | u32 source count S | u32 reference count R | u64 asset bytes A
//   S u32 root vertex sources | R u32 reference vertices
//   u64 checksum = hash_bytes(everything before it)
//   A bytes: the subtree as an .hlod asset (its root cell the asset's root cube, depths
//            relative to the subtree's root, source_hash = key, the material count without
//            the materials), with its own checksums
//
// The asset reader already refuses every broken count, offset, tree or payload; the entry adds
// what a spliced subtree needs on top: the key, the depth it sits at, the root's vertex sources.
#include "runtime/hlod_subtree_entry.h"

#include <algorithm>
#include <cstring>

#include "runtime/byte_order.h"
#include "runtime/hlod_asset.h"
#include "runtime/lod_asset.h"  // hash_bytes

namespace lod {
namespace {

constexpr char kMagic[8] = {'L', 'O', 'D', 'H', 'S', 'U', 'B', '\n'};
constexpr uint64_t kFixedBytes = 56;
constexpr uint64_t kChecksumBytes = 8;

Status refuse(const std::string& what, const std::string& why) { return Status::error(what + ": " + why); }

HlodTree relative_tree(const HlodSubtree& s, uint64_t key) {
  HlodTree t;
  const HlodNode& root = s.nodes[0];
  t.source_hash = key;
  t.min_verts = 1;  // the key holds the settings
  for (int k = 0; k < 3; ++k) t.box_center[k] = root.box_center[k];
  t.box_half = root.box_half;
  t.nodes = s.nodes;
  t.uvs = root.uvs;
  t.uvs1 = root.uvs1;
  t.colors = root.colors;
  t.material_count = s.material_count;
  for (HlodNode& n : t.nodes) n.depth = uint8_t(n.depth - root.depth);
  return t;
}

std::vector<uint32_t> get_ids(const uint8_t* p, uint32_t count) {
  std::vector<uint32_t> ids(count);
  for (uint32_t i = 0; i < count; ++i) ids[i] = detail::load_u32(p + 4 * size_t(i));
  return ids;
}

// The decoded asset as the subtree it was: depths back at the subtree's place, no offsets.
Status place_tree(HlodTree& t, uint32_t depth, const std::string& what) {
  for (HlodNode& n : t.nodes) {
    if (n.depth + depth > kHlodMaxDepth)
      return refuse(what, "subtree at depth " + std::to_string(depth) + " reaches below depth " + std::to_string(kHlodMaxDepth));
    n.depth = uint8_t(n.depth + depth);
    n.payload_offset = n.payload_size = 0;
  }
  return Status::success();
}

// The entry's header (everything before the embedded asset) checked: its size in `head`.
Status check_header(std::span<const uint8_t> bytes, uint64_t entry_size, uint64_t key, const std::string& what,
                    uint64_t& head) {
  using detail::load_u32;
  using detail::load_u64;
  const uint8_t* p = bytes.data();
  if (bytes.size() < kFixedBytes + kChecksumBytes || entry_size < kFixedBytes + kChecksumBytes)
    return refuse(what, "entry is " + std::to_string(entry_size) + " bytes, too short (truncated?)");
  if (std::memcmp(p, kMagic, 8) != 0) return refuse(what, "not an HLOD subtree entry (bad magic bytes)");
  if (load_u32(p + 8) != kHlodSubtreeEntryVersion)
    return refuse(what, "entry version " + std::to_string(load_u32(p + 8)) + " is not " +
                            std::to_string(kHlodSubtreeEntryVersion));
  const uint32_t depth = load_u32(p + 12), sources = load_u32(p + 40), references = load_u32(p + 44);
  const uint64_t asset_bytes = load_u64(p + 48);
  head = kFixedBytes + 4ull * sources + 4ull * references;
  if (head + kChecksumBytes > entry_size || asset_bytes != entry_size - head - kChecksumBytes)
    return refuse(what, "entry is " + std::to_string(entry_size) + " bytes, its counts (" + std::to_string(sources) +
                            " sources, " + std::to_string(references) + " references, asset of " +
                            std::to_string(asset_bytes) + ") say otherwise (truncated?)");
  if (head + kChecksumBytes > bytes.size()) return refuse(what, "entry header not read whole");
  if (load_u64(p + head) != hash_bytes(p, head)) return refuse(what, "entry checksum mismatch (corrupted)");
  if (load_u64(p + 16) != key) return refuse(what, "entry was written for another key (a stale or misplaced entry)");
  if (depth > kHlodMaxDepth) return refuse(what, "subtree depth " + std::to_string(depth) + " is too deep");
  return Status::success();
}

// What the header says of the root, once the nodes are decoded: its depth, counts, sources.
Status take_header(const uint8_t* p, uint64_t mesh_vertices, const std::string& what, HlodSubtree& s) {
  using detail::load_u32;
  using detail::load_u64;
  const uint32_t sources = load_u32(p + 40), references = load_u32(p + 44);
  s.short_layers = load_u64(p + 24);
  s.oversized_leaves = load_u64(p + 32);
  const HlodNode& root = s.nodes[0];
  if (sources != root.layers[root.layer_count - 1].vertices)
    return refuse(what, std::to_string(sources) + " vertex sources for a root layer of " +
                            std::to_string(root.layers[root.layer_count - 1].vertices) + " vertices");
  s.root_source = get_ids(p + kFixedBytes, sources);
  s.root_reference = get_ids(p + kFixedBytes + 4ull * sources, references);
  for (uint32_t v : s.root_source)
    if (v >= mesh_vertices) return refuse(what, "vertex source " + std::to_string(v) + " is not among the mesh's " + std::to_string(mesh_vertices));
  for (uint32_t v : s.root_reference)
    if (v >= mesh_vertices) return refuse(what, "reference vertex " + std::to_string(v) + " is not among the mesh's " + std::to_string(mesh_vertices));
  return Status::success();
}

}  // namespace

std::vector<uint8_t> encode_hlod_subtree(const HlodSubtree& s, uint64_t key) {
  detail::ByteWriter w;
  for (char c : kMagic) w.u8(uint8_t(c));
  w.u32(kHlodSubtreeEntryVersion);
  w.u32(s.nodes[0].depth);
  w.u64(key);
  w.u64(s.short_layers);
  w.u64(s.oversized_leaves);
  w.u32(uint32_t(s.root_source.size()));
  w.u32(uint32_t(s.root_reference.size()));
  const size_t asset_size_at = w.bytes.size();
  w.u64(0);  // the asset's size and the header's checksum, once the asset is appended after them
  w.words(s.root_source.data(), s.root_source.size());
  w.words(s.root_reference.data(), s.root_reference.size());
  const size_t checksum_at = w.bytes.size();
  w.u64(0);
  w.patch_u64(asset_size_at, append_hlod_asset(relative_tree(s, key), s.payloads, w.bytes));
  w.patch_u64(checksum_at, hash_bytes(w.bytes.data(), checksum_at));
  return std::move(w.bytes);
}

Status decode_hlod_subtree(std::span<const uint8_t> bytes, uint64_t key, uint64_t mesh_vertices,
                           const std::string& what, HlodSubtree& out) {
  uint64_t head = 0;
  if (Status st = check_header(bytes, bytes.size(), key, what, head); !st) return st;
  HlodSubtree s;
  HlodTree tree;
  if (Status st = decode_hlod_asset(bytes.subspan(head + kChecksumBytes), what, tree, s.payloads); !st) return st;
  if (tree.source_hash != key) return refuse(what, "embedded subtree was written for another key");
  if (Status st = place_tree(tree, detail::load_u32(bytes.data() + 12), what); !st) return st;
  s.material_count = tree.material_count;
  s.nodes = std::move(tree.nodes);
  if (Status st = take_header(bytes.data(), mesh_vertices, what, s); !st) return st;
  out = std::move(s);
  return Status::success();
}

uint64_t hlod_subtree_entry_root_bytes(std::span<const uint8_t> prefix, uint64_t entry_size) {
  using detail::load_u32;
  using detail::load_u64;
  if (prefix.size() < kFixedBytes) return std::min<uint64_t>(entry_size, kFixedBytes + kChecksumBytes);
  const uint64_t asset = kFixedBytes + 4ull * load_u32(prefix.data() + 40) + 4ull * load_u32(prefix.data() + 44) + kChecksumBytes;
  if (asset + 16 > entry_size) return 0;
  if (prefix.size() < asset + 16) return asset + 16;
  const uint64_t asset_head = load_u32(prefix.data() + asset + 12);  // the asset's head bytes H
  const uint64_t first_payload = asset + asset_head + kChecksumBytes;
  if (asset_head < 16 || first_payload > entry_size) return 0;
  if (prefix.size() < first_payload) return first_payload;
  // The root's payload follows the head; its size is the offset table's first entry, which
  // opens the table's last count * 16 bytes before H.
  const uint64_t count = asset_head >= 96 ? load_u32(prefix.data() + asset + 72) : 0;
  if (count == 0 || 16 * count > asset_head) return 0;
  const uint64_t size = load_u64(prefix.data() + asset + asset_head - 16 * count + 8);
  if (size > entry_size - first_payload) return 0;
  return first_payload + size;
}

Status decode_hlod_subtree_root(std::span<const uint8_t> prefix, uint64_t entry_size, uint64_t key,
                                uint64_t mesh_vertices, const std::string& what, HlodSubtree& out) {
  uint64_t head = 0;
  if (Status st = check_header(prefix, entry_size, key, what, head); !st) return st;
  const uint64_t need = hlod_subtree_entry_root_bytes(prefix, entry_size);
  if (need == 0 || need > prefix.size()) return refuse(what, "entry's root not read whole (truncated?)");
  const std::span<const uint8_t> asset = prefix.subspan(head + kChecksumBytes);
  HlodTree tree;
  if (Status st = decode_hlod_tree(asset, entry_size - head - kChecksumBytes, what, tree); !st) return st;
  if (tree.source_hash != key) return refuse(what, "embedded subtree was written for another key");
  const HlodNode& root = tree.nodes[0];
  if (root.payload_offset + root.payload_size > asset.size()) return refuse(what, "entry's root not read whole (truncated?)");
  HlodSubtree s;
  s.payloads.resize(1);
  if (Status st = decode_hlod_payload(asset.subspan(root.payload_offset, root.payload_size), root, tree.material_count,
                                      what + ": root", s.payloads[0]);
      !st)
    return st;
  if (Status st = place_tree(tree, detail::load_u32(prefix.data() + 12), what); !st) return st;
  s.material_count = tree.material_count;
  s.nodes = std::move(tree.nodes);
  if (Status st = take_header(prefix.data(), mesh_vertices, what, s); !st) return st;
  out = std::move(s);
  return Status::success();
}

Status hlod_subtree_entry_payloads(std::span<const uint8_t> entry, const std::string& what,
                                   std::vector<std::span<const uint8_t>>& out) {
  if (entry.size() < kFixedBytes + kChecksumBytes) return refuse(what, "entry too short (truncated?)");
  const uint64_t head = kFixedBytes + 4ull * detail::load_u32(entry.data() + 40) + 4ull * detail::load_u32(entry.data() + 44);
  if (head + kChecksumBytes > entry.size()) return refuse(what, "entry header runs past its end (truncated?)");
  const std::span<const uint8_t> asset = entry.subspan(head + kChecksumBytes);
  HlodTree tree;
  if (Status st = decode_hlod_tree(asset, asset.size(), what, tree); !st) return st;
  out.clear();
  for (const HlodNode& n : tree.nodes) out.push_back(asset.subspan(n.payload_offset, n.payload_size));
  return Status::success();
}

}  // namespace lod
