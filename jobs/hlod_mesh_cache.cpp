// The cleaned mesh entry, version 1, little-endian:
//   magic "LODHMSH\n" (8) | u32 version | u32 0 | u64 source hash | u64 input triangles |
//   u64 vertices V | u64 indices I | V x 3 f32 positions | I u32 indices |
//   u64 checksum = hash_bytes(everything before it)
#include "jobs/hlod_mesh_cache.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include "runtime/byte_order.h"
#include "runtime/file_write.h"
#include "runtime/lod_asset.h"  // hash_bytes

namespace lod {
namespace {

constexpr char kMagic[8] = {'L', 'O', 'D', 'H', 'M', 'S', 'H', '\n'};
constexpr uint64_t kFixedBytes = 48;

bool read_whole(const std::filesystem::path& path, std::vector<uint8_t>& out) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  struct stat st {};
  bool ok = ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode);
  if (ok) out.resize(size_t(st.st_size));
  for (size_t done = 0; ok && done < out.size();) {
    const ssize_t n = ::pread(fd, out.data() + done, out.size() - done, off_t(done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) ok = false;
    else done += size_t(n);
  }
  ::close(fd);
  return ok;
}

}  // namespace

std::filesystem::path hlod_mesh_entry_path(const std::filesystem::path& dir, uint64_t source_hash) {
  char name[40];
  std::snprintf(name, sizeof name, "%016llx.hmesh", static_cast<unsigned long long>(source_hash));
  return dir / name;
}

Status store_hlod_mesh(const std::filesystem::path& dir, uint64_t source_hash, const MeshData& mesh,
                       uint64_t input_triangles) {
  detail::ByteWriter w;
  w.bytes.reserve(kFixedBytes + 4 * (mesh.positions.size() + mesh.indices.size()) + 8);
  for (char c : kMagic) w.u8(uint8_t(c));
  w.u32(kHlodMeshEntryVersion);
  w.u32(0);
  w.u64(source_hash);
  w.u64(input_triangles);
  w.u64(mesh.vertex_count());
  w.u64(mesh.indices.size());
  w.words(mesh.positions.data(), mesh.positions.size());
  w.words(mesh.indices.data(), mesh.indices.size());
  w.u64(hash_bytes(w.bytes.data(), w.bytes.size()));
  const std::filesystem::path path = hlod_mesh_entry_path(dir, source_hash);
  if (Status s = write_file_atomic(path, w.bytes); !s) return s;
  return Status::success();
}

CacheLookup load_hlod_mesh(const std::filesystem::path& dir, uint64_t source_hash, const std::string& source_name,
                           MeshData& out, uint64_t& input_triangles, std::string* why) {
  const std::filesystem::path path = hlod_mesh_entry_path(dir, source_hash);
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return CacheLookup::missing;
  auto refuse = [&](const std::string& reason) {
    if (why) *why = path.string() + ": " + reason;
    return CacheLookup::refused;
  };
  std::vector<uint8_t> b;
  if (!read_whole(path, b)) return refuse("cannot be read (not a regular file?)");
  if (b.size() < kFixedBytes + 8) return refuse("too short for a cleaned mesh entry (truncated?)");
  if (std::memcmp(b.data(), kMagic, 8) != 0) return refuse("not a cleaned mesh entry (bad magic bytes)");
  if (detail::load_u32(b.data() + 8) != kHlodMeshEntryVersion) return refuse("entry version is not supported");
  const uint64_t vertices = detail::load_u64(b.data() + 32), indices = detail::load_u64(b.data() + 40);
  // Counts against the size before anything is allocated.
  if (vertices >= UINT32_MAX || indices % 3 != 0 || indices > b.size() / 4 ||
      b.size() != kFixedBytes + 12 * vertices + 4 * indices + 8)
    return refuse("its counts (" + std::to_string(vertices) + " vertices, " + std::to_string(indices) +
                  " indices) do not match its " + std::to_string(b.size()) + " bytes (truncated?)");
  const size_t body = b.size() - 8;
  if (detail::load_u64(b.data() + body) != hash_bytes(b.data(), body)) return refuse("checksum mismatch (corrupted)");
  if (detail::load_u64(b.data() + 16) != source_hash) return refuse("written for another source (a misplaced entry)");
  MeshData m;
  m.source = source_name;
  m.positions.resize(size_t(3 * vertices));
  m.indices.resize(size_t(indices));
  const uint8_t* p = b.data() + kFixedBytes;
  for (float& v : m.positions) v = detail::load_f32(p), p += 4;
  for (uint32_t& i : m.indices) i = detail::load_u32(p), p += 4;
  for (uint32_t i : m.indices)
    if (i >= vertices) return refuse("an index names vertex " + std::to_string(i) + " of " + std::to_string(vertices));
  for (float v : m.positions)
    if (!std::isfinite(v)) return refuse("a position is not finite");
  input_triangles = detail::load_u64(b.data() + 24);
  out = std::move(m);
  return CacheLookup::found;
}

}  // namespace lod
