// One baked HLOD subtree as bytes: the entry format of the distributed bake's cache (issue 16).
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

inline constexpr uint32_t kHlodSubtreeEntryVersion = 1;

// `key`: what the entry is stored under (the hash of its inputs); written into the entry.
std::vector<uint8_t> encode_hlod_subtree(const HlodSubtree& subtree, uint64_t key);

// Refuses anything that is not an entry for `key` whose vertex sources lie below
// `mesh_vertices`; `what` names the entry in messages.
Status decode_hlod_subtree(std::span<const uint8_t> bytes, uint64_t key, uint64_t mesh_vertices,
                           const std::string& what, HlodSubtree& out);

}  // namespace lod
