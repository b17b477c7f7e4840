// StreamedFile: a file written piece by piece as a run goes (a frame's CSV or JSON row at a
// time) in memory that does not grow with it. Pieces collect in a buffer of fixed size and go
// to a temporary file beside the target when it fills; close() flushes the temporary to the
// disk and renames it over the target, so the target's name only ever holds a whole file (as
// write_file_atomic). A failed write is kept: ok() turns false, status() names the file and
// says why (a full disk says so), and later writes do nothing. A file not closed (an error
// elsewhere ended the run) has its temporary removed when the StreamedFile goes.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "runtime/status.h"

namespace lod::cli {

class StreamedFile {
 public:
  static constexpr size_t kBufferBytes = size_t(1) << 20;

  StreamedFile() = default;
  StreamedFile(const StreamedFile&) = delete;
  StreamedFile& operator=(const StreamedFile&) = delete;
  ~StreamedFile();

  Status open(const std::filesystem::path& path);
  bool is_open() const { return fd_ >= 0; }
  void write(std::string_view text);
  bool ok() const { return status_.ok; }
  const Status& status() const { return status_; }
  uint64_t bytes() const { return bytes_; }  // written so far, buffered included
  // Flush, sync, rename over the target. After it the StreamedFile is closed either way.
  Status close();

 private:
  void flush();
  void discard();

  std::filesystem::path path_, temp_;
  int fd_ = -1;
  std::string buffer_;
  uint64_t bytes_ = 0;
  Status status_;
};

}  // namespace lod::cli
