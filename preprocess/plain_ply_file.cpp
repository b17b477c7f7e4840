// read_plain_ply_file: the scanners' binary PLY layout read from the file straight into the
// arrays it ends in, hashed on the way (mesh_readers.h). Anything else, or anything the general
// reader must name (a short file, a non-finite coordinate, a face that is not a triangle),
// falls back to reading the file whole: this path only ever accepts what read_ply accepts, the
// same way.
#include <charconv>
#include <cmath>
#include <cstring>
#include <string_view>

#include "preprocess/mesh_readers.h"
#include "runtime/bytes_hasher.h"

namespace lod::detail {
namespace {

struct PlainLayout {
  uint64_t header = 0, vertices = 0, faces = 0;
  bool signed_indices = false;
};

// The whole of n bytes at `offset`, or false (a short file: the general reader names it).
bool read_at(const RegularFile& f, uint8_t* into, size_t n, uint64_t offset) {
  Status st;
  return f.read_at(into, n, offset, st) == n && st;
}

bool count_of(std::string_view word, uint64_t& out) {
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), out);
  return ec == std::errc() && end == word.data() + word.size();
}

// The header, word for word, or false: "ply", the little-endian binary format, comments, a
// vertex element of float x, y, z alone, a face element of one uchar-counted list of 32-bit
// indices, end_header.
bool plain_header(std::string_view text, PlainLayout& out) {
  const size_t end = text.find("\nend_header\n");
  if (end == std::string_view::npos) return false;
  out.header = end + 12;
  std::string_view rest = text.substr(0, end + 1);
  std::vector<std::string_view> lines;
  while (!rest.empty()) {
    const size_t nl = rest.find('\n');
    const std::string_view line = rest.substr(0, nl);
    if (line.substr(0, 8) != "comment " && line.substr(0, 9) != "obj_info " && line != "comment") lines.push_back(line);
    rest.remove_prefix(nl + 1);
  }
  auto is_float = [](std::string_view l, char axis) {
    return l == std::string("property float ") + axis || l == std::string("property float32 ") + axis;
  };
  if (lines.size() != 8 || lines[0] != "ply" || lines[1] != "format binary_little_endian 1.0") return false;
  if (lines[2].substr(0, 15) != "element vertex " || !count_of(lines[2].substr(15), out.vertices)) return false;
  if (!is_float(lines[3], 'x') || !is_float(lines[4], 'y') || !is_float(lines[5], 'z')) return false;
  if (lines[6].substr(0, 13) != "element face " || !count_of(lines[6].substr(13), out.faces)) return false;
  for (const char* count : {"uchar", "uint8"})
    for (const char* index : {"int", "int32", "uint", "uint32"})
      for (const char* name : {"vertex_indices", "vertex_index"})
        if (lines[7] == std::string("property list ") + count + " " + index + " " + name) {
          out.signed_indices = index[0] == 'i';
          return true;
        }
  return false;
}

// Counts the bytes after the header can hold (the general reader names those that they cannot).
bool fits(const PlainLayout& l, uint64_t size) {
  if (l.vertices == 0 || l.faces == 0 || l.vertices > UINT32_MAX || l.header > size) return false;
  const uint64_t left = size - l.header;
  return l.vertices <= left / 12 && l.faces <= (left - 12 * l.vertices) / 13;
}

bool read_positions(const RegularFile& fd, const PlainLayout& l, RawPolygons& raw, BytesHasher& h) {
  raw.positions.resize(size_t(3 * l.vertices));
  uint8_t* bytes = reinterpret_cast<uint8_t*>(raw.positions.data());
  if (!read_at(fd, bytes, size_t(12 * l.vertices), l.header)) return false;
  h.add(bytes, size_t(12 * l.vertices));
  for (float v : raw.positions)
    if (!std::isfinite(v)) return false;
  return true;
}

bool read_triangles(const RegularFile& fd, const PlainLayout& l, RawPolygons& raw, BytesHasher& h) {
  raw.triangles.resize(size_t(3 * l.faces));
  constexpr size_t kRows = 80000;  // ~1 MB of rows at a time
  std::vector<uint8_t> chunk(13 * kRows);
  uint32_t* out = raw.triangles.data();
  const uint64_t at = l.header + 12 * l.vertices;
  for (uint64_t row = 0; row < l.faces;) {
    const size_t rows = size_t(std::min<uint64_t>(kRows, l.faces - row));
    if (!read_at(fd, chunk.data(), 13 * rows, at + 13 * row)) return false;
    h.add(chunk.data(), 13 * rows);
    for (size_t r = 0; r < rows; ++r, out += 3) {
      if (chunk[13 * r] != 3) return false;
      std::memcpy(out, &chunk[13 * r + 1], 12);
    }
    row += rows;
  }
  raw.triangles_signed = l.signed_indices;
  return true;
}

// What follows the faces (other elements, or nothing) is part of the content too.
bool hash_tail(const RegularFile& f, uint64_t from, BytesHasher& h) {
  std::vector<uint8_t> chunk(size_t(1) << 20);
  for (;;) {
    Status st;
    const size_t got = f.read_at(chunk.data(), chunk.size(), from, st);
    if (!st) return false;
    h.add(chunk.data(), got);
    from += got;
    if (got < chunk.size()) return true;
  }
}

}  // namespace

Status read_plain_ply_file(const std::filesystem::path& path, RawPolygons& raw, uint64_t& content_hash, bool& handled) {
  handled = false;
  RegularFile f;
  if (Status s = open_regular_file(path, kInputFileLimit, f); !s) return s;
  std::vector<uint8_t> head(size_t(std::min<uint64_t>(f.size, 65536)));
  PlainLayout l;
  if (!read_at(f, head.data(), head.size(), 0) ||
      !plain_header(std::string_view(reinterpret_cast<const char*>(head.data()), head.size()), l) || !fits(l, f.size))
    return Status::success();
  BytesHasher h;
  h.add(head.data(), size_t(l.header));
  RawPolygons mine;
  try {
    if (!read_positions(f, l, mine, h) || !read_triangles(f, l, mine, h) ||
        !hash_tail(f, l.header + 12 * l.vertices + 13 * l.faces, h))
      return Status::success();
  } catch (const std::bad_alloc&) {
    return Status::error(path.string() + ": not enough memory to load it (" + std::to_string(f.size) + " bytes)");
  }
  raw = std::move(mine);
  content_hash = h.finish();
  handled = true;
  return Status::success();
}

}  // namespace lod::detail
