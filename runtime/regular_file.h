// Opening files for reading: the one way lodkit opens a path it was given (meshes, materials,
// textures, assets, cache entries, height fields, configs).
//
// Only regular files are read. A directory, FIFO, socket or device is refused by stat before
// anything opens it ("f.off: is a FIFO, not a regular file"), so a FIFO never blocks a reader
// and /dev/zero is never read. The open itself uses O_NONBLOCK and the descriptor is checked
// again with fstat, so a path swapped for a FIFO or device between the two is refused too.
//
// Every read is bounded before it starts: the file's size at open is checked against the limit
// its kind allows (FileLimit), and a file read whole must also fit in the host's physical memory.
// Readers of formats with a header (.lod, .hlod, binary STL, GLB, PNG) read the header first
// and check what it declares against the file's size before reading the rest.
#pragma once
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "runtime/status.h"

namespace lod {

// The largest file of a kind that is read, and the kind's name for messages
// ("x.mtl: is 20000000 bytes; a material file is at most 16777216 bytes").
struct FileLimit {
  uint64_t max_bytes;
  const char* kind;
};

// Images a material names (PNG, JPEG): 256 MiB, the bound on an embedded image too.
inline constexpr FileLimit kTextureFileLimit{uint64_t(256) << 20, "a texture file"};
// An OBJ's .mtl: 16 MiB (a material library is a few hundred bytes a material).
inline constexpr FileLimit kMaterialFileLimit{uint64_t(16) << 20, "a material file"};
// A scene config (TOML): 16 MiB.
inline constexpr FileLimit kConfigFileLimit{uint64_t(16) << 20, "a config file"};
// Meshes, assets, cache entries, height fields and the buffers a glTF names: 1 TiB; what is
// read whole must also fit in memory, and each format's header bounds it further.
inline constexpr FileLimit kInputFileLimit{uint64_t(1) << 40, "an input file"};

// Refuses, by stat alone, what is not a regular file of at most `limit.max_bytes`; `size` gets
// its size. Missing: "<path>: no such file".
Status check_regular_file(const std::filesystem::path& path, FileLimit limit, uint64_t* size = nullptr);

// A regular file open for reading, closed when it goes.
struct RegularFile {
  int fd = -1;
  uint64_t size = 0;  // at open
  std::string what;   // the path, for messages
  RegularFile() = default;
  RegularFile(RegularFile&& o) noexcept : fd(std::exchange(o.fd, -1)), size(o.size), what(std::move(o.what)) {}
  RegularFile& operator=(RegularFile&& o) noexcept {
    std::swap(fd, o.fd);
    size = o.size;
    what = std::move(o.what);
    return *this;
  }
  RegularFile(const RegularFile&) = delete;
  RegularFile& operator=(const RegularFile&) = delete;
  ~RegularFile();

  // Up to n bytes from `offset` (fewer at the end of the file, or when it shrank); a read error
  // sets st.
  size_t read_at(uint8_t* into, size_t n, uint64_t offset, Status& st) const;
  // The first min(size, n) bytes.
  Status read_head(size_t n, std::vector<uint8_t>& out) const;
  // Exactly n bytes from `offset` (n checked against the size at open before anything is
  // allocated; "truncated" when the file is shorter).
  Status read_exactly(uint64_t offset, uint64_t n, std::vector<uint8_t>& out) const;
  // The first n bytes (n <= size), or the whole file: refused when it does not fit in memory.
  Status read_all(std::vector<uint8_t>& out, uint64_t n = std::numeric_limits<uint64_t>::max()) const;
};

// check_regular_file, then open (O_NONBLOCK) and fstat: the descriptor must be a regular file
// within the limit too.
Status open_regular_file(const std::filesystem::path& path, FileLimit limit, RegularFile& out);

// The whole file (open_regular_file's checks; refused when it does not fit in memory).
Status read_regular_file(const std::filesystem::path& path, FileLimit limit, std::vector<uint8_t>& out);
Status read_regular_file(const std::filesystem::path& path, FileLimit limit, std::string& out);

// The content hash (hash_bytes with `seed`) of a regular file's bytes, read in 1 MiB pieces: the
// file is never held whole, so its size is not limited.
Status hash_regular_file(const std::filesystem::path& path, uint64_t& hash, uint64_t seed = 0);

// The position of the first NUL byte in `bytes`, or SIZE_MAX: text formats have none, so a
// NUL in a text file's first bytes (a sparse or binary file) refuses it before it is read whole.
size_t first_nul_byte(const std::vector<uint8_t>& bytes);

// Reads the first kTextHeadBytes and refuses a NUL byte there: "f.off: holds binary data (a
// NUL byte at offset 0), not OFF text". A sparse multi-GB file is refused this way unread.
inline constexpr size_t kTextHeadBytes = 64 * 1024;
Status check_text_head(const RegularFile& f, const char* format);

// The host's physical memory in bytes (what a file read whole must fit in).
uint64_t physical_memory_bytes();

}  // namespace lod
