// Regular files only, bounded before they are read (runtime/regular_file.h).
#include "runtime/regular_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <new>

#include "runtime/bytes_hasher.h"

namespace lod {
namespace {

// What a file that is not regular is, for the message; nullptr for a regular file.
const char* not_regular(mode_t m) {
  if (S_ISREG(m)) return nullptr;
  if (S_ISDIR(m)) return "is a directory, not a regular file";
  if (S_ISFIFO(m)) return "is a FIFO, not a regular file";
  if (S_ISSOCK(m)) return "is a socket, not a regular file";
  if (S_ISCHR(m)) return "is a character device, not a regular file";
  if (S_ISBLK(m)) return "is a block device, not a regular file";
  return "is not a regular file";
}

Status check_stat(const std::string& what, const struct stat& st, FileLimit limit) {
  if (const char* k = not_regular(st.st_mode)) return Status::error(what + ": " + k);
  if (uint64_t(st.st_size) > limit.max_bytes)
    return Status::error(what + ": is " + std::to_string(st.st_size) + " bytes; " + limit.kind + " is at most " +
                         std::to_string(limit.max_bytes) + " bytes");
  return Status::success();
}

}  // namespace

uint64_t physical_memory_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  if (pages <= 0 || page <= 0) return std::numeric_limits<uint64_t>::max();
  return uint64_t(pages) * uint64_t(page);
}

Status check_regular_file(const std::filesystem::path& path, FileLimit limit, uint64_t* size) {
  const std::string what = path.string();
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    const int e = errno;
    if (e == ENOENT) return Status::error(what + ": no such file");
    if (e == ENOTDIR) return Status::error(what + ": no such file (a parent is not a directory)");
    return Status::error(what + ": cannot be read (" + std::strerror(e) + ")");
  }
  if (Status s = check_stat(what, st, limit); !s) return s;
  if (size) *size = uint64_t(st.st_size);
  return Status::success();
}

Status open_regular_file(const std::filesystem::path& path, FileLimit limit, RegularFile& out) {
  if (Status s = check_regular_file(path, limit); !s) return s;
  RegularFile f;
  f.what = path.string();
  // O_NONBLOCK: a FIFO swapped in since the stat does not block the open; fstat then refuses it.
  f.fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (f.fd < 0) return Status::error(f.what + ": cannot be opened for reading (" + std::strerror(errno) + ")");
  struct stat st {};
  if (::fstat(f.fd, &st) != 0) return Status::error(f.what + ": cannot be read (" + std::strerror(errno) + ")");
  if (Status s = check_stat(f.what, st, limit); !s) return s;
  f.size = uint64_t(st.st_size);
  out = std::move(f);
  return Status::success();
}

RegularFile::~RegularFile() {
  if (fd >= 0) ::close(fd);
}

size_t RegularFile::read_at(uint8_t* into, size_t n, uint64_t offset, Status& st) const {
  size_t got = 0;
  while (got < n) {
    const ssize_t r = ::pread(fd, into + got, n - got, off_t(offset + got));
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) {
      st = Status::error(what + ": read error (" + std::strerror(errno) + ")");
      return got;
    }
    if (r == 0) break;  // the end, or it shrank while reading
    got += size_t(r);
  }
  return got;
}

Status RegularFile::read_head(size_t n, std::vector<uint8_t>& out) const {
  out.resize(size_t(std::min<uint64_t>(size, n)));
  Status st;
  out.resize(read_at(out.data(), out.size(), 0, st));
  return st;
}

Status RegularFile::read_exactly(uint64_t offset, uint64_t n, std::vector<uint8_t>& out) const {
  if (offset > size || n > size - offset)
    return Status::error(what + ": truncated: " + std::to_string(n) + " bytes at " + std::to_string(offset) +
                         " lie past its end (" + std::to_string(size) + " bytes)");
  if (n > physical_memory_bytes())
    return Status::error(what + ": " + std::to_string(n) + " bytes do not fit in this machine's memory");
  try {
    out.resize(size_t(n));
  } catch (const std::bad_alloc&) {
    return Status::error(what + ": not enough memory to read " + std::to_string(n) + " bytes of it");
  }
  Status st;
  const size_t got = read_at(out.data(), out.size(), offset, st);
  if (!st) return st;
  if (got != n)
    return Status::error(what + ": truncated: shrank while it was read (" + std::to_string(offset + got) + " of " +
                         std::to_string(size) + " bytes)");
  return Status::success();
}

Status RegularFile::read_all(std::vector<uint8_t>& out, uint64_t n) const {
  n = std::min(n, size);
  if (n > physical_memory_bytes())
    return Status::error(what + ": is " + std::to_string(size) + " bytes, more than this machine's memory (" +
                         std::to_string(physical_memory_bytes()) + " bytes)");
  try {
    out.resize(size_t(n));
  } catch (const std::bad_alloc&) {
    return Status::error(what + ": not enough memory to read its " + std::to_string(n) + " bytes");
  }
  Status st;
  out.resize(read_at(out.data(), out.size(), 0, st));  // shorter when it shrank: the reader names it
  return st;
}

Status read_regular_file(const std::filesystem::path& path, FileLimit limit, std::vector<uint8_t>& out) {
  RegularFile f;
  if (Status s = open_regular_file(path, limit, f); !s) return s;
  return f.read_all(out);
}

Status read_regular_file(const std::filesystem::path& path, FileLimit limit, std::string& out) {
  std::vector<uint8_t> bytes;
  if (Status s = read_regular_file(path, limit, bytes); !s) return s;
  out.assign(bytes.begin(), bytes.end());
  return Status::success();
}

Status hash_regular_file(const std::filesystem::path& path, uint64_t& hash, uint64_t seed) {
  RegularFile f;
  if (Status s = open_regular_file(path, {std::numeric_limits<uint64_t>::max(), "a file"}, f); !s) return s;
  std::vector<uint8_t> chunk(size_t(1) << 20);  // one small buffer, not the file's size in fresh memory
  BytesHasher h(seed);
  uint64_t total = 0;
  for (;;) {
    Status read;
    const size_t got = f.read_at(chunk.data(), chunk.size(), total, read);
    if (!read) return read;
    h.add(chunk.data(), got);
    total += got;
    if (got < chunk.size()) break;
  }
  hash = h.finish();
  return Status::success();
}

size_t first_nul_byte(const std::vector<uint8_t>& bytes) {
  const void* at = std::memchr(bytes.data(), 0, bytes.size());
  return at ? size_t(static_cast<const uint8_t*>(at) - bytes.data()) : SIZE_MAX;
}

Status check_text_head(const RegularFile& f, const char* format) {
  std::vector<uint8_t> head;
  if (Status s = f.read_head(kTextHeadBytes, head); !s) return s;
  if (const size_t at = first_nul_byte(head); at != SIZE_MAX)
    return Status::error(f.what + ": holds binary data (a NUL byte at offset " + std::to_string(at) + "), not " +
                         format + " text");
  return Status::success();
}

}  // namespace lod
