// write_file_atomic: temporary + fsync + rename, as the header says.
#include "runtime/file_write.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>

namespace lod {

std::string describe_write_errno(int err) {
  switch (err) {
    case ENOSPC: return "the disk is full (no space left on device)";
    case EDQUOT: return "the disk quota is exceeded";
    case EROFS: return "the file system is read-only";
    case EACCES:
    case EPERM: return "permission denied";
    case EFBIG: return "the file is too large for this file system";
    case EIO: return "an I/O error occurred on the device";
    default: return std::strerror(err);
  }
}

Status write_all(int fd, std::span<const uint8_t> bytes, const std::string& what) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int err = n < 0 ? errno : EIO;
      return Status::error(what + ": " + describe_write_errno(err) + " after writing " + std::to_string(done) +
                           " of " + std::to_string(bytes.size()) + " bytes");
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

Status write_and_sync(const std::filesystem::path& tmp, std::span<const uint8_t> bytes, const std::string& what) {
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) return Status::error(what + ": cannot create " + tmp.string() + ": " + describe_write_errno(errno));
  Status st = write_all(fd, bytes, what);
  // Delayed allocation can report a full disk only here.
  if (st && ::fsync(fd) != 0) st = Status::error(what + ": " + describe_write_errno(errno) + " while flushing to disk");
  if (::close(fd) != 0 && st) st = Status::error(what + ": " + describe_write_errno(errno) + " while closing");
  return st;
}

}  // namespace

Status write_file_atomic(const std::filesystem::path& path, std::span<const uint8_t> bytes) {
  const std::string what = path.string();
  const std::filesystem::path tmp = temporary_beside(path);
  Status st = write_and_sync(tmp, bytes, what);
  std::error_code ec;
  if (st) {
    std::filesystem::rename(tmp, path, ec);
    if (ec) st = Status::error(what + ": cannot rename " + tmp.string() + " into place: " + ec.message());
  }
  if (!st) std::filesystem::remove(tmp, ec);
  return st;
}

Status write_file_atomic(const std::filesystem::path& path, const std::string& text) {
  return write_file_atomic(path, std::span(reinterpret_cast<const uint8_t*>(text.data()), text.size()));
}

Status create_sized_temporary(const std::filesystem::path& path, uint64_t size, std::filesystem::path& temp) {
  const std::string what = path.string();
  temp = temporary_beside(path);
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) return Status::error(what + ": cannot create " + temp.string() + ": " + describe_write_errno(errno));
  Status st;
  // The blocks themselves, where the file system can (a full disk shows here, not mid-write).
  if (const int err = ::posix_fallocate(fd, 0, off_t(size)); err != 0 && err != EOPNOTSUPP && err != EINVAL)
    st = Status::error(what + ": " + describe_write_errno(err) + " while reserving " + std::to_string(size) + " bytes");
  if (st && ::ftruncate(fd, off_t(size)) != 0)
    st = Status::error(what + ": " + describe_write_errno(errno) + " while sizing " + temp.string());
  if (::close(fd) != 0 && st) st = Status::error(what + ": " + describe_write_errno(errno) + " while closing");
  std::error_code ec;
  if (!st) std::filesystem::remove(temp, ec);
  return st;
}

Status write_pieces(const std::filesystem::path& file, std::span<const FilePiece> pieces, const std::string& what) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) return Status::error(what + ": cannot open " + file.string() + ": " + describe_write_errno(errno));
  Status st;
  for (const FilePiece& piece : pieces) {
    size_t done = 0;
    while (st && done < piece.bytes.size()) {
      const ssize_t n = ::pwrite(fd, piece.bytes.data() + done, piece.bytes.size() - done, off_t(piece.offset + done));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0)
        st = Status::error(what + ": " + describe_write_errno(n < 0 ? errno : EIO) + " writing " +
                           std::to_string(piece.bytes.size()) + " bytes at " + std::to_string(piece.offset));
      else
        done += size_t(n);
    }
    if (!st) break;
  }
  // Each writer flushes its own ranges only: an fsync here would also write back the pages
  // other writers dirtied in the same file (twice the writeback at 2 ranks). commit_temporary
  // makes the whole file durable.
  for (size_t i = 0; st && i < pieces.size(); ++i)
    if (::sync_file_range(fd, off_t(pieces[i].offset), off_t(pieces[i].bytes.size()),
                          SYNC_FILE_RANGE_WAIT_BEFORE | SYNC_FILE_RANGE_WRITE | SYNC_FILE_RANGE_WAIT_AFTER) != 0)
      st = Status::error(what + ": " + describe_write_errno(errno) + " while flushing to disk");
  if (::close(fd) != 0 && st) st = Status::error(what + ": " + describe_write_errno(errno) + " while closing");
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
    return Status::error(path.string() + ": " + describe_write_errno(err) + " while flushing " + temp.string() + " to disk");
  }
  std::filesystem::rename(temp, path, ec);
  if (!ec) return Status::success();
  std::error_code ignored;
  std::filesystem::remove(temp, ignored);
  return Status::error(path.string() + ": cannot rename " + temp.string() + " into place: " + ec.message());
}

}  // namespace lod
