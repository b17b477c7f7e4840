// The .lod asset: versioned binary (magic, version, section table, checksum).
// A bad, truncated or wrong-version file is refused with a clear error, never half-loaded.
#pragma once
#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include "runtime/lod_chain.h"
#include "runtime/status.h"

namespace lod {

inline constexpr uint32_t kLodAssetVersion = 1;

std::vector<uint8_t> encode_lod_asset(const LodChain& chain);
// `what` names the source in messages (usually the file path).
Status decode_lod_asset(std::span<const uint8_t> bytes, const std::string& what, LodChain& out);

// Writes to a temporary file and renames, so a crash never leaves a half-written asset.
Status write_lod_asset(const std::filesystem::path& path, const LodChain& chain);
Status read_lod_asset(const std::filesystem::path& path, LodChain& out);

// 64-bit content hash over 8-byte words in four lanes, then mixed; any single changed byte
// changes it. Deterministic across runs and machines. Used by checksums and caches.
uint64_t hash_bytes(const void* data, size_t size, uint64_t seed = 0);

}  // namespace lod
