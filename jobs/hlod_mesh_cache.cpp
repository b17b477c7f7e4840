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
#include "runtime/regular_file.h"

namespace lod {
namespace {

constexpr char kMagic[8] = {'L', 'O', 'D', 'H', 'M', 'S', 'H', '\n'};
constexpr uint64_t kFixedBytes = 72;
constexpr uint32_t kFlagUvs = 1;
constexpr uint32_t kFlagColors = 2;
constexpr uint32_t kFlagUvs1 = 4;

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

HlodMeshEntry hlod_mesh_entry(uint64_t source_hash, const MeshData& mesh, uint64_t input_triangles,
                              const HlodSurfaces& surfaces) {
  const size_t nv = mesh.vertex_count();
  const Columns has{mesh.uvs.size() == 2 * nv && nv > 0, mesh.uvs1.size() == 2 * nv && nv > 0,
                    mesh.colors.size() == 4 * nv && nv > 0};
  LodChain chain;
  chain.materials = surfaces.materials;
  chain.texture_base = surfaces.texture_base;
  HlodMeshEntry e;
  std::vector<std::vector<uint8_t>>& own = e.owned;
  own.reserve(12);  // the parts point into them: never reallocated (at most 10)
  const std::vector<uint8_t>& materials =
      own.emplace_back(surfaces.materials.empty() ? std::vector<uint8_t>() : encode_material_section(chain));
  const std::vector<uint8_t>& images =
      own.emplace_back(surfaces.images.empty() ? std::vector<uint8_t>() : encode_image_section(surfaces.images));
  const std::vector<uint8_t>& head =
      own.emplace_back(entry_head(source_hash, input_triangles, mesh, has, materials.size(), images.size()));
  const std::vector<uint8_t>& rows = own.emplace_back(submesh_rows(mesh));
  e.parts = {head, le_words(mesh.positions, own), le_words(mesh.indices, own)};
  if (has.uvs) e.parts.push_back(le_words(mesh.uvs, own));
  if (has.uvs1) e.parts.push_back(le_words(mesh.uvs1, own));
  if (has.colors) e.parts.push_back(le_words(mesh.colors, own));
  e.parts.insert(e.parts.end(), {rows, materials, images});
  BytesHasher hash;
  for (std::span<const uint8_t> part : e.parts) hash.add(part.data(), part.size());
  detail::ByteWriter checksum;
  checksum.u64(hash.finish());
  e.parts.push_back(own.emplace_back(std::move(checksum.bytes)));
  return e;
}

uint64_t HlodMeshEntry::size() const {
  uint64_t n = 0;
  for (std::span<const uint8_t> part : parts) n += part.size();
  return n;
}

void HlodMeshEntry::copy_to(uint8_t* out) const {
  for (std::span<const uint8_t> part : parts) out = std::copy(part.begin(), part.end(), out);
}

Status store_hlod_mesh(const std::filesystem::path& dir, uint64_t source_hash, const MeshData& mesh,
                       uint64_t input_triangles, const HlodSurfaces& surfaces) {
  const HlodMeshEntry e = hlod_mesh_entry(source_hash, mesh, input_triangles, surfaces);
  return write_file_atomic(hlod_mesh_entry_path(dir, source_hash), e.parts);
}

Status store_hlod_mesh_bytes(const std::filesystem::path& dir, uint64_t source_hash, std::span<const uint8_t> entry) {
  return write_file_atomic(hlod_mesh_entry_path(dir, source_hash), entry);
}

namespace {

// Where an entry's columns lie, from its head; counts checked against its size.
struct EntryLayout {
  uint32_t flags = 0;
  uint64_t vertices = 0, indices = 0, submeshes = 0, material_bytes = 0, image_bytes = 0, input_triangles = 0;
  size_t positions = 0, index_words = 0, uvs = 0, uvs1 = 0, colors = 0, rows = 0, materials = 0, images = 0;
};

// The fixed header (`b`: at least its kFixedBytes when `size` allows them) against the
// entry's `size`: read before the entry is read whole.
std::string head_layout(std::span<const uint8_t> b, uint64_t size, EntryLayout& l) {
  if (size < kFixedBytes + 8 || b.size() < kFixedBytes) return "too short for a cleaned mesh entry (truncated?)";
  if (std::memcmp(b.data(), kMagic, 8) != 0) return "not a cleaned mesh entry (bad magic bytes)";
  if (detail::load_u32(b.data() + 8) != kHlodMeshEntryVersion) return "entry version is not supported";
  l.flags = detail::load_u32(b.data() + 12);
  l.input_triangles = detail::load_u64(b.data() + 24);
  l.vertices = detail::load_u64(b.data() + 32), l.indices = detail::load_u64(b.data() + 40);
  l.submeshes = detail::load_u64(b.data() + 48), l.material_bytes = detail::load_u64(b.data() + 56);
  l.image_bytes = detail::load_u64(b.data() + 64);
  if ((l.flags & ~(kFlagUvs | kFlagColors | kFlagUvs1)) != 0) return "unknown flags " + std::to_string(l.flags);
  const uint64_t per_vertex =
      12 + ((l.flags & kFlagUvs) ? 8 : 0) + ((l.flags & kFlagUvs1) ? 8 : 0) + ((l.flags & kFlagColors) ? 16 : 0);
  // Counts against the size before anything is allocated (each bounded first, so the sum cannot overflow).
  if (l.vertices >= UINT32_MAX || l.indices % 3 != 0 || l.indices > size / 4 || l.submeshes > size / 12 ||
      l.material_bytes > size || l.image_bytes > size ||
      size != kFixedBytes + per_vertex * l.vertices + 4 * l.indices + 12 * l.submeshes + l.material_bytes +
                  l.image_bytes + 8)
    return "its counts (" + std::to_string(l.vertices) + " vertices, " + std::to_string(l.indices) + " indices, " +
           std::to_string(l.submeshes) + " submeshes, " + std::to_string(l.material_bytes) + " bytes of materials, " +
           std::to_string(l.image_bytes) + " of images) do not match its " + std::to_string(size) +
           " bytes (truncated?)";
  return {};
}

std::string read_layout(std::span<const uint8_t> b, uint64_t source_hash, bool check, EntryLayout& l) {
  if (std::string bad = head_layout(b, b.size(), l); !bad.empty()) return bad;
  const size_t body = b.size() - 8;
  if (check && detail::load_u64(b.data() + body) != hash_bytes(b.data(), body)) return "checksum mismatch (corrupted)";
  if (detail::load_u64(b.data() + 16) != source_hash) return "written for another source (a misplaced entry)";
  size_t at = kFixedBytes;
  auto column = [&](size_t& where, uint64_t bytes) { where = at, at += size_t(bytes); };
  column(l.positions, 12 * l.vertices);
  column(l.index_words, 4 * l.indices);
  column(l.uvs, (l.flags & kFlagUvs) ? 8 * l.vertices : 0);
  column(l.uvs1, (l.flags & kFlagUvs1) ? 8 * l.vertices : 0);
  column(l.colors, (l.flags & kFlagColors) ? 16 * l.vertices : 0);
  column(l.rows, 12 * l.submeshes);
  column(l.materials, l.material_bytes);
  column(l.images, l.image_bytes);
  return {};
}

// The small parts: submesh runs (in order inside the triangles, each naming a stored material
// or the default), the materials and the images they embed.
std::string read_surfaces(std::span<const uint8_t> b, const EntryLayout& l, std::vector<Submesh>& submeshes,
                          HlodSurfaces* surfaces) {
  submeshes.resize(size_t(l.submeshes));
  const uint8_t* p = b.data() + l.rows;
  for (Submesh& sm : submeshes) {
    sm.first_triangle = detail::load_u32(p);
    sm.triangle_count = detail::load_u32(p + 4);
    sm.material = int32_t(detail::load_u32(p + 8));
    p += 12;
  }
  LodChain chain;  // images first: the materials' embedded:<k> are checked against them
  if (l.image_bytes > 0 && l.material_bytes == 0) return "it has images but no materials";
  if (l.image_bytes > 0)
    if (Status s = decode_image_section({b.data() + l.images, size_t(l.image_bytes)}, "images", chain.images); !s)
      return s.message;
  if (l.material_bytes > 0)
    if (Status s = decode_material_section({b.data() + l.materials, size_t(l.material_bytes)}, "materials", chain); !s)
      return s.message;
  // The writer stores the section only with materials: one without (its texture base and
  // images lost on the next store) is not one it wrote.
  if (l.material_bytes > 0 && chain.materials.empty()) return "its materials section holds no materials";
  uint64_t covered = 0;
  const uint64_t triangles = l.indices / 3;
  for (const Submesh& sm : submeshes) {
    if (sm.first_triangle < covered || sm.first_triangle > triangles || sm.triangle_count > triangles - sm.first_triangle ||
        sm.material < -1 || (sm.material >= 0 && size_t(sm.material) >= chain.materials.size()))
      return "submesh at triangle " + std::to_string(sm.first_triangle) + " (" + std::to_string(sm.triangle_count) +
             " triangles, material " + std::to_string(sm.material) +
             ") does not continue the runs before it or names a material of the " +
             std::to_string(chain.materials.size());
    covered = uint64_t(sm.first_triangle) + sm.triangle_count;
  }
  if (surfaces) {
    surfaces->materials = std::move(chain.materials);
    surfaces->texture_base = std::move(chain.texture_base);
    surfaces->images = std::move(chain.images);
  }
  return {};
}

std::string check_values(const MeshView& m) {
  const size_t vertices = m.vertex_count();
  for (uint32_t i : m.indices)
    if (i >= vertices) return "an index names vertex " + std::to_string(i) + " of " + std::to_string(vertices);
  for (float v : m.positions)
    if (!std::isfinite(v)) return "a position is not finite";
  for (float v : m.uvs)
    if (!std::isfinite(v)) return "a texture coordinate is not finite";
  for (float v : m.uvs1)
    if (!std::isfinite(v)) return "a TEXCOORD_1 value is not finite";
  for (float v : m.colors)
    if (!std::isfinite(v)) return "a colour is not finite";
  return {};
}

}  // namespace

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
  // The header against the entry's size first, then the entry whole.
  auto refused = [&](const Status& s) {
    if (why) *why = s.message;  // names the file already
    return CacheLookup::refused;
  };
  RegularFile f;
  if (Status s = open_regular_file(path, kInputFileLimit, f); !s) return refused(s);
  std::vector<uint8_t> b;
  if (Status s = f.read_head(kFixedBytes, b); !s) return refused(s);
  EntryLayout head;
  if (std::string bad = head_layout(b, f.size, head); !bad.empty()) return refuse(bad);
  if (Status s = f.read_all(b); !s) return refused(s);
  EntryLayout l;
  if (std::string bad = read_layout(b, source_hash, true, l); !bad.empty()) return refuse(bad);
  MeshData m;
  m.source = source_name;
  auto column = [&](size_t at, uint64_t count, std::vector<float>& into) {
    into.resize(size_t(count));
    const uint8_t* p = b.data() + at;
    for (float& v : into) v = detail::load_f32(p), p += 4;
  };
  column(l.positions, 3 * l.vertices, m.positions);
  m.indices.resize(size_t(l.indices));
  const uint8_t* p = b.data() + l.index_words;
  for (uint32_t& i : m.indices) i = detail::load_u32(p), p += 4;
  if (l.flags & kFlagUvs) column(l.uvs, 2 * l.vertices, m.uvs);
  if (l.flags & kFlagUvs1) column(l.uvs1, 2 * l.vertices, m.uvs1);
  if (l.flags & kFlagColors) column(l.colors, 4 * l.vertices, m.colors);
  HlodSurfaces read;
  if (std::string bad = read_surfaces(b, l, m.submeshes, &read); !bad.empty()) return refuse(bad);
  if (std::string bad = check_values(m); !bad.empty()) return refuse(bad);
  if (surfaces) *surfaces = std::move(read);
  input_triangles = l.input_triangles;
  out = std::move(m);
  return CacheLookup::found;
}

Status view_hlod_mesh(std::span<const uint8_t> entry, uint64_t source_hash, std::string_view source_name, bool check,
                      HlodMeshInPlace& out) {
  if constexpr (std::endian::native != std::endian::little)
    return Status::error(std::string(source_name) + ": a cleaned mesh is viewed in place on little-endian hosts only");
  auto refuse = [&](const std::string& reason) {
    return Status::error(std::string(source_name) + ": the cleaned mesh " + reason);
  };
  if (reinterpret_cast<uintptr_t>(entry.data()) % alignof(float) != 0) return refuse("is not aligned for its arrays");
  EntryLayout l;
  if (std::string bad = read_layout(entry, source_hash, check, l); !bad.empty()) return refuse(bad);
  HlodMeshInPlace v;
  auto floats = [&](size_t at, uint64_t count) {
    return std::span<const float>(reinterpret_cast<const float*>(entry.data() + at), size_t(count));
  };
  v.mesh.source = source_name;
  v.mesh.positions = floats(l.positions, 3 * l.vertices);
  v.mesh.indices = {reinterpret_cast<const uint32_t*>(entry.data() + l.index_words), size_t(l.indices)};
  if (l.flags & kFlagUvs) v.mesh.uvs = floats(l.uvs, 2 * l.vertices);
  if (l.flags & kFlagUvs1) v.mesh.uvs1 = floats(l.uvs1, 2 * l.vertices);
  if (l.flags & kFlagColors) v.mesh.colors = floats(l.colors, 4 * l.vertices);
  if (std::string bad = read_surfaces(entry, l, v.submeshes, &v.surfaces); !bad.empty()) return refuse(bad);
  v.mesh.submeshes = v.submeshes;
  if (check)
    if (std::string bad = check_values(v.mesh); !bad.empty()) return refuse(bad);
  v.input_triangles = l.input_triangles;
  out = std::move(v);
  out.mesh.submeshes = out.submeshes;  // the moved vector keeps its buffer; pointed to again for clarity
  return Status::success();
}

}  // namespace lod
