// Mesh loading through OpenMesh's readers into flat arrays.
//
// OpenMesh's readers feed a BaseImporter. Reading straight into a TriMesh would lose faces:
// its add_face refuses non-manifold faces (dragon/buddha scans have thousands) with only a
// line on omerr(). So FlatImporter records raw vertices and polygons, and everything is
// validated here afterwards. OpenMesh's readers also stop quietly at the end of a truncated
// file and trust header counts, so a cheap pre-check of each format's header runs first:
// it refuses files whose declared counts cannot fit in the file (no multi-gigabyte reserve,
// no endless loop) and gives the declared counts to compare with what was read.
#include "preprocess/mesh_io.h"

#include "preprocess/decimater_chain.h"  // detail::openmesh_global_mutex
#include "preprocess/openmesh_log_capture.h"

#include <OpenMesh/Core/IO/IOManager.hh>
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/IO/importer/BaseImporter.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <optional>
#include <sstream>
#include <string_view>

namespace lod {
namespace detail {
namespace {

namespace fs = std::filesystem;
using OpenMesh::FaceHandle;
using OpenMesh::HalfedgeHandle;
using OpenMesh::VertexHandle;

// Collects what a reader produces; never refuses anything (validation happens later, with
// element numbers in the message).
class FlatImporter final : public OpenMesh::IO::BaseImporter {
 public:
  std::vector<float> positions;
  std::vector<int> polygon_indices;      // raw handle indices, may be invalid
  std::vector<uint32_t> polygon_offsets{0};

  VertexHandle add_vertex(const OpenMesh::Vec3f& p) override {
    positions.insert(positions.end(), {p[0], p[1], p[2]});
    return VertexHandle(static_cast<int>(positions.size() / 3 - 1));
  }
  VertexHandle add_vertex(const OpenMesh::Vec3d& p) override {
    return add_vertex(OpenMesh::Vec3f(float(p[0]), float(p[1]), float(p[2])));
  }
  VertexHandle add_vertex() override { return add_vertex(OpenMesh::Vec3f(0, 0, 0)); }
  HalfedgeHandle add_edge(VertexHandle, VertexHandle) override { return HalfedgeHandle(); }
  FaceHandle add_face(const VHandles& handles) override {
    for (const VertexHandle& h : handles) polygon_indices.push_back(h.idx());
    polygon_offsets.push_back(static_cast<uint32_t>(polygon_indices.size()));
    return FaceHandle(static_cast<int>(polygon_offsets.size() - 2));
  }
  FaceHandle add_face(HalfedgeHandle) override { return FaceHandle(); }
  void set_point(VertexHandle vh, const OpenMesh::Vec3f& p) override {
    if (vh.idx() < 0 || size_t(vh.idx()) >= positions.size() / 3) return;
    std::copy(p.data(), p.data() + 3, positions.begin() + 3 * vh.idx());
  }
  // Attributes are not used by the LOD pipeline: accept and ignore.
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<OpenMesh::Vec2f>&) override {}
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<OpenMesh::Vec3f>&) override {}
  void set_face_texindex(FaceHandle, int) override {}
  void set_halfedge(VertexHandle, HalfedgeHandle) override {}
  void set_normal(VertexHandle, const OpenMesh::Vec3f&) override {}
  void set_normal(VertexHandle, const OpenMesh::Vec3d&) override {}
  void set_color(VertexHandle, const OpenMesh::Vec3uc&) override {}
  void set_color(VertexHandle, const OpenMesh::Vec4uc&) override {}
  void set_color(VertexHandle, const OpenMesh::Vec3f&) override {}
  void set_color(VertexHandle, const OpenMesh::Vec4f&) override {}
  void set_texcoord(VertexHandle, const OpenMesh::Vec2f&) override {}
  void set_status(VertexHandle, const OpenMesh::Attributes::StatusInfo&) override {}
  void set_next(HalfedgeHandle, HalfedgeHandle) override {}
  void set_face(HalfedgeHandle, FaceHandle) override {}
  void request_face_texcoords2D() override {}
  void set_texcoord(HalfedgeHandle, const OpenMesh::Vec2f&) override {}
  void set_texcoord(VertexHandle, const OpenMesh::Vec3f&) override {}
  void set_texcoord(HalfedgeHandle, const OpenMesh::Vec3f&) override {}
  void set_status(HalfedgeHandle, const OpenMesh::Attributes::StatusInfo&) override {}
  void set_color(OpenMesh::EdgeHandle, const OpenMesh::Vec3uc&) override {}
  void set_color(OpenMesh::EdgeHandle, const OpenMesh::Vec4uc&) override {}
  void set_color(OpenMesh::EdgeHandle, const OpenMesh::Vec3f&) override {}
  void set_color(OpenMesh::EdgeHandle, const OpenMesh::Vec4f&) override {}
  void set_status(OpenMesh::EdgeHandle, const OpenMesh::Attributes::StatusInfo&) override {}
  void set_normal(FaceHandle, const OpenMesh::Vec3f&) override {}
  void set_normal(FaceHandle, const OpenMesh::Vec3d&) override {}
  void set_color(FaceHandle, const OpenMesh::Vec3uc&) override {}
  void set_color(FaceHandle, const OpenMesh::Vec4uc&) override {}
  void set_color(FaceHandle, const OpenMesh::Vec3f&) override {}
  void set_color(FaceHandle, const OpenMesh::Vec4f&) override {}
  void set_status(FaceHandle, const OpenMesh::Attributes::StatusInfo&) override {}
  void add_texture_information(int, std::string) override {}

  // Header counts are untrusted: reserve only what the file could plausibly hold.
  void reserve(unsigned int nv, unsigned int, unsigned int nf) override {
    positions.reserve(3 * size_t(std::min(nv, reserve_cap)));
    polygon_offsets.reserve(size_t(std::min(nf, reserve_cap)) + 1);
  }
  size_t n_vertices() const override { return positions.size() / 3; }
  size_t n_faces() const override { return polygon_offsets.size() - 1; }
  size_t n_edges() const override { return 0; }

  unsigned int reserve_cap = 0;
};

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string describe_number(float v) {
  if (std::isnan(v)) return "nan";
  return v > 0 ? "inf" : "-inf";
}

// What a header pre-check learned. Counts are what the header declares.
struct Declared {
  std::optional<uint64_t> vertices;
  std::optional<uint64_t> faces;
};

// Reads the text tokens of an ASCII file, skipping '#' comments.
class TextTokens {
 public:
  explicit TextTokens(const std::vector<uint8_t>& bytes, size_t start = 0, size_t line = 1)
      : b_(bytes), i_(start), line_(line) {}
  bool next(std::string_view& tok) {
    for (;;) {
      while (i_ < b_.size() && std::isspace(b_[i_])) {
        if (b_[i_] == '\n') ++line_;
        ++i_;
      }
      if (i_ < b_.size() && b_[i_] == '#') {
        while (i_ < b_.size() && b_[i_] != '\n') ++i_;
        continue;
      }
      break;
    }
    if (i_ >= b_.size()) return false;
    const size_t start = i_;
    while (i_ < b_.size() && !std::isspace(b_[i_]) && b_[i_] != '#') ++i_;
    tok = std::string_view(reinterpret_cast<const char*>(b_.data()) + start, i_ - start);
    return true;
  }
  // Moves past the end of the current line (extra per-element values such as colours).
  void skip_line() {
    while (i_ < b_.size() && b_[i_] != '\n') ++i_;
  }
  size_t line() const { return line_; }
  size_t offset() const { return i_; }

 private:
  const std::vector<uint8_t>& b_;
  size_t i_;
  size_t line_;
};

bool parse_count(std::string_view tok, uint64_t& out) {
  if (tok.empty() || tok.size() > 19) return false;
  uint64_t v = 0;
  for (char c : tok) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + uint64_t(c - '0');
  }
  out = v;
  return true;
}

// A coordinate token as strtod sees it (accepts nan/inf, which iostreams refuse silently).
// The whole token must be the number: iostreams would stop inside "2-1" and read the rest
// as the next value, shifting everything after it.
bool parse_coordinate(std::string_view tok, float& out) {
  std::string s(tok);
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end == s.c_str() || *end != 0) return false;
  out = static_cast<float>(v);
  return true;
}

// An integer token, optionally negative, nothing else.
bool is_integer_token(std::string_view tok) {
  if (!tok.empty() && tok[0] == '-') tok.remove_prefix(1);
  if (tok.empty() || tok.size() > 20) return false;
  for (char c : tok)
    if (c < '0' || c > '9') return false;
  return true;
}

Status check_coordinates(const std::string& what, uint64_t vertex, size_t line, const float* xyz, int n) {
  for (int k = 0; k < n; ++k)
    if (!std::isfinite(xyz[k]))
      return Status::error(what + ": vertex " + std::to_string(vertex) + " (line " + std::to_string(line) +
                           ") has a non-finite coordinate (" + describe_number(xyz[k]) + ")");
  return Status::success();
}

// ---- PLY -------------------------------------------------------------------------------

struct PlyProperty {
  std::string name;
  int size = 0;          // scalar size in bytes, 0 if unknown type
  bool is_list = false;
  int count_size = 0;    // list count type size
  bool count_signed = false;
  bool is_float = false; // value type
};
struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

int ply_type_size(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "int32" || t == "uint32" || t == "float" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

bool is_float_type(const std::string& t) {
  return t == "float" || t == "float32" || t == "double" || t == "float64";
}

uint64_t read_uint_le(const uint8_t* p, int size, bool big_endian) {
  uint64_t v = 0;
  for (int i = 0; i < size; ++i) {
    const int shift = big_endian ? 8 * (size - 1 - i) : 8 * i;
    v |= uint64_t(p[i]) << shift;
  }
  return v;
}

Status precheck_ply(const std::string& what, const std::vector<uint8_t>& bytes, Declared& declared) {
  // Header: text lines up to "end_header".
  size_t pos = 0;
  auto next_line = [&](std::string& line) {
    if (pos >= bytes.size()) return false;
    size_t end = pos;
    while (end < bytes.size() && bytes[end] != '\n') ++end;
    line.assign(reinterpret_cast<const char*>(bytes.data()) + pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    pos = std::min(end + 1, bytes.size());
    return true;
  };
  std::string line;
  if (!next_line(line) || line != "ply") return Status::error(what + ": not a PLY file (first line is not 'ply')");
  std::string format;
  std::vector<PlyElement> elements;
  bool ended = false;
  size_t header_line = 1;
  // OpenMesh's header parser can loop forever on a malformed header, so anything it might
  // not understand is refused here, naming the line.
  auto bad_header = [&](const std::string& why) {
    return Status::error(what + ": PLY header line " + std::to_string(header_line) + ": " + why);
  };
  while (next_line(line)) {
    ++header_line;
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (word.empty() || word == "comment" || word == "obj_info") continue;
    if (word == "format") {
      std::string version, extra;
      ls >> format >> version >> extra;
      char* end = nullptr;
      std::strtod(version.c_str(), &end);
      if (version.empty() || *end != 0 || !extra.empty())
        return bad_header("malformed format line '" + line.substr(0, 80) + "'");
    } else if (word == "element") {
      PlyElement e;
      std::string count_text, extra;
      ls >> e.name >> count_text >> extra;
      if (e.name.empty() || !extra.empty()) return bad_header("malformed element line '" + line.substr(0, 80) + "'");
      char* end = nullptr;
      errno = 0;
      const unsigned long long n = std::strtoull(count_text.c_str(), &end, 10);
      if (count_text.empty() || *end != 0 || errno != 0 || count_text[0] == '-')
        return Status::error(what + ": PLY header: element '" + e.name + "' has a bad count '" + count_text + "'");
      e.count = n;
      elements.push_back(e);
    } else if (word == "property") {
      if (elements.empty()) return Status::error(what + ": PLY header: property before any element");
      PlyProperty p;
      std::string type;
      ls >> type;
      std::string extra;
      if (type == "list") {
        std::string count_type, value_type;
        ls >> count_type >> value_type >> p.name >> extra;
        p.is_list = true;
        p.count_size = ply_type_size(count_type);
        p.count_signed = count_type == "char" || count_type == "int8" || count_type == "short" ||
                         count_type == "int16" || count_type == "int" || count_type == "int32";
        p.size = ply_type_size(value_type);
        p.is_float = is_float_type(value_type);
        if (p.count_size == 0 || p.size == 0 || p.name.empty() || !extra.empty())
          return bad_header("malformed list property '" + line.substr(0, 80) + "'");
        if (p.count_size > 4 || p.size > 4)
          return bad_header("list property '" + p.name + "' has a non-integer type");
      } else {
        ls >> p.name >> extra;
        p.size = ply_type_size(type);
        p.is_float = is_float_type(type);
        if (p.size == 0 || p.name.empty() || !extra.empty())
          return bad_header("malformed property '" + line.substr(0, 80) + "'");
      }
      elements.back().properties.push_back(p);
    } else if (word == "end_header") {
      ended = true;
      break;
    } else {
      // OpenMesh skips unknown words one by one (some exporters write a bare "Created by
      // ..." line); it would act on a keyword further along the line, so refuse those.
      std::string rest;
      while (ls >> rest)
        if (rest == "element" || rest == "property" || rest == "format" || rest == "end_header")
          return bad_header("unknown keyword '" + word.substr(0, 32) + "' before '" + rest + "'");
    }
  }
  if (!ended) return Status::error(what + ": PLY header has no 'end_header' line (file truncated?)");

  bool has_face = false;
  bool has_tristrips = false;
  for (const PlyElement& e : elements) {
    if (e.name == "vertex") declared.vertices = e.count;
    if (e.name == "face") {
      declared.faces = e.count;
      has_face = true;
      bool has_indices = false;
      for (const PlyProperty& p : e.properties)
        has_indices |= p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index");
      if (!has_indices)
        return Status::error(what + ": PLY element 'face' has no 'vertex_indices' list property");
    }
    if (e.name == "tristrips") has_tristrips = true;
  }
  if (!declared.vertices) return Status::error(what + ": PLY header declares no 'vertex' element");
  if (!has_face && has_tristrips)
    return Status::error(what + ": stores its triangles in a 'tristrips' element, which OpenMesh's PLY reader "
                         "does not read (convert it to a 'face' element)");
  if (!has_face || *declared.faces == 0)
    return Status::error(what + ": has no faces (points only: " + std::to_string(*declared.vertices) +
                         " vertices)");

  const bool binary = format == "binary_little_endian" || format == "binary_big_endian";
  if (!binary && format != "ascii")
    return Status::error(what + ": PLY header: unknown format '" + format + "'");
  if (!binary) {
    // Walk the values as text: iostreams stop silently at "nan" or at the end of a
    // truncated file (repeating the last face), so check counts and coordinates here.
    size_t header_lines = 1;
    for (size_t i = 0; i < pos; ++i) header_lines += bytes[i] == '\n';
    TextTokens tokens(bytes, pos, header_lines);
    std::string_view tok;
    for (const PlyElement& e : elements) {
      const bool is_vertex = e.name == "vertex";
      for (uint64_t i = 0; i < e.count; ++i) {
        float xyz[3] = {0, 0, 0};
        for (const PlyProperty& p : e.properties) {
          uint64_t values = 1;
          if (p.is_list) {
            if (!tokens.next(tok))
              return Status::error(what + ": truncated: the data ends inside " + e.name + " " + std::to_string(i) +
                                   " of " + std::to_string(e.count) + " declared");
            if (!parse_count(tok, values))
              return Status::error(what + ": " + e.name + " " + std::to_string(i) + " (line " +
                                   std::to_string(tokens.line()) + ") has a bad list length '" +
                                   std::string(tok.substr(0, 32)) + "'");
          }
          for (uint64_t k = 0; k < values; ++k) {
            if (!tokens.next(tok))
              return Status::error(what + ": truncated: the data ends inside " + e.name + " " + std::to_string(i) +
                                   " of " + std::to_string(e.count) + " declared");
            float value = 0;
            if (p.is_float ? !parse_coordinate(tok, value) : !is_integer_token(tok))
              return Status::error(what + ": " + e.name + " " + std::to_string(i) + " (line " +
                                   std::to_string(tokens.line()) + ") has a value that is not " +
                                   (p.is_float ? "a number" : "an integer") + " ('" +
                                   std::string(tok.substr(0, 32)) + "')");
            if (is_vertex && !p.is_list && p.name.size() == 1 && p.name[0] >= 'x' && p.name[0] <= 'z')
              xyz[p.name[0] - 'x'] = p.is_float ? value : float(std::strtod(std::string(tok).c_str(), nullptr));
          }
        }
        if (is_vertex) {
          Status st = check_coordinates(what, i, tokens.line(), xyz, 3);
          if (!st) return st;
        }
      }
      if (e.name == "face") break;
    }
    return Status::success();
  }

  // Binary: walk every element up to and including the faces, so that a truncated file or
  // an absurd list length is refused here rather than inside OpenMesh.
  const bool big_endian = format == "binary_big_endian";
  size_t at = pos;
  for (const PlyElement& e : elements) {
    for (const PlyProperty& p : e.properties)
      if (p.size == 0 || (p.is_list && p.count_size == 0))
        return Status::error(what + ": PLY header: property '" + p.name + "' of element '" + e.name +
                             "' has an unknown type");
    bool all_scalar = true;
    size_t row = 0;
    for (const PlyProperty& p : e.properties) {
      if (p.is_list) all_scalar = false;
      row += size_t(p.size);
    }
    auto truncated = [&](uint64_t index) {
      return Status::error(what + ": truncated: the data ends inside " + e.name + " " + std::to_string(index) +
                           " of " + std::to_string(e.count) + " declared");
    };
    if (all_scalar) {
      if (row != 0 && e.count > (bytes.size() - at) / row) return truncated((bytes.size() - at) / row);
      at += size_t(e.count) * row;
    } else {
      for (uint64_t i = 0; i < e.count; ++i) {
        for (const PlyProperty& p : e.properties) {
          if (!p.is_list) {
            if (bytes.size() - at < size_t(p.size)) return truncated(i);
            at += size_t(p.size);
            continue;
          }
          if (bytes.size() - at < size_t(p.count_size)) return truncated(i);
          uint64_t n = read_uint_le(&bytes[at], p.count_size, big_endian);
          if (p.count_signed && (n >> (8 * p.count_size - 1)) != 0)
            return Status::error(what + ": " + e.name + " " + std::to_string(i) + " has a negative list length");
          at += size_t(p.count_size);
          if (n > (bytes.size() - at) / size_t(p.size)) return truncated(i);
          at += size_t(n) * size_t(p.size);
        }
      }
    }
    if (e.name == "face") break;
  }
  return Status::success();
}

// ---- OFF -------------------------------------------------------------------------------

Status precheck_off(const std::string& what, const std::vector<uint8_t>& bytes, Declared& declared) {
  TextTokens tokens(bytes);
  std::string_view tok;
  if (!tokens.next(tok)) return Status::error(what + ": file is empty");
  std::string magic(tok);
  if (magic.find("OFF") == std::string::npos)
    return Status::error(what + ": not an OFF file (first word is '" + magic.substr(0, 32) + "')");
  const bool binary = magic.find("BINARY") != std::string::npos;
  if (!binary && tokens.next(tok) && tok == "BINARY")
    return Status::error(what + ": binary OFF is not supported");
  if (binary) return Status::error(what + ": binary OFF is not supported");
  if (magic.find("n") == 0) return Status::error(what + ": OFF with a vertex dimension ('nOFF') is not supported");
  uint64_t nv = 0, nf = 0;
  // The counts follow the magic word (OpenMesh takes the same three numbers).
  TextTokens t2(bytes);
  t2.next(tok);
  std::string_view a, b;
  if (!t2.next(a) || !t2.next(b) || !parse_count(a, nv) || !parse_count(b, nf))
    return Status::error(what + ": OFF header has no vertex and face counts");
  {
    // An edge count may follow on the same line; otherwise the next token is a coordinate.
    TextTokens peek = t2;
    std::string_view edges_tok;
    const size_t counts_line = t2.line();
    if (peek.next(edges_tok) && peek.line() == counts_line) t2.next(edges_tok);
  }
  declared.vertices = nv;
  declared.faces = nf;
  const size_t size = bytes.size();
  // An ASCII vertex needs at least 6 characters ("0 0 0\n"), a triangle 8 ("3 0 1 2\n").
  if (nv > size / 6 || nf > size / 8 || nv * 6 + nf * 8 > size + 16)
    return Status::error(what + ": truncated or corrupt: the header declares " + std::to_string(nv) +
                         " vertices and " + std::to_string(nf) + " faces, more than " + std::to_string(size) +
                         " bytes can hold");
  if (nf == 0) return Status::error(what + ": has no faces (points only: " + std::to_string(nv) + " vertices)");
  // Check coordinates and counts as text: iostreams stop silently at 'nan' (losing every
  // later value) and at the end of a truncated file (repeating the last face). Colours and
  // normals may follow xyz or a face's indices on the same line.
  for (uint64_t v = 0; v < nv; ++v) {
    float xyz[3];
    for (int k = 0; k < 3; ++k) {
      if (!t2.next(tok))
        return Status::error(what + ": truncated: the data ends inside vertex " + std::to_string(v) + " of " +
                             std::to_string(nv) + " declared");
      if (!parse_coordinate(tok, xyz[k]))
        return Status::error(what + ": vertex " + std::to_string(v) + " (line " + std::to_string(t2.line()) +
                             ") has a coordinate that is not a number ('" + std::string(tok.substr(0, 32)) + "')");
    }
    Status s = check_coordinates(what, v, t2.line(), xyz, 3);
    if (!s) return s;
    t2.skip_line();
  }
  for (uint64_t f = 0; f < nf; ++f) {
    uint64_t n = 0;
    if (!t2.next(tok))
      return Status::error(what + ": truncated: the data ends before face " + std::to_string(f) + " of " +
                           std::to_string(nf) + " declared");
    if (!parse_count(tok, n))
      return Status::error(what + ": face " + std::to_string(f) + " (line " + std::to_string(t2.line()) +
                           ") has a bad corner count '" + std::string(tok.substr(0, 32)) + "'");
    for (uint64_t k = 0; k < n; ++k) {
      if (!t2.next(tok))
        return Status::error(what + ": truncated: the data ends inside face " + std::to_string(f) + " of " +
                             std::to_string(nf) + " declared");
      if (!is_integer_token(tok))
        return Status::error(what + ": face " + std::to_string(f) + " (line " + std::to_string(t2.line()) +
                             ") has a vertex index that is not an integer ('" + std::string(tok.substr(0, 32)) + "')");
    }
    t2.skip_line();
  }
  return Status::success();
}

// ---- OBJ -------------------------------------------------------------------------------

// OpenMesh's OBJ reader drops a 'v' line it cannot parse (e.g. "v nan 0 0"), which shifts
// every later index; find such lines first and name them.
Status precheck_obj(const std::string& what, const std::vector<uint8_t>& bytes) {
  if (bytes.size() >= 2 && ((bytes[0] == 0xFE && bytes[1] == 0xFF) || (bytes[0] == 0xFF && bytes[1] == 0xFE)))
    return Status::error(what + ": is UTF-16 text; OBJ files must be ASCII or UTF-8");
  size_t pos = 0, line_no = 0;
  uint64_t vertex = 0, faces = 0;
  std::string line;
  while (pos < bytes.size()) {
    size_t end = pos;
    while (end < bytes.size() && bytes[end] != '\n') ++end;
    ++line_no;
    line.assign(reinterpret_cast<const char*>(bytes.data()) + pos, end - pos);
    pos = end + 1;
    size_t s = 0;
    while (s < line.size() && (line[s] == ' ' || line[s] == '\t')) ++s;
    if (line.compare(s, 2, "f ") == 0 || line.compare(s, 2, "f\t") == 0) {
      // Every corner must start with a vertex index: OpenMesh's reader asserts (aborts the
      // process) on a corner like "/1/1".
      std::istringstream corners(line.substr(s + 2));
      std::string corner;
      while (corners >> corner) {
        const size_t slash = corner.find('/');
        const std::string index = corner.substr(0, slash);
        char* e = nullptr;
        const long v = std::strtol(index.c_str(), &e, 10);
        if (index.empty() || *e != 0 || v == 0)
          return Status::error(what + ": face " + std::to_string(faces) + " (line " + std::to_string(line_no) +
                               ") has a corner without a valid vertex index ('" + corner.substr(0, 32) + "')");
      }
      ++faces;
    }
    if (!(line.compare(s, 2, "v ") == 0 || line.compare(s, 2, "v\t") == 0)) continue;
    const char* p = line.c_str() + s + 2;
    float xyz[3];
    for (int k = 0; k < 3; ++k) {
      char* e = nullptr;
      const double d = std::strtod(p, &e);
      if (e == p)
        return Status::error(what + ": vertex " + std::to_string(vertex) + " (line " + std::to_string(line_no) +
                             ") does not have three numeric coordinates");
      xyz[k] = static_cast<float>(d);
      p = e;
    }
    Status st = check_coordinates(what, vertex, line_no, xyz, 3);
    if (!st) return st;
    ++vertex;
  }
  if (faces == 0) return Status::error(what + ": has no faces (points only: " + std::to_string(vertex) + " vertices)");
  return Status::success();
}

// ---- STL -------------------------------------------------------------------------------

Status precheck_stl(const std::string& what, const std::vector<uint8_t>& bytes, Declared& declared) {
  // Binary STL may also start with "solid"; the size formula decides, as OpenMesh does.
  const uint64_t n = bytes.size() >= 84 ? read_uint_le(&bytes[80], 4, false) : 0;
  const bool sized_as_binary = bytes.size() >= 84 && 84 + 50 * n == bytes.size();
  if (!sized_as_binary && bytes.size() >= 5 && std::memcmp(bytes.data(), "solid", 5) == 0) return Status::success();
  if (bytes.size() < 84)
    return Status::error(what + ": truncated binary STL (" + std::to_string(bytes.size()) +
                         " bytes; the header alone is 84)");
  declared.faces = n;
  if (n == 0) return Status::error(what + ": has no faces (binary STL declares 0 triangles)");
  if (84 + 50 * n > bytes.size())
    return Status::error(what + ": truncated: binary STL declares " + std::to_string(n) + " triangles (" +
                         std::to_string(84 + 50 * n) + " bytes) but the file has " + std::to_string(bytes.size()) +
                         " bytes");
  for (uint64_t t = 0; t < n; ++t) {
    float xyz[9];
    std::memcpy(xyz, &bytes[84 + 50 * t + 12], sizeof xyz);
    for (float v : xyz)
      if (!std::isfinite(v))
        return Status::error(what + ": triangle " + std::to_string(t) + " has a non-finite coordinate (" +
                             describe_number(v) + ")");
  }
  return Status::success();
}

}  // namespace
}  // namespace detail

Status load_mesh(const std::filesystem::path& path, MeshData& out) {
  using namespace detail;
  const std::string what = path.string();
  std::error_code ec;
  if (!fs::exists(path, ec)) return Status::error(what + ": no such file");
  if (!fs::is_regular_file(path, ec)) return Status::error(what + ": not a regular file");
  const std::string ext = lower(path.extension().string());
  if (ext == ".gz" || ext == ".zip" || ext == ".bz2" || ext == ".xz")
    return Status::error(what + ": is compressed ('" + path.extension().string() +
                         "'); decompress it first (.obj, .ply, .off or .stl)");
  if (ext != ".obj" && ext != ".ply" && ext != ".off" && ext != ".stl")
    return Status::error(what + ": unknown mesh format '" + path.extension().string() +
                         "' (expected .obj, .ply, .off or .stl)");

  std::vector<uint8_t> bytes;
  {
    std::ifstream f(path, std::ios::binary);
    if (!f) return Status::error(what + ": cannot be opened for reading");
    bytes.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
    if (f.bad()) return Status::error(what + ": read error");
  }
  if (bytes.empty()) return Status::error(what + ": file is empty");

  Declared declared;
  Status pre;
  if (ext == ".ply") pre = precheck_ply(what, bytes, declared);
  else if (ext == ".off") pre = precheck_off(what, bytes, declared);
  else if (ext == ".obj") pre = precheck_obj(what, bytes);
  else pre = precheck_stl(what, bytes, declared);
  if (!pre) return pre;

  FlatImporter importer;
  // Nothing legitimate needs more elements than the file has bytes.
  importer.reserve_cap = static_cast<unsigned int>(std::min<size_t>(bytes.size(), 1u << 30));
  bytes.clear();
  bytes.shrink_to_fit();

  bool read_ok = false;
  std::string said;
  {
    // OpenMesh's readers are singletons with per-read state: one read at a time. What they
    // say on omerr()/omlog() goes into the message, not onto the host's terminal.
    std::lock_guard<std::mutex> lock(openmesh_global_mutex());
    OpenMeshLogCapture capture;
    OpenMesh::IO::Options options = OpenMesh::IO::Options::Default;
    try {
      read_ok = OpenMesh::IO::IOManager().read(path.string(), importer, options);
    } catch (const std::exception& e) {
      read_ok = false;
      ::omerr() << "exception: " << e.what();
    }
    said = capture.text();
  }
  const std::string openmesh_said = said.empty() ? "" : " (OpenMesh: " + said + ")";
  if (!read_ok) return Status::error(what + ": OpenMesh could not read it" + openmesh_said);

  const size_t nv = importer.n_vertices();
  const size_t nf = importer.n_faces();
  if (declared.vertices && nv < *declared.vertices)
    return Status::error(what + ": truncated: read " + std::to_string(nv) + " of " +
                         std::to_string(*declared.vertices) + " declared vertices" + openmesh_said);
  if (declared.faces && nf < *declared.faces && ext != ".stl")
    return Status::error(what + ": truncated: read " + std::to_string(nf) + " of " + std::to_string(*declared.faces) +
                         " declared faces" + openmesh_said);
  if (nf == 0) return Status::error(what + ": has no faces (points only: " + std::to_string(nv) + " vertices)" + openmesh_said);

  for (size_t v = 0; v < nv; ++v)
    for (int k = 0; k < 3; ++k) {
      const float c = importer.positions[3 * v + k];
      if (!std::isfinite(c))
        return Status::error(what + ": vertex " + std::to_string(v) + " has a non-finite coordinate (" +
                             describe_number(c) + ")");
    }

  MeshData mesh;
  mesh.source = what;
  mesh.indices.reserve(3 * nf);
  for (size_t f = 0; f < nf; ++f) {
    const uint32_t begin = importer.polygon_offsets[f], end = importer.polygon_offsets[f + 1];
    for (uint32_t i = begin; i < end; ++i) {
      const int idx = importer.polygon_indices[i];
      if (idx < 0 || size_t(idx) >= nv) {
        // OBJ numbers its vertices from 1: name the vertex as the file wrote it.
        const bool obj = ext == ".obj";
        const std::string number = idx < 0 ? std::string("-1 (invalid)") : std::to_string(obj ? idx + 1 : idx);
        return Status::error(what + ": face " + std::to_string(f) + " references vertex " + number + " of " +
                             std::to_string(nv) + (obj && idx >= 0 ? " (OBJ numbering, from 1)" : "") +
                             openmesh_said);
      }
    }
    // Fan triangulation; a polygon with fewer than 3 corners contributes nothing.
    for (uint32_t i = begin + 1; i + 1 < end; ++i)
      mesh.indices.insert(mesh.indices.end(), {uint32_t(importer.polygon_indices[begin]),
                                               uint32_t(importer.polygon_indices[i]),
                                               uint32_t(importer.polygon_indices[i + 1])});
  }
  if (mesh.indices.empty())
    return Status::error(what + ": has no triangles (" + std::to_string(nf) + " faces with fewer than 3 corners)");
  mesh.positions = std::move(importer.positions);
  out = std::move(mesh);
  return Status::success();
}

Status save_ply(const std::filesystem::path& path, const float* positions, size_t vertex_count,
                const uint32_t* indices, size_t index_count) {
  const std::string what = path.string();
  if (index_count % 3 != 0) return Status::error(what + ": index count " + std::to_string(index_count) + " is not a multiple of 3");
  for (size_t i = 0; i < index_count; ++i)
    if (indices[i] >= vertex_count)
      return Status::error(what + ": triangle " + std::to_string(i / 3) + " references vertex " +
                           std::to_string(indices[i]) + " of " + std::to_string(vertex_count));
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (!f) return Status::error(what + ": cannot be opened for writing");
  f << "ply\nformat binary_little_endian 1.0\ncomment lodkit\nelement vertex " << vertex_count
    << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << index_count / 3
    << "\nproperty list uchar int vertex_indices\nend_header\n";
  static_assert(std::endian::native == std::endian::little, "save_ply writes host-order floats");
  f.write(reinterpret_cast<const char*>(positions), std::streamsize(vertex_count * 3 * sizeof(float)));
  std::vector<char> face(13);
  face[0] = 3;
  for (size_t t = 0; t < index_count / 3; ++t) {
    std::memcpy(&face[1], indices + 3 * t, 12);
    f.write(face.data(), 13);
  }
  f.flush();
  if (!f) return Status::error(what + ": write failed (disk full?)");
  return Status::success();
}

}  // namespace lod
