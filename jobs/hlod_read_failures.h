// What happens when a node of a streamed HLOD model cannot be read (its payload fails its
// checksum, the file is truncated, the storage errs): the failure names the file, the node and
// the reason, and a cached .hlod the bake made is marked bad, so that the next bake rebakes it
// instead of taking it up as "cached" again (the head alone, which a cached entry is checked by,
// says nothing about the payloads behind it).
//
// The mark is a file beside the entry, `<entry>.bad`, holding the reason; written atomically,
// removed once a fresh bake has replaced the entry.
#pragma once
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "jobs/hlod_models.h"
#include "runtime/status.h"

namespace lod {

std::filesystem::path bad_mark_path(const std::filesystem::path& entry);
// Writes `<entry>.bad` holding `why` (temporary + rename, as every file here).
Status mark_entry_bad(const std::filesystem::path& entry, const std::string& why);
// True when `<entry>.bad` exists; `why` (when given) gets the reason it holds.
bool entry_marked_bad(const std::filesystem::path& entry, std::string* why = nullptr);
// Removes the mark (after a fresh entry has replaced the bad one).
void clear_bad_mark(const std::filesystem::path& entry);

// `read` (or, when empty, read_hlod_node on models.files naming the node) with cache entries
// (models.cache_entry[m]) marked bad on their first failure; each failure of a marked entry's
// nodes then says so. Safe to call from several loader threads at once, as `read` must be.
ModelNodeLoader marking_bad_entries(std::shared_ptr<const HlodModels> models, ModelNodeLoader read);

// "<file>: node <node>: <why>", the model's file standing for it (its name when it has none);
// `why` as it is when it already starts with the file's name (the .hlod reader names the file
// and the node itself).
std::string hlod_failure_message(const HlodModels& models, uint32_t model, uint32_t node, const std::string& why);

}  // namespace lod
