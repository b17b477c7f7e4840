// Writing a file so that nothing half-written is ever trusted: the bytes go to a temporary
// file of its own in the same folder, are flushed to the disk, and only then renamed over the
// target. A failure removes the temporary and says in plain words what went wrong (a full
// disk says so, not "write failed").
#pragma once
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "runtime/status.h"

namespace lod {

// `path` is the file to replace; messages start with it.
Status write_file_atomic(const std::filesystem::path& path, std::span<const uint8_t> bytes);
Status write_file_atomic(const std::filesystem::path& path, const std::string& text);

// Writes all of `bytes` to an open descriptor, retrying short writes and EINTR. On failure
// the message says how far it got and why ("the disk is full after 4096 of 9000 bytes").
Status write_all(int fd, std::span<const uint8_t> bytes, const std::string& what);

// errno in plain words for file writes: ENOSPC "the disk is full", EDQUOT "the disk quota is
// exceeded", EROFS "the file system is read-only", EACCES/EPERM "permission denied", EFBIG
// "the file is too large", EIO "an I/O error"; otherwise strerror.
std::string describe_write_errno(int err);

}  // namespace lod
