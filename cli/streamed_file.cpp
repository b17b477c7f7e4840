#include "cli/streamed_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <span>

#include "runtime/file_write.h"

namespace lod::cli {

StreamedFile::~StreamedFile() { discard(); }

Status StreamedFile::open(const std::filesystem::path& path) {
  discard();
  path_ = path;
  temp_ = path;
  temp_ += unique_temporary_suffix();
  bytes_ = 0;
  status_ = Status::success();
  if (path.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(path.parent_path(), ec);
  }
  fd_ = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    status_ = Status::error(path_.string() + ": cannot create " + temp_.string() + ": " + describe_write_errno(errno));
    return status_;
  }
  buffer_.reserve(kBufferBytes);
  return status_;
}

void StreamedFile::flush() {
  if (fd_ < 0 || !status_.ok || buffer_.empty()) return;
  status_ = write_all(fd_, std::span(reinterpret_cast<const uint8_t*>(buffer_.data()), buffer_.size()), path_.string());
  buffer_.clear();
}

void StreamedFile::write(std::string_view text) {
  if (fd_ < 0 || !status_.ok) return;
  bytes_ += text.size();
  if (buffer_.size() + text.size() > kBufferBytes) flush();
  if (text.size() >= kBufferBytes) {  // larger than the buffer: straight through
    if (status_.ok)
      status_ = write_all(fd_, std::span(reinterpret_cast<const uint8_t*>(text.data()), text.size()), path_.string());
    return;
  }
  buffer_.append(text);
}

Status StreamedFile::close() {
  if (fd_ < 0) return status_.ok ? Status::error(path_.string() + ": not open") : status_;
  flush();
  if (status_.ok && ::fsync(fd_) != 0)  // delayed allocation can report a full disk only here
    status_ = Status::error(path_.string() + ": " + describe_write_errno(errno) + " while flushing to disk");
  if (::close(fd_) != 0 && status_.ok)
    status_ = Status::error(path_.string() + ": " + describe_write_errno(errno) + " while closing");
  fd_ = -1;
  std::error_code ec;
  if (status_.ok) {
    std::filesystem::rename(temp_, path_, ec);
    if (ec) status_ = Status::error(path_.string() + ": cannot rename " + temp_.string() + " into place: " + ec.message());
  }
  if (!status_.ok) std::filesystem::remove(temp_, ec);
  buffer_.clear();
  buffer_.shrink_to_fit();
  return status_;
}

void StreamedFile::discard() {
  if (fd_ < 0) return;
  ::close(fd_);
  fd_ = -1;
  std::error_code ec;
  std::filesystem::remove(temp_, ec);
}

}  // namespace lod::cli
