// The subtree cache: key, path, store (temporary -> read back -> rename), load.
#include "jobs/hlod_subtree_cache.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <span>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "jobs/hlod_bake.h"  // kHlodBuildVersion
#include "runtime/file_write.h"
#include "runtime/hlod_subtree_entry.h"
#include "runtime/lod_asset.h"  // hash_bytes
#include "runtime/regular_file.h"

namespace lod {
namespace {

// `out.size()` bytes from `offset`, retrying short reads; false on an error or an early end.
bool read_at(int fd, uint64_t offset, std::span<uint8_t> out) {
  size_t done = 0;
  while (done < out.size()) {
    const ssize_t n = ::pread(fd, out.data() + done, out.size() - done, off_t(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += size_t(n);
  }
  return true;
}

// The whole file; `opened` false when it does not exist. Anything else unreadable (a folder in
// its place, an I/O error) is read as no bytes, which the decoder refuses. A file whose first
// bytes are not an entry is not read further: those are enough for the decoder to say why.
std::vector<uint8_t> read_all(const std::filesystem::path& path, bool& opened) {
  std::error_code ec;
  opened = std::filesystem::exists(std::filesystem::symlink_status(path, ec));
  RegularFile f;
  std::vector<uint8_t> bytes;
  if (!opened || !open_regular_file(path, kInputFileLimit, f) || !f.read_head(64 * 1024, bytes)) return {};
  if (hlod_subtree_entry_root_bytes(bytes, f.size) == 0) return bytes;
  if (!f.read_all(bytes)) return {};
  return bytes;
}

}  // namespace

uint64_t hlod_subtree_key(uint64_t source_hash, const HlodBuildOptions& o, const HlodSubtreeSpec& spec) {
  const uint64_t words[9] = {source_hash,
                             kHlodSubtreeEntryVersion,
                             o.min_verts,
                             std::bit_cast<uint32_t>(o.max_error_per_cell),
                             std::bit_cast<uint32_t>(o.layer_samples_per_triangle),
                             o.reference_samples,
                             spec.fingerprint,
                             kHlodBuildVersion /* as hlod_source_hash */,
                             std::bit_cast<uint32_t>(o.uv_weight)};
  return hash_bytes(words, sizeof words, 0x68737562ull);
}

std::filesystem::path hlod_subtree_entry_path(const std::filesystem::path& dir, uint64_t key) {
  char name[32];
  std::snprintf(name, sizeof name, "%016llx.hsub", static_cast<unsigned long long>(key));
  return dir / name;
}

Status store_hlod_subtree(const std::filesystem::path& dir, uint64_t key, uint64_t mesh_vertices,
                          const HlodSubtree& subtree, uint64_t* bytes_written, std::vector<uint8_t>* entry) {
  const std::filesystem::path path = hlod_subtree_entry_path(dir, key);
  std::filesystem::path temp = dir / ".";  // a temporary of this writer's own, beside the entry
  temp += path.filename();
  remove_dead_temporaries(dir, temp.filename().string());  // what killed writers of it left
  temp += unique_temporary_suffix();
  std::vector<uint8_t> bytes = encode_hlod_subtree(subtree, key);
  (void)mesh_vertices;
  // Read back from the disk and compared before it is trusted (a reader still decodes and
  // checks an entry in full whenever it takes one up).
  if (Status s = write_new_file_checked(temp, bytes, path.string()); !s)
    return Status::error(s.message + " (the entry was not stored)");
  std::error_code ec;
  std::filesystem::rename(temp, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
    return Status::error(path.string() + ": cannot rename the verified entry into place: " + ec.message());
  }
  if (bytes_written) *bytes_written = bytes.size();
  if (entry) *entry = std::move(bytes);
  return Status::success();
}

CacheLookup load_hlod_subtree(const std::filesystem::path& dir, uint64_t key, uint64_t mesh_vertices, HlodSubtree& out,
                              std::string* why, uint64_t* bytes_read, std::vector<uint8_t>* entry) {
  const std::filesystem::path path = hlod_subtree_entry_path(dir, key);
  bool opened = false;
  std::vector<uint8_t> bytes = read_all(path, opened);
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
  if (entry) *entry = std::move(bytes);
  return CacheLookup::found;
}

Status read_hlod_subtree_entry(const std::filesystem::path& dir, uint64_t key, uint64_t size,
                               std::vector<uint8_t>& bytes) {
  const std::filesystem::path path = hlod_subtree_entry_path(dir, key);
  RegularFile f;
  if (Status s = open_regular_file(path, kInputFileLimit, f); !s) return s;
  const int fd = f.fd;
  std::string wrong;
  if (f.size != size)
    wrong = "is " + std::to_string(f.size) + " bytes, not the " + std::to_string(size) + " this rank had";
  if (wrong.empty()) {
    bytes.clear();  // a buffer reused: nothing copied when it grows
    bytes.resize(size_t(size));
    if (!read_at(fd, 0, bytes)) wrong = "cannot be read";
    // Read once: its page-cache pages go back at once, for the next read to reuse.
    ::posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED);
  }
  if (wrong.empty()) return Status::success();
  std::vector<uint8_t>().swap(bytes);
  return Status::error(path.string() + ": " + wrong);
}

CacheLookup load_hlod_subtree_root(const std::filesystem::path& dir, uint64_t key, uint64_t mesh_vertices,
                                   HlodSubtree& out, std::string* why, uint64_t* bytes_read) {
  const std::filesystem::path path = hlod_subtree_entry_path(dir, key);
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) return CacheLookup::missing;
  auto refused = [&](const std::string& message) {
    if (why) *why = message;
    return CacheLookup::refused;
  };
  if (!std::filesystem::is_regular_file(status)) return refused(path.string() + ": is not a regular file");
  RegularFile f;
  if (Status s = open_regular_file(path, kInputFileLimit, f); !s) return refused(s.message);
  const int fd = f.fd;
  const uint64_t size = f.size;
  // Most roots lie in the first 64 KiB; otherwise each answer names the bytes still wanted.
  std::vector<uint8_t> prefix(size_t(std::min<uint64_t>(size, 64 * 1024)));
  bool read = read_at(fd, 0, prefix);
  for (int step = 0; read && step < 4; ++step) {
    const uint64_t need = hlod_subtree_entry_root_bytes(prefix, size);
    if (need == 0 || need <= prefix.size() || need > size) break;  // the decoder names it
    const size_t have = prefix.size();
    prefix.resize(size_t(need));
    read = read_at(fd, have, std::span<uint8_t>(prefix).subspan(have));
  }
  if (!read) return refused(path.string() + ": cannot be read (truncated?)");
  if (bytes_read) *bytes_read = prefix.size();
  if (Status s = decode_hlod_subtree_root(prefix, size, key, mesh_vertices, path.string(), out); !s)
    return refused(s.message);
  return CacheLookup::found;
}

}  // namespace lod
