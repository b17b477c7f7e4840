// The .hlod file (Zhou and Tian, Fig. 6): a header, the octree as breadth-first OctreeCode and
// NodeDescription bits, per-node metadata and a per-node offset table (all checksummed
// together: the "head"), then each node's payload with a checksum of its own, so that one
// node can be read and verified without reading the rest.
//
// Nothing in a file is trusted: every count is checked against the sizes before anything is
// allocated, every offset and index before it is used, the tree against its bits (parents,
// child ranges, depth <= kHlodMaxDepth), values for finiteness and errors for monotonicity.
// A refused file leaves the output untouched.
#pragma once
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "runtime/hlod_tree.h"
#include "runtime/status.h"

namespace lod {

// 3: colours (COLOR_0) and a second uv set (TEXCOORD_1); 2: uvs, materials and material runs.
// Version 2 files are still read (3 only adds flags); version 1 is refused.
inline constexpr uint32_t kHlodAssetVersion = 3;

// The whole file. Offsets and sizes in the written file are computed here (tree's own
// payload_offset / payload_size are ignored); payloads[i] is node i's geometry.
std::vector<uint8_t> encode_hlod_asset(const HlodTree& tree, std::span<const HlodPayload> payloads);
// The same bytes appended to `out`, which grows once to hold them (an asset of hundreds of MB is
// not built in pieces and copied together); returns how many were appended.
uint64_t append_hlod_asset(const HlodTree& tree, std::span<const HlodPayload> payloads, std::vector<uint8_t>& out);

// The same in pieces, for a writer that places each payload itself (every rank
// writes its own subtrees' payloads): the head, whose offset table lays the payloads out back to
// back in node order with these sizes, and one node's payload (its data, then its checksum).
std::vector<uint8_t> encode_hlod_head(const HlodTree& tree, std::span<const uint64_t> payload_sizes);
std::vector<uint8_t> encode_hlod_payload(const HlodPayload& payload);
// The bytes encode_hlod_payload gives for a payload matching `node`'s counts.
uint64_t hlod_payload_bytes(const HlodNode& node);

// The tree from the file's first bytes (`head`: at least the head, possibly the whole file);
// `file_size` is the whole file's, so that every payload range can be checked. `what` names
// the source in messages.
Status decode_hlod_tree(std::span<const uint8_t> head, uint64_t file_size, const std::string& what, HlodTree& out);
// One node's payload from its own bytes (exactly node.payload_size of them, read at
// node.payload_offset), checked against `node` (a node of a tree decode_hlod_tree accepted)
// and its run's material ids against `materials` (the tree's material_count).
Status decode_hlod_payload(std::span<const uint8_t> bytes, const HlodNode& node, uint32_t materials,
                           const std::string& what, HlodPayload& out);
// Everything, from the whole file in memory.
Status decode_hlod_asset(std::span<const uint8_t> file, const std::string& what, HlodTree& tree,
                         std::vector<HlodPayload>& payloads);

// Temporary file + rename, as .lod assets.
Status write_hlod_asset(const std::filesystem::path& path, const HlodTree& tree, std::span<const HlodPayload> payloads);

// An open .hlod file: the head is read and checked once, nodes are read one at a time.
// read_node may be called from several threads at once (positioned reads on one descriptor).
class HlodFile {
 public:
  HlodFile() = default;
  ~HlodFile();
  HlodFile(HlodFile&& other) noexcept;
  HlodFile& operator=(HlodFile&& other) noexcept;
  HlodFile(const HlodFile&) = delete;
  HlodFile& operator=(const HlodFile&) = delete;

  // Regular files only (a FIFO never blocks the reader). Reads the head, not the payloads.
  Status open(const std::filesystem::path& path, HlodTree& tree);
  // Every read checks the payload's checksum. A failure names the file and why; with the
  // node's index, the node too ("scene.hlod: node 17: payload checksum mismatch ...").
  Status read_node(const HlodNode& node, HlodPayload& out) const;
  Status read_node(uint32_t index, const HlodNode& node, HlodPayload& out) const;
  bool is_open() const { return fd_ >= 0; }

 private:
  Status read_node_as(const HlodNode& node, const std::string& what, HlodPayload& out) const;

  int fd_ = -1;
  uint64_t size_ = 0;
  uint32_t materials_ = 0;  // the tree's material_count, for the runs' ids
  std::string path_;
};

// Header + tree + offsets only.
Status read_hlod_tree(const std::filesystem::path& path, HlodTree& out);
// One node of the file at `path` (the node from read_hlod_tree of the same file).
Status read_hlod_node(const std::filesystem::path& path, const HlodNode& node, HlodPayload& out);
// The same, naming node `index` in messages.
Status read_hlod_node(const std::filesystem::path& path, uint32_t index, const HlodNode& node, HlodPayload& out);

// Bytes a payload with these counts takes in memory (positions, normals, uvs, uv1, colours,
// indices, runs),
// as HlodNode::resident_bytes counts them.
uint64_t hlod_resident_bytes(const HlodNode& node);

namespace detail {
// One vertex in a payload: position and normal (24), each uv set (8), RGBA (16). What the
// resident bytes count and what the encoder sizes its buffer by.
constexpr uint64_t hlod_vertex_bytes(bool uvs, bool uvs1, bool colors) {
  return 24 + (uvs ? 8 : 0) + (uvs1 ? 8 : 0) + (colors ? 16 : 0);
}
}  // namespace detail

}  // namespace lod
