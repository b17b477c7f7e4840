// write_file_atomic: temporary + fsync + rename, as the header says.
#include "runtime/file_write.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>

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
// once, and each rename then replaces it whole (last one wins).
std::filesystem::path temporary_beside(const std::filesystem::path& path) {
  static std::atomic<uint64_t> serial{0};
  std::filesystem::path tmp = path;
  std::string suffix = ".";  // appended piecewise: GCC 12 warns (-Wrestrict) on "." + to_string
  suffix += std::to_string(::getpid());
  suffix += '-';
  suffix += std::to_string(serial++);
  suffix += ".tmp";
  tmp += suffix;
  return tmp;
}

Status write_and_sync(const std::filesystem::path& tmp, std::span<const std::span<const uint8_t>> parts,
                      const std::string& what) {
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0)
    return Status::error(what + ": cannot create " + tmp.string() + ": " + describe_write_errno(errno));
  Status st;
  for (size_t i = 0; st && i < parts.size(); ++i) st = write_all(fd, parts[i], what);
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

Status write_each(int fd, std::span<const FilePiece> pieces, const std::string& what) {
  for (const FilePiece& piece : pieces) {
    size_t done = 0;
    while (done < piece.bytes.size()) {
      const ssize_t n =
          ::pwrite(fd, piece.bytes.data() + done, piece.bytes.size() - done, off_t(piece.offset + done));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0)
        return Status::error(what + ": " + describe_write_errno(n < 0 ? errno : EIO) + " writing " +
                             std::to_string(piece.bytes.size()) + " bytes at " +
                             std::to_string(piece.offset));
      done += size_t(n);
    }
  }
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

}  // namespace

Status write_pieces(const std::filesystem::path& file, std::span<const FilePiece> pieces,
                    const std::string& what) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0)
    return Status::error(what + ": cannot open " + file.string() + ": " + describe_write_errno(errno));
  std::vector<FilePiece> ordered(pieces.begin(), pieces.end());  // in file order: sequential writeback
  std::stable_sort(ordered.begin(), ordered.end(),
                   [](const FilePiece& a, const FilePiece& b) { return a.offset < b.offset; });
  Status st;
  {
    // Released before the flush: one writer's writeback overlaps the next one's copy.
    const HostTurn turn(fd);
    st = write_each(fd, ordered, what);
  }
  if (st) st = flush_ranges(fd, detail::covered_ranges(ordered), what);
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
