// write_file_atomic: temporary + fsync + rename, as the header says.
#include "runtime/file_write.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <string_view>

#include "runtime/host_turn.h"

namespace lod {

std::string describe_write_errno(int err) {
  switch (err) {
    case ENOSPC:
      return "the disk is full (no space left on device)";
    case EDQUOT:
      return "the disk quota is exceeded";
    case EROFS:
      return "the file system is read-only";
    case EACCES:
    case EPERM:
      return "permission denied";
    case EFBIG:
      return "the file is too large for this file system";
    case EIO:
      return "an I/O error occurred on the device";
    default:
      return std::strerror(err);
  }
}

Status write_all(int fd, std::span<const uint8_t> bytes, const std::string& what) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int err = n < 0 ? errno : EIO;
      return Status::error(what + ": " + describe_write_errno(err) + " after writing " +
                           std::to_string(done) + " of " + std::to_string(bytes.size()) + " bytes");
    }
    done += size_t(n);
  }
  return Status::success();
}

namespace {

// A name of its own per process and call: runs sharing a folder may write the same file at
// once, and each rename then replaces it whole (last one wins). What killed writers of the same
// file left there goes first.
std::filesystem::path temporary_beside(const std::filesystem::path& path) {
  const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  remove_dead_temporaries(dir, path.filename().string());
  std::filesystem::path tmp = path;
  tmp += unique_temporary_suffix();
  return tmp;
}

uint64_t fnv1a(uint64_t h, const std::string& text) {
  for (const unsigned char c : text) h = (h ^ c) * 0x100000001b3ull;
  return h;
}

std::string first_line_of(const char* file) {
  const int fd = ::open(file, O_RDONLY | O_CLOEXEC);
  if (fd < 0) return {};
  char buf[128];
  const ssize_t n = ::read(fd, buf, sizeof buf);
  ::close(fd);
  return n > 0 ? std::string(buf, size_t(n)) : std::string();
}

// Where a pid means something: the host's name, its boot and this process's pid namespace.
// Without the namespace to go by, a random draw: no other process shares the scope, so no
// temporary is ever taken for a dead writer's that might be a live one's.
uint64_t writer_scope() {
  static const uint64_t scope = [] {
    uint64_t h = 0xcbf29ce484222325ull;
    char host[256] = {};
    if (::gethostname(host, sizeof host - 1) == 0) h = fnv1a(h, host);
    h = fnv1a(h, first_line_of("/proc/sys/kernel/random/boot_id"));
    struct stat ns {};
    if (::stat("/proc/self/ns/pid", &ns) == 0) {
      h = fnv1a(h, std::to_string(ns.st_dev) + ":" + std::to_string(ns.st_ino));
    } else {
      std::random_device rd;
      h = fnv1a(h, std::to_string(rd()) + std::to_string(rd()));
    }
    return h;
  }();
  return scope;
}

// The pid in `suffix` when it is one of this scope's (".<scope>-<pid>-<n>.tmp"), else 0.
pid_t pid_of_suffix(std::string_view suffix, uint64_t scope) {
  char own[24];
  std::snprintf(own, sizeof own, ".%016llx-", static_cast<unsigned long long>(scope));
  const std::string_view head(own);
  if (suffix.size() <= head.size() + 4 || suffix.substr(0, head.size()) != head ||
      suffix.substr(suffix.size() - 4) != ".tmp")
    return 0;
  const std::string_view rest = suffix.substr(head.size(), suffix.size() - head.size() - 4);  // <pid>-<n>
  const size_t dash = rest.find('-');
  if (dash == 0 || dash == std::string_view::npos || dash + 1 == rest.size()) return 0;
  const auto digits = [](std::string_view v) {
    return std::all_of(v.begin(), v.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  if (!digits(rest.substr(0, dash)) || !digits(rest.substr(dash + 1)) || dash > 9) return 0;
  return pid_t(std::stol(std::string(rest.substr(0, dash))));
}

Status write_parts(const std::filesystem::path& file, int fd, std::span<const std::span<const uint8_t>> parts,
                   const std::string& what);

Status write_and_sync(const std::filesystem::path& tmp, std::span<const std::span<const uint8_t>> parts,
                      const std::string& what) {
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0)
    return Status::error(what + ": cannot create " + tmp.string() + ": " + describe_write_errno(errno));
  Status st = write_parts(tmp, fd, parts, what);
  // Delayed allocation can report a full disk only here.
  if (st && ::fsync(fd) != 0)
    st = Status::error(what + ": " + describe_write_errno(errno) + " while flushing to disk");
  if (::close(fd) != 0 && st)
    st = Status::error(what + ": " + describe_write_errno(errno) + " while closing");
  return st;
}

}  // namespace

Status write_file_atomic(const std::filesystem::path& path, std::span<const std::span<const uint8_t>> parts) {
  const std::string what = path.string();
  const std::filesystem::path tmp = temporary_beside(path);
  Status st = write_and_sync(tmp, parts, what);
  std::error_code ec;
  if (st) {
    std::filesystem::rename(tmp, path, ec);
    if (ec) st = Status::error(what + ": cannot rename " + tmp.string() + " into place: " + ec.message());
  }
  if (!st) std::filesystem::remove(tmp, ec);
  return st;
}

Status write_file_atomic(const std::filesystem::path& path, std::span<const uint8_t> bytes) {
  const std::span<const uint8_t> parts[] = {bytes};
  return write_file_atomic(path, parts);
}

Status write_file_atomic(const std::filesystem::path& path, const std::string& text) {
  return write_file_atomic(path, std::span(reinterpret_cast<const uint8_t*>(text.data()), text.size()));
}

std::string unique_temporary_suffix() {
  // The pid asked at every call: a forked child keeps the parent's statics.
  static std::atomic<uint64_t> serial{0};
  char suffix[64];
  std::snprintf(suffix, sizeof suffix, ".%016llx-%lld-%llu.tmp", static_cast<unsigned long long>(writer_scope()),
                static_cast<long long>(::getpid()), static_cast<unsigned long long>(serial++));
  return suffix;
}

size_t remove_dead_temporaries(const std::filesystem::path& dir, const std::string& name) {
  const uint64_t scope = writer_scope();
  const pid_t self = ::getpid();
  size_t removed = 0;
  // readdir, not directory_iterator: a cache folder holds thousands of entries, and only names
  // starting with `name` are looked at further.
  DIR* d = ::opendir(dir.c_str());
  if (!d) return 0;
  while (const dirent* e = ::readdir(d)) {
    const std::string_view file(e->d_name);
    if (file.size() <= name.size() || file.compare(0, name.size(), name) != 0) continue;
    const pid_t pid = pid_of_suffix(file.substr(name.size()), scope);
    if (pid <= 0 || pid == self) continue;
    if (::kill(pid, 0) == 0 || errno != ESRCH) continue;  // alive, or not ours to ask (EPERM: alive)
    if (::unlinkat(::dirfd(d), e->d_name, 0) == 0) ++removed;
  }
  ::closedir(d);
  return removed;
}

Status create_sized_temporary(const std::filesystem::path& path, uint64_t size, std::filesystem::path& temp) {
  const std::string what = path.string();
  temp = temporary_beside(path);
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0)
    return Status::error(what + ": cannot create " + temp.string() + ": " + describe_write_errno(errno));
  Status st;
  // The blocks themselves, where the file system can (a full disk shows here, not mid-write).
  if (const int err = ::posix_fallocate(fd, 0, off_t(size)); err != 0 && err != EOPNOTSUPP && err != EINVAL)
    st = Status::error(what + ": " + describe_write_errno(err) + " while reserving " + std::to_string(size) +
                       " bytes");
  if (st && ::ftruncate(fd, off_t(size)) != 0)
    st = Status::error(what + ": " + describe_write_errno(errno) + " while sizing " + temp.string());
  if (::close(fd) != 0 && st)
    st = Status::error(what + ": " + describe_write_errno(errno) + " while closing");
  std::error_code ec;
  if (!st) std::filesystem::remove(temp, ec);
  return st;
}

namespace detail {

std::vector<std::pair<uint64_t, uint64_t>> covered_ranges(std::span<const FilePiece> pieces) {
  std::vector<std::pair<uint64_t, uint64_t>> ranges;  // [begin, end)
  for (const FilePiece& piece : pieces)
    if (!piece.bytes.empty()) ranges.emplace_back(piece.offset, piece.offset + piece.bytes.size());
  std::sort(ranges.begin(), ranges.end());
  std::vector<std::pair<uint64_t, uint64_t>> joined;
  for (const auto& r : ranges) {
    if (!joined.empty() && r.first <= joined.back().second)
      joined.back().second = std::max(joined.back().second, r.second);
    else
      joined.push_back(r);
  }
  return joined;
}

}  // namespace detail

namespace {

Status pwrite_all(int fd, const uint8_t* p, size_t n, uint64_t at, const std::string& what) {
  size_t done = 0;
  while (done < n) {
    const ssize_t k = ::pwrite(fd, p + done, n - done, off_t(at + done));
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0)
      return Status::error(what + ": " + describe_write_errno(k < 0 ? errno : EIO) + " writing " +
                           std::to_string(n) + " bytes at " + std::to_string(at));
    done += size_t(k);
  }
  return Status::success();
}

Status write_each(int fd, std::span<const FilePiece> pieces, const std::string& what) {
  for (const FilePiece& piece : pieces)
    if (Status s = pwrite_all(fd, piece.bytes.data(), piece.bytes.size(), piece.offset, what); !s) return s;
  return Status::success();
}

// Each writer flushes its own ranges only: an fsync would also write back the pages other
// writers dirtied in the same file. All writes are started before any is waited for: one wait
// per piece (27k on the 14M dragon) cost more CPU than the copy itself on a virtio disk.
Status flush_ranges(int fd, const std::vector<std::pair<uint64_t, uint64_t>>& ranges,
                    const std::string& what) {
  for (unsigned flags :
       {unsigned(SYNC_FILE_RANGE_WRITE),
        unsigned(SYNC_FILE_RANGE_WAIT_BEFORE | SYNC_FILE_RANGE_WRITE | SYNC_FILE_RANGE_WAIT_AFTER)})
    for (const auto& [begin, end] : ranges)
      if (::sync_file_range(fd, off_t(begin), off_t(end - begin), flags) != 0)
        return Status::error(what + ": " + describe_write_errno(errno) + " while flushing to disk");
  return Status::success();
}

constexpr size_t kDirectAlign = 4096;           // O_DIRECT's alignment on every common device
constexpr size_t kDirectChunk = size_t(4) << 20;

size_t round_up(size_t n) { return (n + kDirectAlign - 1) & ~(kDirectAlign - 1); }

// The bounce buffer O_DIRECT needs (address, length and offset all aligned).
struct AlignedBuffer {
  explicit AlignedBuffer(size_t n) : raw(new uint8_t[n + kDirectAlign]), size(n) {
    data = raw.get() + ((kDirectAlign - reinterpret_cast<uintptr_t>(raw.get()) % kDirectAlign) % kDirectAlign);
  }
  std::unique_ptr<uint8_t[]> raw;
  uint8_t* data = nullptr;
  size_t size = 0;
};

// Whole aligned chunks, the last one zero-padded; the padding is cut off afterwards.
Status write_direct(int fd, std::span<const uint8_t> bytes, AlignedBuffer& buf, const std::string& what) {
  for (uint64_t at = 0; at < bytes.size(); at += buf.size) {
    const size_t n = size_t(std::min<uint64_t>(buf.size, bytes.size() - at));
    std::memcpy(buf.data, bytes.data() + at, n);
    std::memset(buf.data + n, 0, round_up(n) - n);
    if (Status s = pwrite_all(fd, buf.data, round_up(n), at, what); !s) return s;
  }
  if (::ftruncate(fd, off_t(bytes.size())) != 0)
    return Status::error(what + ": " + describe_write_errno(errno) + " while sizing the file");
  return Status::success();
}

// Reads the file back chunk by chunk and compares; says where it first differs.
Status compare_file(int fd, std::span<const uint8_t> bytes, AlignedBuffer& buf, const std::string& what) {
  struct stat st {};
  if (::fstat(fd, &st) != 0 || uint64_t(st.st_size) != bytes.size())
    return Status::error(what + ": reads back " + std::to_string(st.st_size) + " bytes, " +
                         std::to_string(bytes.size()) + " were written");
  for (uint64_t at = 0; at < bytes.size(); at += buf.size) {
    const size_t n = size_t(std::min<uint64_t>(buf.size, bytes.size() - at));
    size_t got = 0;
    while (got < n) {
      const ssize_t k = ::pread(fd, buf.data + got, round_up(n) - got, off_t(at + got));
      if (k < 0 && errno == EINTR) continue;
      if (k <= 0)
        return Status::error(what + ": " + (k < 0 ? std::string(std::strerror(errno)) : "early end of file") +
                             " reading back at " + std::to_string(at + got));
      got += size_t(k);
    }
    if (std::memcmp(buf.data, bytes.data() + at, n) != 0)
      return Status::error(what + ": reads back other bytes than were written (in the " + std::to_string(n) +
                           " bytes from " + std::to_string(at) + ")");
  }
  return Status::success();
}

Status write_new_and_sync(const std::filesystem::path& file, std::span<const uint8_t> bytes, AlignedBuffer& buf,
                          const std::string& what, bool& direct, bool& created) {
  int fd = direct ? ::open(file.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_DIRECT, 0644) : -1;
  if (fd < 0 && direct && errno == EINVAL) direct = false;  // a file system without O_DIRECT
  else if (fd < 0 && direct)
    return Status::error(what + ": cannot create " + file.string() + ": " + describe_write_errno(errno));
  if (!direct) fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) return Status::error(what + ": cannot create " + file.string() + ": " + describe_write_errno(errno));
  created = true;
  Status st = direct ? write_direct(fd, bytes, buf, what) : write_all(fd, bytes, what);
  if (st && ::fdatasync(fd) != 0)
    st = Status::error(what + ": " + describe_write_errno(errno) + " while flushing to disk");
  if (st && !direct) ::posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED);  // read back from the disk
  if (::close(fd) != 0 && st) st = Status::error(what + ": " + describe_write_errno(errno) + " while closing");
  return st;
}

// The bytes of `run` (sorted by offset; a later piece wins where two overlap) that fall in
// [begin, end), copied to `out`.
void gather(std::span<const FilePiece> run, uint64_t begin, uint64_t end, uint8_t* out) {
  for (const FilePiece& p : run) {
    const uint64_t b = std::max(begin, p.offset), e = std::min(end, p.offset + p.bytes.size());
    if (b < e) std::memcpy(out + (b - begin), p.bytes.data() + (b - p.offset), size_t(e - b));
  }
}

// One gapless run of pieces covering [begin, end): its whole 4 KB blocks past the page cache
// (fresh page-cache pages for 0.9 GB cost more CPU than the copy itself on a virtual machine),
// the partial blocks at its two ends buffered, since another writer may own the rest of them.
Status write_run(int fd, int direct_fd, std::span<const FilePiece> run, uint64_t begin, uint64_t end,
                 AlignedBuffer& buf, const std::string& what) {
  const uint64_t inner_begin = round_up(size_t(begin)), inner_end = end / kDirectAlign * kDirectAlign;
  if (direct_fd < 0 || inner_begin >= inner_end) return write_each(fd, run, what);
  for (const FilePiece& p : run) {
    const uint64_t p_end = p.offset + p.bytes.size();
    if (p.offset < inner_begin) {
      const uint64_t e = std::min(p_end, inner_begin);
      if (Status s = pwrite_all(fd, p.bytes.data(), size_t(e - p.offset), p.offset, what); !s) return s;
    }
    if (p_end > inner_end) {
      const uint64_t b = std::max(p.offset, inner_end);
      if (Status s = pwrite_all(fd, p.bytes.data() + (b - p.offset), size_t(p_end - b), b, what); !s) return s;
    }
  }
  for (uint64_t at = inner_begin; at < inner_end; at += buf.size) {
    const size_t n = size_t(std::min<uint64_t>(buf.size, inner_end - at));
    gather(run, at, at + n, buf.data);
    // A file system that opens O_DIRECT but refuses its writes: the whole run again, buffered
    // (a real failure, a full disk, repeats there and is reported).
    if (!pwrite_all(direct_fd, buf.data, n, at, what)) return write_each(fd, run, what);
  }
  return Status::success();
}

// Each gapless run of `ordered` pieces in turn.
Status write_runs(const std::filesystem::path& file, int fd, std::span<const FilePiece> ordered,
                  const std::vector<std::pair<uint64_t, uint64_t>>& ranges, const std::string& what) {
  const int direct_fd = ::open(file.c_str(), O_WRONLY | O_CLOEXEC | O_DIRECT);  // none: all buffered
  const uint64_t span = ranges.empty() ? 0 : ranges.back().second - ranges.front().first;
  AlignedBuffer buf(direct_fd >= 0 ? std::min(kDirectChunk, std::max(kDirectAlign, round_up(size_t(span))))
                                   : kDirectAlign);
  Status st;
  size_t first = 0;
  for (const auto& [begin, end] : ranges) {
    while (first < ordered.size() && ordered[first].offset < begin) ++first;  // empty ones between runs
    size_t last = first;
    while (last < ordered.size() && ordered[last].offset < end) ++last;
    if (st) st = write_run(fd, direct_fd, ordered.subspan(first, last - first), begin, end, buf, what);
    first = last;
  }
  if (direct_fd >= 0) ::close(direct_fd);
  return st;
}

// A new file's parts one after another: one run, its whole blocks past the page cache where
// the file system allows (a cleaned 14M-triangle mesh is 250 MB, a local bake's .hlod 0.9 GB).
Status write_parts(const std::filesystem::path& file, int fd, std::span<const std::span<const uint8_t>> parts,
                   const std::string& what) {
  std::vector<FilePiece> pieces;
  uint64_t at = 0;
  for (std::span<const uint8_t> part : parts) {
    if (!part.empty()) pieces.push_back({at, part});
    at += part.size();
  }
  if (at < 2 * kDirectAlign) return write_each(fd, pieces, what);  // nothing worth a bounce buffer
  return write_runs(file, fd, pieces, {{0, at}}, what);
}

}  // namespace

Status write_new_file_checked(const std::filesystem::path& file, std::span<const uint8_t> bytes,
                              const std::string& what, bool direct) {
  AlignedBuffer buf(std::min(kDirectChunk, std::max(kDirectAlign, round_up(bytes.size()))));
  bool created = false;
  Status st = write_new_and_sync(file, bytes, buf, what, direct, created);
  std::error_code ec;
  if (!st && created && direct) {  // O_DIRECT opened but refused: once more, buffered
    std::filesystem::remove(file, ec);
    created = direct = false;
    st = write_new_and_sync(file, bytes, buf, what, direct, created);
  }
  const int fd = st ? ::open(file.c_str(), O_RDONLY | O_CLOEXEC | (direct ? O_DIRECT : 0)) : -1;
  if (st && fd < 0) st = Status::error(what + ": cannot read " + file.string() + " back: " + std::strerror(errno));
  if (st) st = compare_file(fd, bytes, buf, what);
  if (fd >= 0) ::close(fd);
  if (!st && created) std::filesystem::remove(file, ec);
  return st;
}

Status write_pieces(const std::filesystem::path& file, std::span<const FilePiece> pieces,
                    const std::string& what) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0)
    return Status::error(what + ": cannot open " + file.string() + ": " + describe_write_errno(errno));
  std::vector<FilePiece> ordered(pieces.begin(), pieces.end());  // in file order: sequential writeback
  std::stable_sort(ordered.begin(), ordered.end(),
                   [](const FilePiece& a, const FilePiece& b) { return a.offset < b.offset; });
  const std::vector<std::pair<uint64_t, uint64_t>> ranges = detail::covered_ranges(ordered);
  Status st;
  {
    // Released before the flush: one writer's writeback overlaps the next one's copy.
    const HostTurn turn(fd);
    st = write_runs(file, fd, ordered, ranges, what);
  }
  if (st) st = flush_ranges(fd, ranges, what);
  if (::close(fd) != 0 && st)
    st = Status::error(what + ": " + describe_write_errno(errno) + " while closing");
  return st;
}

Status commit_temporary(const std::filesystem::path& temp, const std::filesystem::path& path) {
  // The writers flushed their data; this makes the file's metadata (its extents) durable too.
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CLOEXEC);
  const bool flushed = fd >= 0 && ::fdatasync(fd) == 0;
  const int err = errno;
  if (fd >= 0) ::close(fd);
  std::error_code ec;
  if (!flushed) {
    std::filesystem::remove(temp, ec);
    return Status::error(path.string() + ": " + describe_write_errno(err) + " while flushing " +
                         temp.string() + " to disk");
  }
  std::filesystem::rename(temp, path, ec);
  if (!ec) return Status::success();
  std::error_code ignored;
  std::filesystem::remove(temp, ignored);
  return Status::error(path.string() + ": cannot rename " + temp.string() + " into place: " + ec.message());
}

}  // namespace lod
