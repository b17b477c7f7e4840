// Content-addressed cache of baked HLOD subtrees, a folder on storage every rank
// sees: DIR/<key, 16 hex digits>.hsub, one file per subtree, in runtime/hlod_subtree_entry's
// format. An entry appears under its name only complete and verified (written to a temporary
// file, read back and decoded, then renamed), so a rank killed mid-write leaves at worst a
// temporary; an entry that is nevertheless wrong (flipped bits, truncated, another key) is
// refused when read and baked again.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "preprocess/hlod_build.h"
#include "runtime/hlod_subtree.h"
#include "runtime/status.h"

namespace lod {

// The key: the source's content hash (the mesh file's bytes and min_verts: every layer's error
// is measured against the whole original surface and rim normals see neighbouring triangles,
// so a subtree's bytes depend on the whole mesh), the builder's other options, the entry
// format version and the subtree's own fingerprint (depth, cell, triangles, locks).
uint64_t hlod_subtree_key(uint64_t source_hash, const HlodBuildOptions& options, const HlodSubtreeSpec& spec);

std::filesystem::path hlod_subtree_entry_path(const std::filesystem::path& dir, uint64_t key);

// Writes, verifies and renames into place; the message names the entry and what failed.
// Returns the entry's size in `bytes_written` when given.
// `entry` (when given) gets the entry's bytes, as they are on the disk.
Status store_hlod_subtree(const std::filesystem::path& dir, uint64_t key, uint64_t mesh_vertices,
                          const HlodSubtree& subtree, uint64_t* bytes_written = nullptr,
                          std::vector<uint8_t>* entry = nullptr);

enum class CacheLookup : uint8_t { found, missing, refused };
// `why` says why an entry was refused; `bytes_read` its size.
// `entry` (when given) gets the checked entry's bytes.
CacheLookup load_hlod_subtree(const std::filesystem::path& dir, uint64_t key, uint64_t mesh_vertices,
                              HlodSubtree& out, std::string* why = nullptr, uint64_t* bytes_read = nullptr,
                              std::vector<uint8_t>* entry = nullptr);
// An entry's bytes, when it is a regular file of exactly `size` bytes (checked before anything
// is allocated): how a rank reads back an entry it stored or checked earlier in the job.
Status read_hlod_subtree_entry(const std::filesystem::path& dir, uint64_t key, uint64_t size,
                               std::vector<uint8_t>& bytes);

// The subtree's nodes and root only (decode_hlod_subtree_root), read from the entry's first
// bytes: what the levels above need. `bytes_read`: how many were read.
CacheLookup load_hlod_subtree_root(const std::filesystem::path& dir, uint64_t key, uint64_t mesh_vertices,
                                   HlodSubtree& out, std::string* why = nullptr, uint64_t* bytes_read = nullptr);

}  // namespace lod
