// PLY reader (ASCII, binary little and big endian), single pass over the bytes in memory.
//
// Replaces OpenMesh's PLY reader, whose header parser loops forever on some unknown words
// and which reserves whatever a header declares. Reads element "vertex" (x, y, z of any
// scalar type) and element "face" (list "vertex_indices" or "vertex_index" with an integer
// count and integer indices); every other element and property is skipped by its declared
// size. Before an element's rows are read its count is checked against the bytes left (a row
// takes at least its fixed size in binary, two bytes per property in ASCII), so nothing is
// reserved that the file cannot hold; an element whose rows take no bytes is skipped in O(1).
#include <algorithm>
#include <cstring>
#include <limits>

#include "preprocess/mesh_readers.h"

namespace lod::detail {
namespace {

enum class Type { none, i8, u8, i16, u16, i32, u32, f32, f64 };

Type parse_type(std::string_view t) {
  if (t == "char" || t == "int8") return Type::i8;
  if (t == "uchar" || t == "uint8") return Type::u8;
  if (t == "short" || t == "int16") return Type::i16;
  if (t == "ushort" || t == "uint16") return Type::u16;
  if (t == "int" || t == "int32") return Type::i32;
  if (t == "uint" || t == "uint32") return Type::u32;
  if (t == "float" || t == "float32") return Type::f32;
  if (t == "double" || t == "float64") return Type::f64;
  return Type::none;
}
size_t type_size(Type t) {
  switch (t) {
    case Type::i8: case Type::u8: return 1;
    case Type::i16: case Type::u16: return 2;
    case Type::i32: case Type::u32: case Type::f32: return 4;
    case Type::f64: return 8;
    default: return 0;
  }
}
bool is_real(Type t) { return t == Type::f32 || t == Type::f64; }

// Vertex roles x..t index a row's values (slot = role - x); indices is the face list.
enum class Role { skip, x, y, z, nx, ny, nz, red, green, blue, alpha, s, t, indices };
constexpr int kSlots = int(Role::t) - int(Role::x) + 1;
int slot(Role r) { return int(r) - int(Role::x); }
bool is_vertex_role(Role r) { return r >= Role::x && r <= Role::t; }

// The names scanners and MeshLab write for each vertex attribute.
Role vertex_role(std::string_view n) {
  if (n == "x") return Role::x;
  if (n == "y") return Role::y;
  if (n == "z") return Role::z;
  if (n == "nx") return Role::nx;
  if (n == "ny") return Role::ny;
  if (n == "nz") return Role::nz;
  if (n == "red" || n == "diffuse_red" || n == "r") return Role::red;
  if (n == "green" || n == "diffuse_green" || n == "g") return Role::green;
  if (n == "blue" || n == "diffuse_blue" || n == "b") return Role::blue;
  if (n == "alpha" || n == "diffuse_alpha" || n == "a") return Role::alpha;
  if (n == "s" || n == "u" || n == "texture_u" || n == "texture_s") return Role::s;
  if (n == "t" || n == "v" || n == "texture_v" || n == "texture_t") return Role::t;
  return Role::skip;
}

struct Property {
  std::string name;
  Type type = Type::none;      // value type
  bool is_list = false;
  Type count_type = Type::none;
  Role role = Role::skip;
  double scale = 1;  // a colour's divisor: the largest value of its integer type (1 for reals)
};

// Which attribute groups the vertex rows carry (each kept only whole: nx ny nz, red green blue
// [alpha], s t), and appending one row's values to them.
struct VertexGroups {
  bool normals = false, colors = false, alpha = false, uvs = false;
  bool any() const { return normals || colors || uvs; }
};

double colour_scale(Type t) {
  switch (t) {
    case Type::u8: return 255;
    case Type::i8: return 127;
    case Type::u16: return 65535;
    case Type::i16: return 32767;
    case Type::u32: return 4294967295.0;
    case Type::i32: return 2147483647.0;
    default: return 1;
  }
}

void append_attributes(const VertexGroups& g, const double* v, RawPolygons& raw) {
  auto at = [v](Role r) { return float(v[slot(r)]); };
  if (g.normals) raw.normals.insert(raw.normals.end(), {at(Role::nx), at(Role::ny), at(Role::nz)});
  if (g.colors)
    raw.colors.insert(raw.colors.end(), {at(Role::red), at(Role::green), at(Role::blue), g.alpha ? at(Role::alpha) : 1.0f});
  if (g.uvs) raw.uvs.insert(raw.uvs.end(), {at(Role::s), at(Role::t)});
}
struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> properties;
  size_t header_line = 0;
};

// Splits a header line into words (spaces/tabs).
std::vector<std::string_view> words_of(std::string_view line) {
  std::vector<std::string_view> w;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r' || line[i] == '\v' || line[i] == '\f')) ++i;
    const size_t s = i;
    while (i < line.size() && !(line[i] == ' ' || line[i] == '\t' || line[i] == '\r' || line[i] == '\v' || line[i] == '\f')) ++i;
    if (i > s) w.push_back(line.substr(s, i - s));
    if (w.size() > 64) break;  // no header line has that many words; stop quadratic work
  }
  return w;
}

// A binary value, widened. Reads exactly type_size(t) bytes at p (the caller checked them).
double load_real(const uint8_t* p, Type t, bool big) {
  uint8_t b[8];
  const size_t n = type_size(t);
  for (size_t i = 0; i < n; ++i) b[i] = big ? p[n - 1 - i] : p[i];
  switch (t) {
    case Type::i8: return double(int8_t(b[0]));
    case Type::u8: return double(b[0]);
    case Type::i16: { int16_t v; std::memcpy(&v, b, 2); return v; }
    case Type::u16: { uint16_t v; std::memcpy(&v, b, 2); return v; }
    case Type::i32: { int32_t v; std::memcpy(&v, b, 4); return v; }
    case Type::u32: { uint32_t v; std::memcpy(&v, b, 4); return v; }
    case Type::f32: { float v; std::memcpy(&v, b, 4); return double(v); }
    case Type::f64: { double v; std::memcpy(&v, b, 8); return v; }
    default: return 0;
  }
}
int64_t load_int(const uint8_t* p, Type t, bool big) {
  uint8_t b[8];
  const size_t n = type_size(t);
  for (size_t i = 0; i < n; ++i) b[i] = big ? p[n - 1 - i] : p[i];
  switch (t) {
    case Type::i8: return int8_t(b[0]);
    case Type::u8: return b[0];
    case Type::i16: { int16_t v; std::memcpy(&v, b, 2); return v; }
    case Type::u16: { uint16_t v; std::memcpy(&v, b, 2); return v; }
    case Type::i32: { int32_t v; std::memcpy(&v, b, 4); return v; }
    case Type::u32: { uint32_t v; std::memcpy(&v, b, 4); return v; }
    default: return 0;
  }
}


Status truncated_in(const std::string& what, const Element& e, uint64_t row) {
  return Status::error(what + ": truncated: the data ends inside " + quote_token(e.name) + " " + std::to_string(row) +
                       " of " + std::to_string(e.count) + " declared");
}

// Binary vertex rows without lists: every row the same size, each coordinate at its offset.
// The common scanner layout (little-endian float x, y, z first) is read without widening.
Status binary_vertex_rows(const std::string& what, const uint8_t* data, size_t size, size_t& at, const Element& e,
                          bool big, const VertexGroups& groups, RawPolygons& raw) {
  size_t row = 0, offset[3] = {0, 0, 0};
  Type type[3] = {Type::none, Type::none, Type::none};
  struct Column { size_t offset; const Property* p; };
  std::vector<Column> attributes;  // the kept groups' columns
  for (const Property& p : e.properties) {
    if (p.role >= Role::x && p.role <= Role::z) offset[int(p.role) - int(Role::x)] = row, type[int(p.role) - int(Role::x)] = p.type;
    else if (is_vertex_role(p.role)) attributes.push_back({row, &p});
    row += type_size(p.type);
  }
  if (e.count > (size - at) / row) return truncated_in(what, e, (size - at) / row);
  const bool plain = !big && type[0] == Type::f32 && type[1] == Type::f32 && type[2] == Type::f32 && offset[0] == 0 &&
                     offset[1] == 4 && offset[2] == 8;
  const size_t base = raw.positions.size();
  raw.positions.resize(base + 3 * size_t(e.count));
  float* out = raw.positions.data() + base;
  for (uint64_t i = 0; i < e.count; ++i, at += row, out += 3) {
    if (plain) std::memcpy(out, data + at, 12);
    else
      for (int k = 0; k < 3; ++k) out[k] = type[k] == Type::none ? 0.0f : float(load_real(data + at + offset[k], type[k], big));
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(out[k]))
        return Status::error(what + ": vertex " + std::to_string(i) + " has a non-finite coordinate (" +
                             describe_nonfinite(out[k]) + ")");
    if (attributes.empty()) continue;
    double v[kSlots] = {};
    for (const Column& c : attributes) v[slot(c.p->role)] = load_real(data + at + c.offset, c.p->type, big) / c.p->scale;
    append_attributes(groups, v, raw);
  }
  return Status::success();
}

// Binary face rows holding only their index list: count, then indices, row after row.
// Triangles whose corners are little-endian 32-bit numbers, read straight into raw.triangles
// while every face has three; returns how many were, and the general reader takes on from the
// first that has not (after spill_triangles).
uint64_t plain_triangle_rows(const uint8_t* data, size_t size, size_t& at, const Element& e, RawPolygons& raw) {
  raw.triangles.reserve(std::min<uint64_t>(3 * e.count, (size - at) / 4));  // never more than the file backs
  uint64_t i = 0;
  for (; i < e.count && size - at >= 13 && data[at] == 3; ++i, at += 13) {
    uint32_t v[3];
    std::memcpy(v, data + at + 1, 12);
    raw.triangles.insert(raw.triangles.end(), v, v + 3);
  }
  return i;
}

// The triangles read so far as corners and offsets, for faces that are not all triangles.
void spill_triangles(RawPolygons& raw) {
  raw.corners.reserve(raw.corners.size() + raw.triangles.size());
  for (uint32_t v : raw.triangles) {
    raw.corners.push_back(raw.triangles_signed ? int64_t(int32_t(v)) : int64_t(v));
    if (raw.corners.size() % 3 == 0) raw.offsets.push_back(uint32_t(raw.corners.size()));
  }
  std::vector<uint32_t>().swap(raw.triangles);
}

Status binary_face_rows(const std::string& what, const uint8_t* data, size_t size, size_t& at, const Element& e,
                        bool big, RawPolygons& raw) {
  const Property& p = e.properties.front();
  const size_t cs = type_size(p.count_type), s = type_size(p.type);
  const bool plain = !big && cs == 1 && s == 4;
  uint64_t first = 0;
  if (plain && raw.corners.empty() && raw.triangles.empty()) {
    raw.triangles_signed = p.type != Type::u32;
    first = plain_triangle_rows(data, size, at, e, raw);
    if (first == e.count) return Status::success();
  }
  if (!raw.triangles.empty()) spill_triangles(raw);
  // Triangles, as far as the bytes left can hold them: never more than the file backs.
  raw.corners.reserve(raw.corners.size() + std::min<uint64_t>(3 * (e.count - first), (size - at) / s));
  for (uint64_t i = first; i < e.count; ++i) {
    if (size - at < cs) return truncated_in(what, e, i);
    const int64_t c = plain ? int64_t(data[at]) : load_int(data + at, p.count_type, big);
    at += cs;
    if (c < 0)
      return Status::error(what + ": " + quote_token(e.name) + " " + std::to_string(i) + " has a negative list length (" +
                           std::to_string(c) + ")");
    if (uint64_t(c) > (size - at) / s) return truncated_in(what, e, i);
    for (int64_t k = 0; k < c; ++k, at += s) {
      if (!plain) {
        raw.corners.push_back(load_int(data + at, p.type, big));
        continue;
      }
      if (p.type == Type::u32) {
        uint32_t v;
        std::memcpy(&v, data + at, 4);
        raw.corners.push_back(v);
      } else {
        int32_t v;
        std::memcpy(&v, data + at, 4);
        raw.corners.push_back(v);
      }
    }
    if (raw.corners.size() > std::numeric_limits<uint32_t>::max()) return Status::error(what + ": more than 2^32-1 face corners");
    raw.offsets.push_back(uint32_t(raw.corners.size()));
  }
  return Status::success();
}

// Roles for the vertex element's properties: positions, and each attribute group only when
// whole (a lone 'nx' or 'red' is skipped); what is skipped is said in `warnings`.
VertexGroups assign_vertex_roles(const std::string& what, Element& vertex, std::vector<std::string>& warnings) {
  bool seen[kSlots] = {};
  for (Property& p : vertex.properties) {
    const Role r = p.is_list ? Role::skip : vertex_role(p.name);
    if (r == Role::skip || seen[slot(r)]) continue;  // a second name for one role: the first wins
    p.role = r;
    seen[slot(r)] = true;
    if (r >= Role::red && r <= Role::alpha) p.scale = colour_scale(p.type);
  }
  VertexGroups g;
  g.normals = seen[slot(Role::nx)] && seen[slot(Role::ny)] && seen[slot(Role::nz)];
  g.colors = seen[slot(Role::red)] && seen[slot(Role::green)] && seen[slot(Role::blue)];
  g.alpha = g.colors && seen[slot(Role::alpha)];
  g.uvs = seen[slot(Role::s)] && seen[slot(Role::t)];
  std::string skipped;
  for (Property& p : vertex.properties) {
    const bool kept = (p.role >= Role::x && p.role <= Role::z) || (g.normals && p.role >= Role::nx && p.role <= Role::nz) ||
                      (g.colors && p.role >= Role::red && p.role <= Role::alpha) || (g.uvs && p.role >= Role::s && p.role <= Role::t);
    if (kept) continue;
    p.role = Role::skip;
    if (skipped.size() < 200) skipped += (skipped.empty() ? "'" : ", '") + quote_token(p.name) + "'";
  }
  if (!skipped.empty())
    warnings.push_back(what + ": vertex properties " + skipped + " are not imported (positions, nx ny nz, red green blue "
                       "[alpha] and s t / u v are)");
  return g;
}

}  // namespace

Status read_ply(const std::string& what, const uint8_t* data, size_t size, RawPolygons& raw) {
  if (size == 0) return Status::error(what + ": file is empty");
  // ---- header: text lines up to "end_header" -------------------------------------------
  size_t pos = 0;
  size_t line_no = 0;
  auto next_line = [&](std::string_view& line) {
    if (pos >= size) return false;
    const void* nl = std::memchr(data + pos, '\n', size - pos);
    const size_t end = nl ? size_t(static_cast<const uint8_t*>(nl) - data) : size;
    line = std::string_view(reinterpret_cast<const char*>(data) + pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos = nl ? end + 1 : size;
    ++line_no;
    return true;
  };
  std::string_view line;
  if (!next_line(line) || line != "ply")
    return Status::error(what + ": not a PLY file (first line is not 'ply')");
  auto bad_header = [&](const std::string& why) {
    return Status::error(what + ": PLY header line " + std::to_string(line_no) + ": " + why);
  };
  auto quoted_line = [&] {
    std::string q = "'";  // appended piecewise: GCC 12 warns (-Wrestrict) on "'" + std::string
    q += quote_token(line.substr(0, 80));
    return q += "'";
  };
  std::string format;
  std::vector<Element> elements;
  bool ended = false;
  while (next_line(line)) {
    const std::vector<std::string_view> w = words_of(line);
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "format") {
      double version = 0;
      if (w.size() != 3 || !parse_real(w[2], version)) return bad_header("malformed format line " + quoted_line());
      if (!format.empty()) return bad_header("a second format line");
      format = std::string(w[1]);
      if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
        return Status::error(what + ": PLY header: unknown format '" + quote_token(w[1]) + "'");
    } else if (w[0] == "element") {
      if (w.size() != 3) return bad_header("malformed element line " + quoted_line());
      Element e;
      e.name = std::string(w[1]);
      e.header_line = line_no;
      if (!parse_uint(w[2], e.count))
        return Status::error(what + ": PLY header: element '" + quote_token(w[1]) + "' has a bad count '" +
                             quote_token(w[2]) + "'");
      for (const Element& other : elements)
        if (other.name == e.name) return bad_header("element '" + quote_token(w[1]) + "' declared twice");
      if (elements.size() >= 1024) return bad_header("more than 1024 elements");
      elements.push_back(std::move(e));
    } else if (w[0] == "property") {
      if (elements.empty()) return Status::error(what + ": PLY header: property before any element");
      Property p;
      if (w.size() >= 2 && w[1] == "list") {
        if (w.size() != 5) return bad_header("malformed list property " + quoted_line());
        p.is_list = true;
        p.count_type = parse_type(w[2]);
        p.type = parse_type(w[3]);
        p.name = std::string(w[4]);
        if (p.count_type == Type::none || p.type == Type::none) return bad_header("malformed list property " + quoted_line());
        if (is_real(p.count_type)) return bad_header("list property '" + quote_token(w[4]) + "' has a non-integer count type");
      } else {
        if (w.size() != 3) return bad_header("malformed property " + quoted_line());
        p.type = parse_type(w[1]);
        p.name = std::string(w[2]);
        if (p.type == Type::none) return bad_header("malformed property " + quoted_line());
      }
      Element& e = elements.back();
      if (e.properties.size() >= 1024) return bad_header("more than 1024 properties in element '" + quote_token(e.name) + "'");
      for (const Property& other : e.properties)
        if (other.name == p.name) return bad_header("property '" + quote_token(p.name) + "' declared twice");
      e.properties.push_back(std::move(p));
    } else if (w[0] == "end_header") {
      ended = true;
      break;
    } else {
      // Some exporters write a bare "Created by ..." line: ignore a line of unknown words,
      // but not one that hides a keyword (a broken line that lost its newline).
      for (size_t k = 1; k < w.size(); ++k)
        if (w[k] == "element" || w[k] == "property" || w[k] == "format" || w[k] == "end_header")
          return bad_header("unknown keyword '" + quote_token(w[0]) + "' before '" + std::string(w[k]) + "'");
    }
  }
  if (!ended) return Status::error(what + ": PLY header has no 'end_header' line (file truncated?)");
  if (format.empty()) return Status::error(what + ": PLY header has no 'format' line");

  // ---- what we read from which element ---------------------------------------------------
  Element* vertex = nullptr;
  Element* face = nullptr;
  bool has_tristrips = false;
  for (Element& e : elements) {
    if (e.name == "vertex") vertex = &e;
    if (e.name == "face") face = &e;
    if (e.name == "tristrips") has_tristrips = true;
  }
  if (!vertex) return Status::error(what + ": PLY header declares no 'vertex' element");
  const VertexGroups groups = assign_vertex_roles(what, *vertex, raw.warnings);
  {
    bool seen[3] = {false, false, false};
    for (const Property& p : vertex->properties)
      if (p.role >= Role::x && p.role <= Role::z) seen[slot(p.role)] = true;
    if (vertex->count > 0 && !(seen[0] && seen[1] && seen[2]))
      return Status::error(what + ": PLY element 'vertex' lacks an 'x', 'y' or 'z' property");
  }
  if (!face && has_tristrips)
    return Status::error(what + ": stores its triangles in a 'tristrips' element, which lodkit's PLY reader "
                         "does not read (convert it to a 'face' element)");
  if (!face || face->count == 0)
    return Status::error(what + ": has no faces (points only: " + std::to_string(vertex->count) + " vertices)");
  {
    bool has_indices = false;
    for (Property& p : face->properties)
      if (p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index") && !has_indices) {
        if (is_real(p.type))
          return Status::error(what + ": PLY property 'face' '" + p.name + "' has a non-integer index type");
        p.role = Role::indices;
        has_indices = true;
      }
    if (!has_indices) return Status::error(what + ": PLY element 'face' has no 'vertex_indices' list property");
  }
  if (vertex->count > std::numeric_limits<uint32_t>::max())
    return Status::error(what + ": declares " + std::to_string(vertex->count) + " vertices, more than 2^32-1");

  const bool ascii = format == "ascii";
  const bool big = format == "binary_big_endian";
  size_t at = pos;  // binary cursor
  TextTokens tokens(data, size, pos, line_no + 1, /*hash_comments=*/false);
  bool have_vertices = false, have_faces = false;

  for (Element& e : elements) {
    if (have_vertices && have_faces) break;  // what follows is not needed
    const bool is_vertex = &e == vertex;
    const bool is_face = &e == face;
    // Least bytes a row can take, to check the count before reading or reserving.
    size_t min_row = 0;
    for (const Property& p : e.properties)
      min_row += ascii ? 2 : (p.is_list ? type_size(p.count_type) : type_size(p.type));
    const size_t left = ascii ? tokens.remaining() : size - at;
    if (min_row == 0) {
      if (e.count == 0 || !(is_vertex || is_face)) continue;  // rows take no bytes
    } else if (e.count > (left + 1) / min_row) {
      return Status::error(what + ": truncated or corrupt: element '" + quote_token(e.name) + "' declares " +
                           std::to_string(e.count) + " rows, more than the " + std::to_string(left) +
                           " bytes after it can hold");
    }
    if (is_vertex) raw.positions.reserve(size_t(e.count) * 3);
    if (is_face) raw.offsets.reserve(size_t(e.count) + 1);
    const bool lists = std::any_of(e.properties.begin(), e.properties.end(), [](const Property& p) { return p.is_list; });
    if (!ascii && is_vertex && !lists && min_row > 0) {
      if (Status s = binary_vertex_rows(what, data, size, at, e, big, groups, raw); !s) return s;
      have_vertices = true;
      continue;
    }
    if (!ascii && is_face && e.properties.size() == 1 && e.properties[0].role == Role::indices) {
      if (Status s = binary_face_rows(what, data, size, at, e, big, raw); !s) return s;
      have_faces = true;
      continue;
    }
    auto truncated = [&](uint64_t i) {
      return Status::error(what + ": truncated: the data ends inside " + quote_token(e.name) + " " + std::to_string(i) +
                           " of " + std::to_string(e.count) + " declared");
    };
    for (uint64_t i = 0; i < e.count; ++i) {
      float xyz[3] = {0, 0, 0};
      double values[kSlots] = {};
      size_t row_line = tokens.line();
      for (const Property& p : e.properties) {
        if (ascii) {
          std::string_view tok;
          uint64_t n = 1;
          if (p.is_list) {
            if (!tokens.next(tok)) return truncated(i);
            int64_t c = 0;
            if (!parse_int(tok, c) || c < 0)
              return Status::error(what + ": " + quote_token(e.name) + " " + std::to_string(i) + " (line " +
                                   std::to_string(tokens.line()) + ") has a bad list length '" + quote_token(tok) + "'");
            n = uint64_t(c);
            if (n > (tokens.remaining() + 1) / 2) return truncated(i);
          }
          for (uint64_t k = 0; k < n; ++k) {
            if (!tokens.next(tok)) return truncated(i);
            if (k == 0) row_line = tokens.line();
            if (is_real(p.type)) {
              double v = 0;
              if (!parse_real(tok, v))
                return Status::error(what + ": " + quote_token(e.name) + " " + std::to_string(i) + " (line " +
                                     std::to_string(tokens.line()) + ") has a value that is not a number ('" +
                                     quote_token(tok) + "')");
              if (p.role >= Role::x && p.role <= Role::z) xyz[int(p.role) - int(Role::x)] = float(v);
              else if (is_vertex_role(p.role)) values[slot(p.role)] = v / p.scale;
            } else {
              int64_t v = 0;
              if (!parse_int(tok, v))
                return Status::error(what + ": " + quote_token(e.name) + " " + std::to_string(i) + " (line " +
                                     std::to_string(tokens.line()) + ") has a value that is not an integer ('" +
                                     quote_token(tok) + "')");
              if (p.role >= Role::x && p.role <= Role::z) xyz[int(p.role) - int(Role::x)] = float(v);
              else if (is_vertex_role(p.role)) values[slot(p.role)] = double(v) / p.scale;
              if (p.role == Role::indices) raw.corners.push_back(v);
            }
          }
        } else {
          if (!p.is_list) {
            const size_t s = type_size(p.type);
            if (size - at < s) return truncated(i);
            if (p.role >= Role::x && p.role <= Role::z) xyz[int(p.role) - int(Role::x)] = float(load_real(data + at, p.type, big));
            else if (is_vertex_role(p.role)) values[slot(p.role)] = load_real(data + at, p.type, big) / p.scale;
            at += s;
            continue;
          }
          const size_t cs = type_size(p.count_type), s = type_size(p.type);
          if (size - at < cs) return truncated(i);
          const int64_t c = load_int(data + at, p.count_type, big);
          at += cs;
          if (c < 0)
            return Status::error(what + ": " + quote_token(e.name) + " " + std::to_string(i) + " has a negative list length (" +
                                 std::to_string(c) + ")");
          if (uint64_t(c) > (size - at) / s) return truncated(i);
          if (p.role == Role::indices)
            for (int64_t k = 0; k < c; ++k) raw.corners.push_back(load_int(data + at + size_t(k) * s, p.type, big));
          at += size_t(c) * s;
        }
      }
      if (is_vertex) {
        for (int k = 0; k < 3; ++k)
          if (!std::isfinite(xyz[k]))
            return Status::error(what + ": vertex " + std::to_string(i) +
                                 (ascii ? " (line " + std::to_string(row_line) + ")" : std::string()) +
                                 " has a non-finite coordinate (" + describe_nonfinite(xyz[k]) + ")");
        raw.positions.insert(raw.positions.end(), xyz, xyz + 3);
        if (groups.any()) append_attributes(groups, values, raw);
      }
      if (is_face) {
        if (raw.corners.size() > std::numeric_limits<uint32_t>::max())
          return Status::error(what + ": more than 2^32-1 face corners");
        raw.offsets.push_back(uint32_t(raw.corners.size()));
      }
    }
    have_vertices |= is_vertex;
    have_faces |= is_face;
  }
  return Status::success();
}

}  // namespace lod::detail
