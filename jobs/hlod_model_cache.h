// Content-addressed cache of whole baked models (a scene of many models split over
// ranks), beside the subtree entries on storage every rank sees: DIR/<key, 16 hex digits>.hlod,
// the model's .hlod exactly as `lod bake --hlod` writes it. An entry appears under its name only
// complete and verified (the bake's finished file read back and decoded in full, then renamed),
// so a rank killed mid-way leaves at worst a folder of its own; an entry that is nevertheless
// wrong (flipped bits, truncated, another model's) is refused when read and baked again, as is
// one marked bad (jobs/hlod_read_failures.h); storing an entry removes its mark.
#pragma once
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "jobs/hlod_subtree_cache.h"  // CacheLookup
#include "runtime/hlod_tree.h"
#include "runtime/status.h"

namespace lod {

inline constexpr uint32_t kHlodModelEntryVersion = 1;

// The key: the source's content hash (hlod_source_hash: the mesh file's bytes, min_verts and the
// build's version), the model's name (written in the file's head), the .hlod format version and
// this entry's version.
uint64_t hlod_model_key(uint64_t source_hash, const std::string& name);

std::filesystem::path hlod_model_entry_path(const std::filesystem::path& dir, uint64_t key);

// `bytes` as the .hlod of model `name` from `source_hash`: the .hlod reader's checks in full
// (counts, offsets, every checksum), the name and hash in its head, nothing after the last
// payload. `what` names the bytes in messages; `tree` (when given) gets the head.
Status check_hlod_model(std::span<const uint8_t> bytes, const std::string& name, uint64_t source_hash,
                        const std::string& what, HlodTree* tree = nullptr);

// Takes the finished file `baked` (on the cache's file system: a bake's output in a folder of
// its own inside DIR) into the cache: read back, checked, renamed to the entry's path. `bytes`
// gets the file's bytes. On failure `baked` is removed and the message names the entry.
Status store_hlod_model(const std::filesystem::path& dir, uint64_t key, const std::filesystem::path& baked,
                        const std::string& name, uint64_t source_hash, std::vector<uint8_t>& bytes,
                        HlodTree* tree = nullptr);

// found: `bytes` are the entry's, checked; refused: `why` says why (the caller removes it).
CacheLookup load_hlod_model(const std::filesystem::path& dir, uint64_t key, const std::string& name,
                            uint64_t source_hash, std::vector<uint8_t>& bytes, HlodTree* tree = nullptr,
                            std::string* why = nullptr);

}  // namespace lod
