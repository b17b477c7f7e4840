// The cleaned mesh entry, version 4, little-endian:
//   magic "LODHMSH\n" (8) | u32 version | u32 flags (bit 0: uvs, bit 1: colours, bit 2: uv1) |
//   u64 source hash | u64 input triangles | u64 vertices V | u64 indices I | u64 submeshes S |
//   u64 materials bytes M | u64 images bytes G |
//   V x 3 f32 positions | I u32 indices | V x 2 f32 uvs (with the flag) | V x 2 f32 uv1 (with
//   its flag) | V x 4 f32 linear RGBA colours (with theirs) |
//   S x (u32 first triangle, u32 triangles, i32 material) | M bytes: the materials and texture
//   base in the .lod's MATL layout (runtime/material_section.h) | G bytes: the images the
//   materials embed in the .lod's IMGS layout (0 = none) |
//   u64 checksum = hash_bytes(everything before it)
#include "jobs/hlod_mesh_cache.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <span>
#include <vector>

#include "runtime/byte_order.h"
#include "runtime/bytes_hasher.h"
#include "runtime/file_write.h"
#include "runtime/lod_asset.h"  // hash_bytes
#include "runtime/material_section.h"

namespace lod {
namespace {

constexpr char kMagic[8] = {'L', 'O', 'D', 'H', 'M', 'S', 'H', '\n'};
constexpr uint64_t kFixedBytes = 72;
constexpr uint32_t kFlagUvs = 1;
constexpr uint32_t kFlagColors = 2;
constexpr uint32_t kFlagUvs1 = 4;

bool read_whole(const std::filesystem::path& path, std::vector<uint8_t>& out) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  struct stat st {};
  bool ok = ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode);
  if (ok) out.resize(size_t(st.st_size));
  for (size_t done = 0; ok && done < out.size();) {
    const ssize_t n = ::pread(fd, out.data() + done, out.size() - done, off_t(done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      ok = false;
    else
      done += size_t(n);
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

namespace {

struct Columns {
  bool uvs, uvs1, colors;
};

std::vector<uint8_t> entry_head(uint64_t source_hash, uint64_t input_triangles, const MeshData& mesh,
                                Columns has, size_t material_bytes, size_t image_bytes) {
  detail::ByteWriter head;
  for (char c : kMagic) head.u8(uint8_t(c));
  head.u32(kHlodMeshEntryVersion);
  head.u32((has.uvs ? kFlagUvs : 0) | (has.colors ? kFlagColors : 0) | (has.uvs1 ? kFlagUvs1 : 0));
  for (uint64_t v :
       {source_hash, input_triangles, uint64_t(mesh.vertex_count()), uint64_t(mesh.indices.size()),
        uint64_t(mesh.submeshes.size()), uint64_t(material_bytes), uint64_t(image_bytes)})
    head.u64(v);
  return std::move(head.bytes);
}

std::vector<uint8_t> submesh_rows(const MeshData& mesh) {
  detail::ByteWriter rows;
  for (const Submesh& sm : mesh.submeshes) {
    rows.u32(sm.first_triangle);
    rows.u32(sm.triangle_count);
    rows.u32(uint32_t(sm.material));
  }
  return std::move(rows.bytes);
}

// A 32-bit array's bytes in the file's order: where it lies on a little-endian host (a
// 14M-triangle mesh is 250 MB, written without a copy), a swapped copy kept in `copies` else.
template <class T>
std::span<const uint8_t> le_words(const std::vector<T>& v, std::vector<std::vector<uint8_t>>& copies) {
  if constexpr (std::endian::native == std::endian::little) {
    return {reinterpret_cast<const uint8_t*>(v.data()), 4 * v.size()};
  } else {
    detail::ByteWriter w;
    w.words(v.data(), v.size());
    return copies.emplace_back(std::move(w.bytes));  // a moved vector keeps its buffer
  }
}

}  // namespace

Status store_hlod_mesh(const std::filesystem::path& dir, uint64_t source_hash, const MeshData& mesh,
                       uint64_t input_triangles, const HlodSurfaces& surfaces) {
  const size_t nv = mesh.vertex_count();
  const Columns has{mesh.uvs.size() == 2 * nv && nv > 0, mesh.uvs1.size() == 2 * nv && nv > 0,
                    mesh.colors.size() == 4 * nv && nv > 0};
  LodChain chain;
  chain.materials = surfaces.materials;
  chain.texture_base = surfaces.texture_base;
  const std::vector<uint8_t> materials =
      surfaces.materials.empty() ? std::vector<uint8_t>() : encode_material_section(chain);
  const std::vector<uint8_t> images =
      surfaces.images.empty() ? std::vector<uint8_t>() : encode_image_section(surfaces.images);
  const std::vector<uint8_t> head =
      entry_head(source_hash, input_triangles, mesh, has, materials.size(), images.size());
  const std::vector<uint8_t> rows = submesh_rows(mesh);
  std::vector<std::vector<uint8_t>> copies;
  std::vector<std::span<const uint8_t>> parts{head, le_words(mesh.positions, copies),
                                              le_words(mesh.indices, copies)};
  if (has.uvs) parts.push_back(le_words(mesh.uvs, copies));
  if (has.uvs1) parts.push_back(le_words(mesh.uvs1, copies));
  if (has.colors) parts.push_back(le_words(mesh.colors, copies));
  parts.insert(parts.end(), {rows, materials, images});
  BytesHasher hash;
  for (std::span<const uint8_t> part : parts) hash.add(part.data(), part.size());
  detail::ByteWriter checksum;
  checksum.u64(hash.finish());
  parts.push_back(checksum.bytes);
  return write_file_atomic(hlod_mesh_entry_path(dir, source_hash), parts);
}

CacheLookup load_hlod_mesh(const std::filesystem::path& dir, uint64_t source_hash,
                           const std::string& source_name, MeshData& out, uint64_t& input_triangles,
                           std::string* why, HlodSurfaces* surfaces) {
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
  if (detail::load_u32(b.data() + 8) != kHlodMeshEntryVersion)
    return refuse("entry version is not supported");
  const uint32_t flags = detail::load_u32(b.data() + 12);
  const uint64_t vertices = detail::load_u64(b.data() + 32), indices = detail::load_u64(b.data() + 40);
  const uint64_t submeshes = detail::load_u64(b.data() + 48),
                 material_bytes = detail::load_u64(b.data() + 56);
  const uint64_t image_bytes = detail::load_u64(b.data() + 64);
  if ((flags & ~(kFlagUvs | kFlagColors | kFlagUvs1)) != 0)
    return refuse("unknown flags " + std::to_string(flags));
  const uint64_t per_vertex =
      12 + ((flags & kFlagUvs) ? 8 : 0) + ((flags & kFlagUvs1) ? 8 : 0) + ((flags & kFlagColors) ? 16 : 0);
  // Counts against the size before anything is allocated (each bounded first, so the sum cannot overflow).
  if (vertices >= UINT32_MAX || indices % 3 != 0 || indices > b.size() / 4 || submeshes > b.size() / 12 ||
      material_bytes > b.size() || image_bytes > b.size() ||
      b.size() != kFixedBytes + per_vertex * vertices + 4 * indices + 12 * submeshes + material_bytes +
                      image_bytes + 8)
    return refuse("its counts (" + std::to_string(vertices) + " vertices, " + std::to_string(indices) +
                  " indices, " + std::to_string(submeshes) + " submeshes, " + std::to_string(material_bytes) +
                  " bytes of materials, " + std::to_string(image_bytes) + " of images) do not match its " +
                  std::to_string(b.size()) + " bytes (truncated?)");
  const size_t body = b.size() - 8;
  if (detail::load_u64(b.data() + body) != hash_bytes(b.data(), body))
    return refuse("checksum mismatch (corrupted)");
  if (detail::load_u64(b.data() + 16) != source_hash)
    return refuse("written for another source (a misplaced entry)");
  MeshData m;
  m.source = source_name;
  m.positions.resize(size_t(3 * vertices));
  m.indices.resize(size_t(indices));
  const uint8_t* p = b.data() + kFixedBytes;
  for (float& v : m.positions) v = detail::load_f32(p), p += 4;
  for (uint32_t& i : m.indices) i = detail::load_u32(p), p += 4;
  auto column = [&](uint32_t flag, size_t per, std::vector<float>& into) {
    if (!(flags & flag)) return;
    into.resize(size_t(per * vertices));
    for (float& v : into) v = detail::load_f32(p), p += 4;
  };
  column(kFlagUvs, 2, m.uvs);
  column(kFlagUvs1, 2, m.uvs1);
  column(kFlagColors, 4, m.colors);
  m.submeshes.resize(size_t(submeshes));
  for (Submesh& sm : m.submeshes) {
    sm.first_triangle = detail::load_u32(p);
    sm.triangle_count = detail::load_u32(p + 4);
    sm.material = int32_t(detail::load_u32(p + 8));
    p += 12;
  }
  LodChain chain;  // images first: the materials' embedded:<k> are checked against them
  if (image_bytes > 0 && material_bytes == 0) return refuse("it has images but no materials");
  if (image_bytes > 0)
    if (Status s = decode_image_section({p + material_bytes, size_t(image_bytes)}, "images", chain.images);
        !s)
      return refuse(s.message);
  if (material_bytes > 0)
    if (Status s = decode_material_section({p, size_t(material_bytes)}, "materials", chain); !s)
      return refuse(s.message);
  // The writer stores the section only with materials: one without (its texture base and
  // images lost on the next store) is not one it wrote.
  if (material_bytes > 0 && chain.materials.empty())
    return refuse("its materials section holds no materials");
  for (uint32_t i : m.indices)
    if (i >= vertices)
      return refuse("an index names vertex " + std::to_string(i) + " of " + std::to_string(vertices));
  for (float v : m.positions)
    if (!std::isfinite(v)) return refuse("a position is not finite");
  for (float v : m.uvs)
    if (!std::isfinite(v)) return refuse("a texture coordinate is not finite");
  for (float v : m.uvs1)
    if (!std::isfinite(v)) return refuse("a TEXCOORD_1 value is not finite");
  for (float v : m.colors)
    if (!std::isfinite(v)) return refuse("a colour is not finite");
  // Submeshes in order inside the triangles, each naming a stored material (or the default).
  uint64_t covered = 0;
  for (const Submesh& sm : m.submeshes) {
    if (sm.first_triangle < covered || sm.first_triangle > indices / 3 ||
        sm.triangle_count > indices / 3 - sm.first_triangle || sm.material < -1 ||
        (sm.material >= 0 && size_t(sm.material) >= chain.materials.size()))
      return refuse("submesh at triangle " + std::to_string(sm.first_triangle) + " (" +
                    std::to_string(sm.triangle_count) + " triangles, material " +
                    std::to_string(sm.material) +
                    ") does not continue the runs before it or "
                    "names a material of the " +
                    std::to_string(chain.materials.size()));
    covered = uint64_t(sm.first_triangle) + sm.triangle_count;
  }
  if (surfaces) {
    surfaces->materials = std::move(chain.materials);
    surfaces->texture_base = std::move(chain.texture_base);
    surfaces->images = std::move(chain.images);
  }
  input_triangles = detail::load_u64(b.data() + 24);
  out = std::move(m);
  return CacheLookup::found;
}

}  // namespace lod
