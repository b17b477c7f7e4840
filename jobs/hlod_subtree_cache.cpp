// The subtree cache: key, path, store (temporary -> read back -> rename), load.
#include "jobs/hlod_subtree_cache.h"

#include <unistd.h>

#include <atomic>
#include <bit>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <vector>

#include "runtime/file_write.h"
#include "runtime/hlod_subtree_entry.h"
#include "runtime/lod_asset.h"  // hash_bytes

namespace lod {
namespace {

// The whole file; `opened` false when it does not exist. Anything else unreadable (a folder in
// its place, an I/O error) is read as no bytes, which the decoder refuses.
std::vector<uint8_t> read_all(const std::filesystem::path& path, bool& opened) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  opened = std::filesystem::exists(status);
  if (!opened || !std::filesystem::is_regular_file(status)) return {};
  try {
    std::ifstream f(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
  } catch (const std::exception&) {
    return {};
  }
}

}  // namespace

uint64_t hlod_subtree_key(uint64_t source_hash, const HlodBuildOptions& o, const HlodSubtreeSpec& spec) {
  const uint64_t words[8] = {source_hash,
                             kHlodSubtreeEntryVersion,
                             o.min_verts,
                             std::bit_cast<uint32_t>(o.max_error_per_cell),
                             std::bit_cast<uint32_t>(o.layer_samples_per_triangle),
                             o.reference_samples,
                             spec.fingerprint,
                             1 /* build version, as hlod_source_hash */};
  return hash_bytes(words, sizeof words, 0x68737562ull);
}

std::filesystem::path hlod_subtree_entry_path(const std::filesystem::path& dir, uint64_t key) {
  char name[32];
  std::snprintf(name, sizeof name, "%016llx.hsub", static_cast<unsigned long long>(key));
  return dir / name;
}

Status store_hlod_subtree(const std::filesystem::path& dir, uint64_t key, uint64_t mesh_vertices,
                          const HlodSubtree& subtree, uint64_t* bytes_written) {
  static std::atomic<uint64_t> serial{0};
  const std::filesystem::path path = hlod_subtree_entry_path(dir, key);
  char suffix[64];  // a temporary of this process's own, beside the entry
  std::snprintf(suffix, sizeof suffix, ".%d.%llu.tmp", int(::getpid()), static_cast<unsigned long long>(serial++));
  std::filesystem::path temp = dir / ".";
  temp += path.filename();
  temp += suffix;
  const std::vector<uint8_t> bytes = encode_hlod_subtree(subtree, key);
  if (Status s = write_file_atomic(temp, bytes); !s) return s;
  bool opened = false;
  const std::vector<uint8_t> back = read_all(temp, opened);
  HlodSubtree check;
  Status verified = opened ? decode_hlod_subtree(back, key, mesh_vertices, temp.string(), check)
                           : Status::error(temp.string() + ": cannot be read back");
  if (verified && back != bytes) verified = Status::error(temp.string() + ": reads back other bytes than were written");
  std::error_code ec;
  if (!verified) {
    std::filesystem::remove(temp, ec);
    return Status::error(path.string() + ": written entry does not verify: " + verified.message);
  }
  std::filesystem::rename(temp, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
    return Status::error(path.string() + ": cannot rename the verified entry into place: " + ec.message());
  }
  if (bytes_written) *bytes_written = bytes.size();
  return Status::success();
}

CacheLookup load_hlod_subtree(const std::filesystem::path& dir, uint64_t key, uint64_t mesh_vertices, HlodSubtree& out,
                              std::string* why, uint64_t* bytes_read) {
  const std::filesystem::path path = hlod_subtree_entry_path(dir, key);
  bool opened = false;
  const std::vector<uint8_t> bytes = read_all(path, opened);
  if (!opened) return CacheLookup::missing;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    if (why) *why = path.string() + ": is not a regular file";
    return CacheLookup::refused;
  }
  if (bytes_read) *bytes_read = bytes.size();
  if (Status s = decode_hlod_subtree(bytes, key, mesh_vertices, path.string(), out); !s) {
    if (why) *why = s.message;
    return CacheLookup::refused;
  }
  return CacheLookup::found;
}

}  // namespace lod
