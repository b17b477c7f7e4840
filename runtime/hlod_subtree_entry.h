// One baked HLOD subtree as bytes: the entry format of the distributed bake's cache.
// An entry is hostile input like any file: every count is checked against the size before
// anything is allocated, every index against what it indexes, every byte against a checksum,
// and the key it was written under against the one asked for. A refused entry leaves the
// output untouched (and the bake rebakes it).
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "runtime/hlod_subtree.h"
#include "runtime/status.h"

namespace lod {

// 3: .hlod version 3 inside (colours, uv1); 2: version 2 (uvs, material runs)
inline constexpr uint32_t kHlodSubtreeEntryVersion = 3;

// `key`: what the entry is stored under (the hash of its inputs); written into the entry.
std::vector<uint8_t> encode_hlod_subtree(const HlodSubtree& subtree, uint64_t key);

// Refuses anything that is not an entry for `key` whose vertex sources lie below
// `mesh_vertices`; `what` names the entry in messages.
Status decode_hlod_subtree(std::span<const uint8_t> bytes, uint64_t key, uint64_t mesh_vertices,
                           const std::string& what, HlodSubtree& out);

// The root alone, from an entry's first bytes (the levels above need only the
// subtrees' roots, so the rank that assembles them reads a few percent of each entry):
// `prefix` starts the entry of `entry_size` bytes and must hold hlod_subtree_entry_root_bytes
// of it. `out` gets every node's record, payloads[0] (the root's) and the root's sources and
// references; the header, the embedded head and the root payload are checked as in
// decode_hlod_subtree (the other payloads are checked by whoever reads them).
Status decode_hlod_subtree_root(std::span<const uint8_t> prefix, uint64_t entry_size, uint64_t key,
                                uint64_t mesh_vertices, const std::string& what, HlodSubtree& out);
// How many leading bytes decode_hlod_subtree_root needs, from as many as `prefix` holds (read
// more and ask again while the answer exceeds prefix.size()); 0: not an entry it can read.
uint64_t hlod_subtree_entry_root_bytes(std::span<const uint8_t> prefix, uint64_t entry_size);

// Each node's payload (data and checksum, as an .hlod file stores it) inside a whole entry, by
// node, after checking the embedded head; the spans point into `entry`.
Status hlod_subtree_entry_payloads(std::span<const uint8_t> entry, const std::string& what,
                                   std::vector<std::span<const uint8_t>>& out);

}  // namespace lod
