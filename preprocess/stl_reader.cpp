// STL reader (binary and ASCII), single pass over the bytes in memory.
//
// Replaces OpenMesh's STL reader so that a UTF-8 byte-order mark before "solid" is skipped
// (OpenMesh read such a file as binary: "declares 1695166496 triangles") and every count is
// checked against the file's size. Binary or ASCII is decided as OpenMesh does: a file whose
// size is exactly 84 + 50 * (the count at byte 80) is binary even if it starts with "solid";
// otherwise "solid" (after an optional BOM and blanks) means ASCII. Corners with identical
// coordinates become one vertex (as OpenMesh's reader does; -0 and 0 are the same).
#include <cstring>
#include <unordered_map>

#include "preprocess/mesh_readers.h"

namespace lod::detail {
namespace {

struct Key {
  uint32_t b[3];
  bool operator==(const Key& o) const { return b[0] == o.b[0] && b[1] == o.b[1] && b[2] == o.b[2]; }
};
struct KeyHash {
  size_t operator()(const Key& k) const {
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (uint32_t v : k.b) h = (h ^ v) * 0x100000001B3ull, h ^= h >> 29;
    return size_t(h);
  }
};

class Welder {
 public:
  explicit Welder(RawPolygons& raw) : raw_(raw) {}
  void reserve(size_t triangles) {
    map_.reserve(triangles);
    raw_.positions.reserve(triangles * 3);
    raw_.corners.reserve(triangles * 3);
    raw_.offsets.reserve(triangles + 1);
  }
  void corner(const float* xyz) {
    Key k;
    for (int d = 0; d < 3; ++d) {
      const float v = xyz[d] == 0.0f ? 0.0f : xyz[d];  // -0 -> 0
      std::memcpy(&k.b[d], &v, 4);
    }
    auto [it, inserted] = map_.try_emplace(k, int64_t(raw_.vertex_count()));
    if (inserted) raw_.positions.insert(raw_.positions.end(), {xyz[0] == 0.0f ? 0.0f : xyz[0], xyz[1] == 0.0f ? 0.0f : xyz[1], xyz[2] == 0.0f ? 0.0f : xyz[2]});
    raw_.corners.push_back(it->second);
  }
  void end_triangle() { raw_.offsets.push_back(uint32_t(raw_.corners.size())); }

 private:
  RawPolygons& raw_;
  std::unordered_map<Key, int64_t, KeyHash> map_;
};

bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if ((a[i] | 0x20) != (b[i] | 0x20)) return false;
  return true;
}

}  // namespace

Status read_stl(const std::string& what, const uint8_t* data, size_t size, RawPolygons& raw) {
  if (size == 0) return Status::error(what + ": file is empty");
  uint32_t n = 0;
  if (size >= 84) std::memcpy(&n, data + 80, 4);  // little endian (checked in mesh_io.cpp)
  const bool sized_as_binary = size >= 84 && 84 + 50 * uint64_t(n) == size;
  size_t text = 0;
  if (size >= 3 && data[0] == 0xEF && data[1] == 0xBB && data[2] == 0xBF) text = 3;  // UTF-8 BOM
  while (text < size && (data[text] == ' ' || data[text] == '\t' || data[text] == '\r' || data[text] == '\n')) ++text;
  const bool ascii = !sized_as_binary && size - text >= 5 && std::memcmp(data + text, "solid", 5) == 0;
  Welder weld(raw);
  if (!ascii) {
    if (size < 84)
      return Status::error(what + ": truncated binary STL (" + std::to_string(size) + " bytes; the header alone is 84)");
    if (n == 0) return Status::error(what + ": has no faces (binary STL declares 0 triangles)");
    if (84 + 50 * uint64_t(n) > size)
      return Status::error(what + ": truncated: binary STL declares " + std::to_string(n) + " triangles (" +
                           std::to_string(84 + 50 * uint64_t(n)) + " bytes) but the file has " + std::to_string(size) +
                           " bytes");
    weld.reserve(n);
    for (uint32_t t = 0; t < n; ++t) {
      float xyz[9];
      std::memcpy(xyz, data + 84 + 50 * size_t(t) + 12, sizeof xyz);
      for (float v : xyz)
        if (!std::isfinite(v))
          return Status::error(what + ": triangle " + std::to_string(t) + " has a non-finite coordinate (" +
                               describe_nonfinite(v) + ")");
      for (int k = 0; k < 3; ++k) weld.corner(xyz + 3 * k);
      weld.end_triangle();
    }
    return Status::success();
  }
  // ASCII: "solid name / facet normal n n n / outer loop / vertex x y z (x3) / endloop /
  // endfacet ... endsolid". Only the vertex lines carry what we need; every three vertices
  // make a triangle. Names after "solid"/"endsolid" are skipped with their line.
  TextTokens t(data, size, text, 1, /*hash_comments=*/false);
  std::string_view tok;
  t.next(tok);  // "solid"
  t.skip_line();
  float tri[9];
  int corners = 0;
  uint64_t triangle = 0;
  while (t.next(tok)) {
    if (iequals(tok, "endsolid")) {
      t.skip_line();
      continue;
    }
    if (iequals(tok, "solid")) {  // several solids in one file
      t.skip_line();
      continue;
    }
    if (!iequals(tok, "vertex")) continue;  // facet, normal, outer, loop, endloop, endfacet and normal values
    const size_t line = t.line();
    for (int d = 0; d < 3; ++d) {
      double v = 0;
      if (!t.next(tok) || !parse_real(tok, v))
        return Status::error(what + ": triangle " + std::to_string(triangle) + " (line " + std::to_string(line) +
                             ") has a vertex without three numeric coordinates");
      const float f = float(v);
      if (!std::isfinite(f))
        return Status::error(what + ": triangle " + std::to_string(triangle) + " (line " + std::to_string(line) +
                             ") has a non-finite coordinate (" + describe_nonfinite(f) + ")");
      tri[3 * corners + d] = f;
    }
    if (++corners == 3) {
      for (int k = 0; k < 3; ++k) weld.corner(tri + 3 * k);
      weld.end_triangle();
      corners = 0;
      ++triangle;
    }
  }
  if (corners != 0)
    return Status::error(what + ": truncated: triangle " + std::to_string(triangle) + " has only " +
                         std::to_string(corners) + " of its 3 vertices");
  if (triangle == 0) return Status::error(what + ": has no faces (ASCII STL without a 'vertex' line)");
  return Status::success();
}

}  // namespace lod::detail
