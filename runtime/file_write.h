// Writing a file so that nothing half-written is ever trusted: the bytes go to a temporary
// file of its own in the same folder, are flushed to the disk, and only then renamed over the
// target. A failure removes the temporary and says in plain words what went wrong (a full
// disk says so, not "write failed").
#pragma once
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "runtime/status.h"

namespace lod {

// `path` is the file to replace; messages start with it.
Status write_file_atomic(const std::filesystem::path& path, std::span<const uint8_t> bytes);
Status write_file_atomic(const std::filesystem::path& path, const std::string& text);
// The file is the parts one after another (written where they lie: no concatenated copy).
Status write_file_atomic(const std::filesystem::path& path, std::span<const std::span<const uint8_t>> parts);

// A new file (created, never replaced: `file` must not exist) holding `bytes`, checked against the
// device before the caller trusts it: written past the page cache where the file system allows
// (O_DIRECT through an aligned bounce buffer; otherwise written and dropped from the cache),
// flushed, then read back the same way and compared. A cache entry is renamed into place only
// after this succeeds, and reading back from the disk, not the page cache, checks what a rerun
// will read. Large entries (0.9 GB of them for a 14M-triangle bake) also stay out of the page
// cache, which the bake's ranks would otherwise fill and evict. `direct` false takes the buffered
// path (the one used where O_DIRECT is refused). On failure the file is removed (if this made it).
Status write_new_file_checked(const std::filesystem::path& file, std::span<const uint8_t> bytes,
                              const std::string& what, bool direct = true);

// A file written in pieces, possibly by several processes at once (every rank writes
// its own subtrees' payloads into the .hlod): create_sized_temporary makes a temporary of its
// own beside `path` at the full size; write_pieces opens it by name, writes each piece at its
// offset (processes on one host taking turns, runtime/host_turn.h) and flushes its own ranges
// to the disk; commit_temporary flushes the whole file (its
// extents) and renames it over `path` once every writer
// has succeeded (otherwise remove it).
struct FilePiece {
  uint64_t offset = 0;
  std::span<const uint8_t> bytes;
};
Status create_sized_temporary(const std::filesystem::path& path, uint64_t size, std::filesystem::path& temp);
Status write_pieces(const std::filesystem::path& file, std::span<const FilePiece> pieces,
                    const std::string& what);
Status commit_temporary(const std::filesystem::path& temp, const std::filesystem::path& path);

namespace detail {
// The byte ranges `pieces` cover, sorted, overlapping or touching ones joined: what a writer
// flushes (a few large ranges for a rank's runs of neighbouring nodes).
std::vector<std::pair<uint64_t, uint64_t>> covered_ranges(std::span<const FilePiece> pieces);
}  // namespace detail

// Writes all of `bytes` to an open descriptor, retrying short writes and EINTR. On failure
// the message says how far it got and why ("the disk is full after 4096 of 9000 bytes").
Status write_all(int fd, std::span<const uint8_t> bytes, const std::string& what);

// ".<scope>-<pid>-<n>.tmp": a temporary's suffix no other writer uses, in this process (n counts)
// or in any other, on this host or another sharing the folder. The scope (16 hex digits) names
// where the pid means something: the host, its boot and the pid namespace (a pid alone repeats
// across the nodes of an MPI job writing to shared storage, and across containers).
std::string unique_temporary_suffix();

// A writer killed mid-write leaves its temporary behind, full-size. Before a file is written,
// the temporaries of the same name (`dir/<name><suffix>`, suffixes as above) left by writers of
// this scope whose pid no longer exists (kill(pid, 0) fails with ESRCH) are removed; those of
// live writers, and of other scopes (another host: its pids cannot be asked), are left alone.
// write_file_atomic and create_sized_temporary do this for their target; a writer that names
// its own temporaries calls it itself. Returns how many were removed.
size_t remove_dead_temporaries(const std::filesystem::path& dir, const std::string& name);

// errno in plain words for file writes: ENOSPC "the disk is full", EDQUOT "the disk quota is
// exceeded", EROFS "the file system is read-only", EACCES/EPERM "permission denied", EFBIG
// "the file is too large", EIO "an I/O error"; otherwise strerror.
std::string describe_write_errno(int err);

}  // namespace lod
