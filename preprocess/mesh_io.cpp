// Mesh loading: the file is read once into memory (a regular file only, opened so that a FIFO
// or device never blocks), then parsed by the reader for its extension. PLY, OFF and STL have
// single-pass readers of our own (ply_reader.cpp, off_reader.cpp, stl_reader.cpp): OpenMesh's
// PLY header parser loops forever on some unknown words and its PLY/OFF readers reserve
// whatever a header declares. OBJ still goes through OpenMesh's reader, fed from the bytes
// in memory after a pre-check that refuses everything it mishandles (unparsable 'v' lines it
// would drop, corners it asserts on, indices out of range) with the file's own numbers.
//
// OpenMesh's reader feeds a BaseImporter. Reading straight into a TriMesh would lose faces:
// its add_face refuses non-manifold faces (dragon/buddha scans have thousands) with only a
// line on omerr(). So FlatImporter records raw vertices and polygons.
#include "preprocess/mesh_io.h"

#include "preprocess/decimater_chain.h"  // detail::openmesh_global_mutex
#include "preprocess/mesh_readers.h"
#include "preprocess/openmesh_log_capture.h"

#include <OpenMesh/Core/IO/IOManager.hh>
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/IO/importer/BaseImporter.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <mutex>
#include <new>
#include <sstream>
#include <string_view>

namespace lod {
namespace detail {

// ---- shared helpers (mesh_readers.h) -----------------------------------------------------

std::string quote_token(std::string_view tok) {
  std::string s(tok.substr(0, 32));
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7F) c = '?';
  return s;
}

namespace {
bool is_space(uint8_t c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }
}  // namespace

bool TextTokens::next(std::string_view& tok) {
  for (;;) {
    while (i_ < n_ && is_space(d_[i_])) {
      if (d_[i_] == '\n') ++line_;
      ++i_;
    }
    if (comments_ && i_ < n_ && d_[i_] == '#') {
      while (i_ < n_ && d_[i_] != '\n') ++i_;
      continue;
    }
    break;
  }
  if (i_ >= n_) return false;
  const size_t start = i_;
  while (i_ < n_ && !is_space(d_[i_]) && !(comments_ && d_[i_] == '#')) ++i_;
  tok = std::string_view(reinterpret_cast<const char*>(d_) + start, i_ - start);
  return true;
}

void TextTokens::skip_line() {
  while (i_ < n_ && d_[i_] != '\n') ++i_;
  if (i_ < n_) {
    ++i_;
    ++line_;
  }
}

bool TextTokens::more_on_line() const {
  size_t i = i_;
  while (i < n_ && d_[i] != '\n' && is_space(d_[i])) ++i;
  return i < n_ && d_[i] != '\n' && !(comments_ && d_[i] == '#');
}

bool parse_uint(std::string_view tok, uint64_t& out) {
  if (tok.empty() || tok[0] < '0' || tok[0] > '9') return false;
  const auto r = std::from_chars(tok.data(), tok.data() + tok.size(), out);
  return r.ec == std::errc() && r.ptr == tok.data() + tok.size();
}

bool parse_int(std::string_view tok, int64_t& out) {
  if (tok.empty()) return false;
  const auto r = std::from_chars(tok.data(), tok.data() + tok.size(), out);
  return r.ec == std::errc() && r.ptr == tok.data() + tok.size();
}

bool parse_real(std::string_view tok, double& out) {
  if (tok.empty() || tok.size() > 64) return false;
  char buf[65];
  std::memcpy(buf, tok.data(), tok.size());
  buf[tok.size()] = 0;
  char* end = nullptr;
  out = std::strtod(buf, &end);
  return end == buf + tok.size();
}

Status finish_polygons(const std::string& what, RawPolygons& raw, MeshData& out, bool obj_numbering) {
  const size_t nv = raw.vertex_count();
  const size_t nf = raw.polygon_count();
  if (nf == 0) return Status::error(what + ": has no faces (points only: " + std::to_string(nv) + " vertices)");
  size_t triangles = 0;
  for (size_t f = 0; f < nf; ++f) {
    const uint32_t begin = raw.offsets[f], end = raw.offsets[f + 1];
    for (uint32_t i = begin; i < end; ++i) {
      const int64_t idx = raw.corners[i];
      if (idx < 0 || uint64_t(idx) >= nv) {
        const std::string number = obj_numbering ? (idx < 0 ? std::string("-1 (invalid)") : std::to_string(idx + 1))
                                                 : std::to_string(idx);
        return Status::error(what + ": face " + std::to_string(f) + " references vertex " + number + " of " +
                             std::to_string(nv) + (obj_numbering && idx >= 0 ? " (OBJ numbering, from 1)" : ""));
      }
    }
    if (end - begin >= 3) triangles += end - begin - 2;
  }
  if (triangles == 0)
    return Status::error(what + ": has no triangles (" + std::to_string(nf) + " faces with fewer than 3 corners)");
  MeshData mesh;
  mesh.source = what;
  mesh.indices.reserve(3 * triangles);
  for (size_t f = 0; f < nf; ++f) {
    const uint32_t begin = raw.offsets[f], end = raw.offsets[f + 1];
    // Fan triangulation; a polygon with fewer than 3 corners contributes nothing.
    for (uint32_t i = begin + 1; i + 1 < end; ++i)
      mesh.indices.insert(mesh.indices.end(), {uint32_t(raw.corners[begin]), uint32_t(raw.corners[i]),
                                               uint32_t(raw.corners[i + 1])});
  }
  mesh.positions = std::move(raw.positions);
  out = std::move(mesh);
  return Status::success();
}

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

// ---- OBJ -------------------------------------------------------------------------------

// OpenMesh's OBJ reader drops a 'v' line it cannot parse (e.g. "v nan 0 0"), which shifts
// every later index, asserts on a corner without a vertex index, and turns an index out of
// range into whatever handle arithmetic gives; find such lines first and name them with the
// file's own numbers (OBJ numbers vertices from 1; -1 is the last vertex before the face).
Status precheck_obj(const std::string& what, const uint8_t* data, size_t size) {
  if (size >= 2 && ((data[0] == 0xFE && data[1] == 0xFF) || (data[0] == 0xFF && data[1] == 0xFE)))
    return Status::error(what + ": is UTF-16 text; OBJ files must be ASCII or UTF-8");
  auto is_v = [](std::string_view line, size_t s) {
    return line.size() >= s + 2 && line[s] == 'v' && (line[s + 1] == ' ' || line[s + 1] == '\t');
  };
  auto is_f = [](std::string_view line, size_t s) {
    return line.size() >= s + 2 && line[s] == 'f' && (line[s + 1] == ' ' || line[s + 1] == '\t');
  };
  auto lines = [&](auto&& visit) -> Status {
    size_t pos = 0, line_no = 0;
    while (pos < size) {
      const void* nl = std::memchr(data + pos, '\n', size - pos);
      const size_t end = nl ? size_t(static_cast<const uint8_t*>(nl) - data) : size;
      ++line_no;
      std::string_view line(reinterpret_cast<const char*>(data) + pos, end - pos);
      pos = end + 1;
      size_t s = 0;
      while (s < line.size() && (line[s] == ' ' || line[s] == '\t')) ++s;
      Status st = visit(line, s, line_no);
      if (!st) return st;
    }
    return Status::success();
  };
  // Pass 1 (in memory): how many vertices, so that a forward reference can be checked.
  uint64_t total = 0;
  (void)lines([&](std::string_view line, size_t s, size_t) {
    total += is_v(line, s);
    return Status::success();
  });
  uint64_t vertex = 0, faces = 0;
  std::string buf;
  Status st = lines([&](std::string_view line, size_t s, size_t line_no) -> Status {
    if (is_f(line, s)) {
      // Every corner must start with a vertex index: OpenMesh's reader asserts (aborts the
      // process) on a corner like "/1/1".
      TextTokens corners(reinterpret_cast<const uint8_t*>(line.data()), line.size(), s + 2, line_no, false);
      std::string_view corner;
      while (corners.next(corner)) {
        const std::string_view index = corner.substr(0, corner.find('/'));
        int64_t v = 0;
        if (!parse_int(index, v) || v == 0)
          return Status::error(what + ": face " + std::to_string(faces) + " (line " + std::to_string(line_no) +
                               ") has a corner without a valid vertex index ('" + quote_token(corner) + "')");
        if (v < 0 && uint64_t(-(v + 1)) >= vertex)
          return Status::error(what + ": face " + std::to_string(faces) + " references vertex " + std::to_string(v) +
                               " (relative) of " + std::to_string(vertex) + " before it, on line " +
                               std::to_string(line_no));
        if (v > 0 && (uint64_t(v) > total || v > std::numeric_limits<int>::max()))
          return Status::error(what + ": face " + std::to_string(faces) + " references vertex " + std::to_string(v) +
                               " of " + std::to_string(total) + " (OBJ numbering, from 1), on line " +
                               std::to_string(line_no));
      }
      ++faces;
      return Status::success();
    }
    if (!is_v(line, s)) return Status::success();
    buf.assign(line.substr(s + 2));
    const char* p = buf.c_str();
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
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(xyz[k]))
        return Status::error(what + ": vertex " + std::to_string(vertex) + " (line " + std::to_string(line_no) +
                             ") has a non-finite coordinate (" + describe_nonfinite(xyz[k]) + ")");
    ++vertex;
    return Status::success();
  });
  if (!st) return st;
  if (faces == 0) return Status::error(what + ": has no faces (points only: " + std::to_string(vertex) + " vertices)");
  if (vertex > uint64_t(std::numeric_limits<int>::max()))
    return Status::error(what + ": has " + std::to_string(vertex) + " vertices, more than OpenMesh's reader numbers");
  return Status::success();
}

Status read_obj(const std::string& what, const uint8_t* data, size_t size, MeshData& out) {
  // A UTF-8 byte-order mark before the first line is not part of it (OpenMesh would drop
  // the first 'v' and shift every index).
  if (size >= 3 && data[0] == 0xEF && data[1] == 0xBB && data[2] == 0xBF) data += 3, size -= 3;
  Status pre = precheck_obj(what, data, size);
  if (!pre) return pre;
  FlatImporter importer;
  importer.reserve_cap = static_cast<unsigned int>(std::min<size_t>(size, 1u << 30));
  bool read_ok = false;
  std::string said;
  {
    // OpenMesh's readers are singletons with per-read state: one read at a time. What they
    // say on omerr()/omlog() goes into the message, not onto the host's terminal.
    std::lock_guard<std::mutex> lock(openmesh_global_mutex());
    OpenMeshLogCapture capture;
    OpenMesh::IO::Options options = OpenMesh::IO::Options::Default;
    try {
      std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
      read_ok = OpenMesh::IO::IOManager().read(in, "obj", importer, options);
    } catch (const std::exception& e) {
      read_ok = false;
      ::omerr() << "exception: " << e.what();
    }
    said = capture.text();
  }
  const std::string openmesh_said = said.empty() ? "" : " (OpenMesh: " + said + ")";
  if (!read_ok) return Status::error(what + ": OpenMesh could not read it" + openmesh_said);
  RawPolygons raw;
  raw.positions = std::move(importer.positions);
  raw.corners.assign(importer.polygon_indices.begin(), importer.polygon_indices.end());
  raw.offsets = std::move(importer.polygon_offsets);
  for (float c : raw.positions)
    if (!std::isfinite(c)) return Status::error(what + ": has a non-finite coordinate (" + describe_nonfinite(c) + ")");
  Status st = finish_polygons(what, raw, out, /*obj_numbering=*/true);
  if (!st) st.message += openmesh_said;
  return st;
}

// Reads a regular file whole. stat first (a directory, FIFO, socket or device is refused by
// name without opening it), then open with O_NONBLOCK (a FIFO swapped in meanwhile does not
// block the open) and fstat the descriptor (refused unless still a regular file).
Status read_regular_file(const fs::path& path, std::vector<uint8_t>& bytes) {
  const std::string what = path.string();
  auto kind = [](mode_t m) -> const char* {
    if (S_ISDIR(m)) return "is a directory, not a mesh file";
    if (S_ISFIFO(m)) return "is a FIFO (named pipe), not a regular file";
    if (S_ISSOCK(m)) return "is a socket, not a regular file";
    if (S_ISCHR(m) || S_ISBLK(m)) return "is a device, not a regular file";
    if (!S_ISREG(m)) return "is not a regular file";
    return nullptr;
  };
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    const int e = errno;
    if (e == ENOENT) return Status::error(what + ": no such file");
    if (e == ENOTDIR) return Status::error(what + ": no such file (a parent is not a directory)");
    return Status::error(what + ": cannot be read (" + std::strerror(e) + ")");
  }
  if (const char* k = kind(st.st_mode)) return Status::error(what + ": " + k);
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    const int e = errno;
    return Status::error(what + ": cannot be opened for reading (" + std::strerror(e) + ")");
  }
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  if (::fstat(fd, &st) != 0) return Status::error(what + ": cannot be read (" + std::strerror(errno) + ")");
  if (const char* k = kind(st.st_mode)) return Status::error(what + ": " + k);
  if (st.st_size == 0) return Status::error(what + ": file is empty");
  if (uint64_t(st.st_size) > std::numeric_limits<size_t>::max() / 2)
    return Status::error(what + ": is too large (" + std::to_string(st.st_size) + " bytes)");
  try {
    bytes.resize(size_t(st.st_size));
  } catch (const std::bad_alloc&) {
    return Status::error(what + ": not enough memory to read its " + std::to_string(st.st_size) + " bytes");
  }
  size_t got = 0;
  while (got < bytes.size()) {
    const ssize_t r = ::read(fd, bytes.data() + got, bytes.size() - got);
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) return Status::error(what + ": read error (" + std::strerror(errno) + ")");
    if (r == 0) break;  // shrank while reading
    got += size_t(r);
  }
  bytes.resize(got);
  if (bytes.empty()) return Status::error(what + ": file is empty");
  return Status::success();
}

}  // namespace
}  // namespace detail

Status load_mesh_from_memory(const std::string& name, const std::string& extension, const uint8_t* data, size_t size,
                             MeshData& out) {
  using namespace detail;
  static_assert(std::endian::native == std::endian::little, "the binary readers assume a little-endian host");
  const std::string ext = lower(extension);
  if (size == 0) return Status::error(name + ": file is empty");
  try {
    if (ext == ".obj") return read_obj(name, data, size, out);
    RawPolygons raw;
    Status s;
    if (ext == ".ply") s = read_ply(name, data, size, raw);
    else if (ext == ".off") s = read_off(name, data, size, raw);
    else if (ext == ".stl") s = read_stl(name, data, size, raw);
    else
      return Status::error(name + ": unknown mesh format '" + extension + "' (expected .obj, .ply, .off or .stl)");
    if (!s) return s;
    return finish_polygons(name, raw, out);
  } catch (const std::bad_alloc&) {
    return Status::error(name + ": not enough memory to load it (" + std::to_string(size) + " bytes)");
  }
}

Status load_mesh(const std::filesystem::path& path, MeshData& out) {
  using namespace detail;
  const std::string what = path.string();
  const std::string ext = lower(path.extension().string());
  if (ext == ".gz" || ext == ".zip" || ext == ".bz2" || ext == ".xz")
    return Status::error(what + ": is compressed ('" + path.extension().string() +
                         "'); decompress it first (.obj, .ply, .off or .stl)");
  if (ext != ".obj" && ext != ".ply" && ext != ".off" && ext != ".stl")
    return Status::error(what + ": unknown mesh format '" + path.extension().string() +
                         "' (expected .obj, .ply, .off or .stl)");
  std::vector<uint8_t> bytes;
  Status r = read_regular_file(path, bytes);
  if (!r) return r;
  return load_mesh_from_memory(what, path.extension().string(), bytes.data(), bytes.size(), out);
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
