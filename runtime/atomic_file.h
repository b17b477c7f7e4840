// Whole-file writes that never leave a half-written file: a temporary beside it, then rename.
#pragma once
#include <cstdint>
#include <filesystem>
#include <span>

#include "runtime/status.h"

namespace lod {

// Writes `bytes` to a temporary name of its own (per process and call) beside `path`, then
// renames it over `path`; concurrent writers of one path each replace it whole (last wins).
// Messages name `path`.
Status write_file_atomically(const std::filesystem::path& path, std::span<const uint8_t> bytes);

}  // namespace lod
