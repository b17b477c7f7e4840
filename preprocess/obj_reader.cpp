// OBJ reader, single pass over the bytes in memory.
//
// Replaces OpenMesh's OBJ reader, which asserts (aborts the process) on a corner without a
// vertex index ("f /1/1 ..."; also "f\r/1" since any blank ends a keyword), drops a 'v' line
// it cannot parse (shifting every later index), opens whatever file a "mtllib" line names (a
// FIFO blocks) and turns an out-of-range relative index into handle arithmetic.
//
// Read: "v x y z" (anything after the three numbers, such as w or a colour, is ignored) and
// "f c0 c1 c2 ..." with corners "v", "v/vt", "v//vn" or "v/vt/vn"; a negative v counts back
// from the last vertex before the face (-1 = that vertex). Other statements (vt, vn, g, o,
// s, usemtl, mtllib, l, p, ...) are ignored. A line ending in '\' continues on the next one.
// Keywords and values are separated by any blank (space, tab, CR, VT, FF), as iostreams do.
// A UTF-8 byte-order mark before the first line is skipped; UTF-16 is refused. A vertex
// repeated within one face is dropped after its first corner (as OpenMesh's reader did).
#include <cstdlib>
#include <cstring>
#include <limits>
#include <unordered_set>

#include "preprocess/mesh_readers.h"

namespace lod::detail {
namespace {

bool blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

}  // namespace

Status read_obj(const std::string& what, const uint8_t* data, size_t size, RawPolygons& raw) {
  if (size >= 2 && ((data[0] == 0xFE && data[1] == 0xFF) || (data[0] == 0xFF && data[1] == 0xFE)))
    return Status::error(what + ": is UTF-16 text; OBJ files must be ASCII or UTF-8");
  if (size >= 3 && data[0] == 0xEF && data[1] == 0xBB && data[2] == 0xBF) data += 3, size -= 3;
  const char* text = reinterpret_cast<const char*>(data);
  size_t pos = 0, line_no = 0;
  uint64_t faces = 0;
  std::string joined;  // a statement continued over several lines
  std::string number;  // one coordinate, NUL-terminated for strtod
  std::unordered_set<int64_t> seen;  // corners of a long face
  while (pos < size) {
    ++line_no;
    const size_t first_line = line_no;
    const void* nl = std::memchr(text + pos, '\n', size - pos);
    size_t end = nl ? size_t(static_cast<const char*>(nl) - text) : size;
    std::string_view line(text + pos, end - pos);
    pos = nl ? end + 1 : size;
    // Continuation: "...\" + newline joins the next line (with a blank in between).
    auto continued = [](std::string_view l) {
      while (!l.empty() && blank(l.back())) l.remove_suffix(1);
      return !l.empty() && l.back() == '\\';
    };
    if (continued(line)) {
      joined.clear();
      for (;;) {
        std::string_view l = line;
        while (!l.empty() && blank(l.back())) l.remove_suffix(1);
        const bool more = !l.empty() && l.back() == '\\';
        if (more) l.remove_suffix(1);
        joined.append(l);
        joined.push_back(' ');
        if (!more || pos >= size) break;
        ++line_no;
        nl = std::memchr(text + pos, '\n', size - pos);
        end = nl ? size_t(static_cast<const char*>(nl) - text) : size;
        line = std::string_view(text + pos, end - pos);
        pos = nl ? end + 1 : size;
      }
      line = joined;
    }
    size_t s = 0;
    while (s < line.size() && blank(line[s])) ++s;
    size_t k = s;
    while (k < line.size() && !blank(line[k])) ++k;
    const std::string_view keyword = line.substr(s, k - s);
    if (keyword == "v") {
      float xyz[3];
      size_t at = k;
      for (int d = 0; d < 3; ++d) {
        while (at < line.size() && blank(line[at])) ++at;
        size_t e = at;
        while (e < line.size() && !blank(line[e])) ++e;
        // strtod on the token: "3.1+e2" reads as 3.1, as iostreams do.
        number.assign(line.substr(at, std::min<size_t>(e - at, 64)));
        char* stop = nullptr;
        const double v = number.empty() ? 0 : std::strtod(number.c_str(), &stop);
        if (number.empty() || stop == number.c_str())
          return Status::error(what + ": vertex " + std::to_string(raw.vertex_count()) + " (line " +
                               std::to_string(first_line) + ") does not have three numeric coordinates");
        xyz[d] = float(v);
        at = e;
      }
      for (int d = 0; d < 3; ++d)
        if (!std::isfinite(xyz[d]))
          return Status::error(what + ": vertex " + std::to_string(raw.vertex_count()) + " (line " +
                               std::to_string(first_line) + ") has a non-finite coordinate (" +
                               describe_nonfinite(xyz[d]) + ")");
      if (raw.vertex_count() >= std::numeric_limits<uint32_t>::max())
        return Status::error(what + ": more than 2^32-1 vertices");
      raw.positions.insert(raw.positions.end(), xyz, xyz + 3);
    } else if (keyword == "f") {
      const int64_t before = int64_t(raw.vertex_count());
      const size_t face_begin = raw.corners.size();
      seen.clear();
      // A vertex repeated within a face is dropped after its first corner, as OpenMesh's
      // reader did ("f 1 2 3 4 1 2 3 4" is the quad 1 2 3 4).
      auto add = [&](int64_t idx) {
        const size_t n = raw.corners.size() - face_begin;
        if (n < 16) {
          for (size_t c = face_begin; c < raw.corners.size(); ++c)
            if (raw.corners[c] == idx) return;
        } else {
          if (seen.empty()) seen.insert(raw.corners.begin() + std::ptrdiff_t(face_begin), raw.corners.end());
          if (!seen.insert(idx).second) return;
        }
        raw.corners.push_back(idx);
      };
      size_t at = k;
      for (;;) {
        while (at < line.size() && blank(line[at])) ++at;
        if (at >= line.size()) break;
        size_t e = at;
        while (e < line.size() && !blank(line[e])) ++e;
        const std::string_view corner = line.substr(at, e - at);
        at = e;
        const std::string_view index = corner.substr(0, corner.find('/'));
        int64_t v = 0;
        if (!parse_int(index, v) || v == 0)
          return Status::error(what + ": face " + std::to_string(faces) + " (line " + std::to_string(first_line) +
                               ") has a corner without a valid vertex index ('" + quote_token(corner) + "')");
        if (v < 0) {
          if (v < -before)
            return Status::error(what + ": face " + std::to_string(faces) + " references vertex " +
                                 std::to_string(v) + " (relative) of " + std::to_string(before) +
                                 " before it, on line " + std::to_string(first_line));
          add(before + v);
        } else {
          add(v - 1);  // checked against the final count by finish_polygons
        }
      }
      if (raw.corners.size() > std::numeric_limits<uint32_t>::max())
        return Status::error(what + ": more than 2^32-1 face corners");
      raw.offsets.push_back(uint32_t(raw.corners.size()));
      ++faces;
    }
  }
  if (faces == 0)
    return Status::error(what + ": has no faces (points only: " + std::to_string(raw.vertex_count()) + " vertices)");
  return Status::success();
}

}  // namespace lod::detail
