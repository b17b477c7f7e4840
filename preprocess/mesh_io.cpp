// Mesh loading: the file is read once into memory (a regular file only, opened so that a FIFO
// or device never blocks), then parsed by the single-pass reader for its extension
// (ply_reader.cpp, off_reader.cpp, stl_reader.cpp, obj_reader.cpp). OpenMesh's readers are
// no longer used for loading: its PLY header parser loops forever on some unknown words, its
// PLY/OFF readers reserve whatever a header declares, its OBJ reader asserts on some corners
// and opens the files "mtllib" names, and its STL reader took a BOM for a binary header.
#include "preprocess/mesh_io.h"

#include "preprocess/gltf_io.h"
#include "preprocess/mesh_readers.h"
#include "preprocess/texture_uri.h"
#include "runtime/bytes_hasher.h"
#include "runtime/file_write.h"

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

namespace {

// A reader's per-vertex attributes into MeshData's conventions (linear colours, uv origin top
// left), each checked finite; the reader's warnings with them.
Status take_vertex_attributes(const std::string& what, RawPolygons& raw, MeshData& mesh) {
  const struct {
    const std::vector<float>* values;
    size_t width;
    const char* name;
  } columns[] = {{&raw.normals, 3, "normal"}, {&raw.colors, 4, "colour"}, {&raw.uvs, 2, "texture coordinate"}};
  for (const auto& c : columns)
    for (size_t i = 0; i < c.values->size(); ++i)
      if (!std::isfinite((*c.values)[i]))
        return Status::error(what + ": vertex " + std::to_string(i / c.width) + " has a non-finite " + c.name + " (" +
                             describe_nonfinite((*c.values)[i]) + ")");
  size_t clamped = 0;
  for (size_t i = 0; i < raw.colors.size(); ++i) {
    float& c = raw.colors[i];
    clamped += c < 0 || c > 1;
    c = std::clamp(c, 0.0f, 1.0f);
    if (i % 4 != 3) c = srgb_to_linear(c);
  }
  if (clamped) raw.warnings.push_back(what + ": " + std::to_string(clamped) + " vertex colour values outside 0..1 clamped");
  for (size_t v = 0; v < raw.uvs.size() / 2; ++v) raw.uvs[2 * v + 1] = 1.0f - raw.uvs[2 * v + 1];  // PLY: origin bottom left
  mesh.normals = std::move(raw.normals);
  mesh.colors = std::move(raw.colors);
  mesh.uvs = std::move(raw.uvs);
  mesh.warnings = std::move(raw.warnings);
  return Status::success();
}

}  // namespace

namespace {

// Faces read as 32-bit triangles (RawPolygons::triangles): checked, then taken as they are.
Status finish_triangles(const std::string& what, RawPolygons& raw, MeshData& out) {
  const size_t nv = raw.vertex_count();
  for (size_t k = 0; k < raw.triangles.size(); ++k) {
    if (raw.triangles[k] < nv) continue;
    const uint32_t v = raw.triangles[k];
    const std::string number = raw.triangles_signed ? std::to_string(int32_t(v)) : std::to_string(v);
    return Status::error(what + ": face " + std::to_string(k / 3) + " references vertex " + number + " of " +
                         std::to_string(nv));
  }
  MeshData mesh;
  mesh.source = what;
  if (Status s = take_vertex_attributes(what, raw, mesh); !s) return s;
  mesh.indices = std::move(raw.triangles);
  mesh.positions = std::move(raw.positions);
  out = std::move(mesh);
  return Status::success();
}

}  // namespace

Status finish_polygons(const std::string& what, RawPolygons& raw, MeshData& out, bool obj_numbering) {
  if (!raw.triangles.empty()) return finish_triangles(what, raw, out);
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
  if (Status s = take_vertex_attributes(what, raw, mesh); !s) return s;
  if (triangles * 3 == raw.corners.size() && triangles == nf) {  // all triangles: copy and free
    mesh.indices.assign(raw.corners.begin(), raw.corners.end());
    std::vector<int64_t>().swap(raw.corners);
    mesh.positions = std::move(raw.positions);
    out = std::move(mesh);
    return Status::success();
  }
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
constexpr const char* kMeshFormats = ".obj, .ply, .off, .stl, .gltf or .glb";
std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

namespace {

// glTF's parser takes 32-bit sizes (tinygltf): a larger .gltf or .glb is refused unread.
constexpr FileLimit kGltfFileLimit{std::numeric_limits<uint32_t>::max(), "a glTF file"};

const char* text_format(const std::string& ext) {
  if (ext == ".obj") return "OBJ";
  if (ext == ".off") return "OFF";
  if (ext == ".gltf") return "glTF JSON";
  return nullptr;
}

}  // namespace

Status open_mesh_file(const fs::path& path, RegularFile& f, uint64_t& read_bytes) {
  const std::string ext = lower(path.extension().string());
  const bool gltf = ext == ".gltf" || ext == ".glb";
  if (Status s = open_regular_file(path, gltf ? kGltfFileLimit : kInputFileLimit, f); !s) return s;
  read_bytes = f.size;
  if (f.size == 0) return Status::error(f.what + ": file is empty");
  if (const char* format = text_format(ext)) return check_text_head(f, format);
  std::vector<uint8_t> head;
  if (Status s = f.read_head(84, head); !s) return s;
  if (ext == ".ply") {
    // The header is text whatever the format of the body; "ply" is its first line.
    const bool ply = head.size() >= 4 && std::memcmp(head.data(), "ply", 3) == 0 &&
                     (head[3] == '\n' || (head[3] == '\r' && head.size() >= 5 && head[4] == '\n'));
    if (!ply) return Status::error(f.what + ": not a PLY file (first line is not 'ply')");
  } else if (ext == ".stl") {
    // Binary (the count at byte 80 and the size agree, or it does not start with "solid"):
    // what the count declares is all that is read; ASCII: text.
    uint32_t n = 0;
    if (head.size() >= 84) std::memcpy(&n, head.data() + 80, 4);
    const uint64_t binary_bytes = 84 + 50 * uint64_t(n);
    size_t text = head.size() >= 3 && head[0] == 0xEF && head[1] == 0xBB && head[2] == 0xBF ? 3 : 0;
    while (text < head.size() && (head[text] == ' ' || head[text] == '\t' || head[text] == '\r' || head[text] == '\n'))
      ++text;
    const bool ascii = binary_bytes != f.size && head.size() - text >= 5 && std::memcmp(head.data() + text, "solid", 5) == 0;
    if (ascii) return check_text_head(f, "ASCII STL");
    if (head.size() < 84) return Status::success();  // the reader names the short header
    if (n == 0) return Status::error(f.what + ": has no faces (binary STL declares 0 triangles)");
    if (binary_bytes > f.size)
      return Status::error(f.what + ": truncated: binary STL declares " + std::to_string(n) + " triangles (" +
                           std::to_string(binary_bytes) + " bytes) but the file has " + std::to_string(f.size) + " bytes");
    read_bytes = binary_bytes;
  } else if (ext == ".glb") {
    if (head.size() >= 4 && std::memcmp(head.data(), "glTF", 4) != 0)
      return Status::error(f.what + ": not a GLB file (the first 4 bytes are not 'glTF')");
    if (head.size() >= 12) {
      uint32_t length = 0;
      std::memcpy(&length, head.data() + 8, 4);
      if (length > f.size)
        return Status::error(f.what + ": truncated GLB: the header declares " + std::to_string(length) +
                             " bytes, the file has " + std::to_string(f.size));
      if (length >= 12) read_bytes = length;
    }
  }
  return Status::success();
}

Status read_mesh_file(const fs::path& path, std::vector<uint8_t>& bytes) {
  RegularFile f;
  uint64_t n = 0;
  if (Status s = open_mesh_file(path, f, n); !s) return s;
  if (Status s = f.read_all(bytes, n); !s) return s;
  if (bytes.empty()) return Status::error(f.what + ": file is empty");
  return Status::success();
}

}  // namespace detail

namespace detail {
namespace {
// Parses, then frees `owned` (the file's bytes, when load_mesh read them) before the
// polygons are checked and triangulated, so the bytes and the triangles never coexist.
// The materials an OBJ's faces use, in usemtl order, from its mtllib files (found next to the
// OBJ; `base_dir` empty: nothing is read from disk, and the materials get default factors).
Status obj_materials(const std::string& name, const fs::path& base_dir, ObjAttributes& attr,
                     std::vector<MeshMaterial>& out) {
  std::vector<MeshMaterial> found;
  std::vector<std::string> found_names;
  for (size_t i = 0; i < attr.mtllibs.size(); ++i) {
    const std::string here = name + ":" + std::to_string(attr.mtllib_lines[i]);
    if (base_dir.empty()) {
      attr.warnings.push_back(here + ": mtllib '" + quote_token(attr.mtllibs[i]) + "' not read (mesh read from memory)");
      continue;
    }
    const fs::path file = base_dir / attr.mtllibs[i];
    std::error_code ec;
    if (!fs::exists(file, ec))
      return Status::error(here + ": mtllib '" + quote_token(attr.mtllibs[i]) + "' not found (looked for " + file.string() + ")");
    std::vector<uint8_t> bytes;
    if (Status r = read_regular_file(file, kMaterialFileLimit, bytes); !r) return Status::error(here + ": mtllib: " + r.message);
    if (const size_t at = first_nul_byte(bytes); at != SIZE_MAX)
      return Status::error(here + ": mtllib: " + file.string() + ": holds binary data (a NUL byte at offset " +
                           std::to_string(at) + "), not MTL text");
    std::string prefix = fs::path(attr.mtllibs[i]).parent_path().generic_string();
    if (!prefix.empty()) prefix += '/';
    if (Status r = read_mtl(file.string(), bytes.data(), bytes.size(), prefix, found, found_names, attr.warnings); !r) return r;
  }
  for (size_t m = 0; m < attr.material_names.size(); ++m) {
    const auto it = std::find(found_names.begin(), found_names.end(), attr.material_names[m]);
    if (it != found_names.end()) {
      out.push_back(found[size_t(it - found_names.begin())]);
      static const char* kStatement[kTextureSlots] = {"map_Kd", "map_Pm / map_Pr", "map_Bump", "", "map_Ke"};
      for (size_t k = 0; k < kTextureSlots; ++k) {
        const std::string& uri = *texture_slots(out.back())[k].uri;
        if (uri.empty() || base_dir.empty()) continue;
        const fs::path image = base_dir / decode_uri(uri);
        std::error_code ec;
        if (!fs::exists(image, ec))
          return Status::error(name + ": material '" + quote_token(attr.material_names[m]) + "': " + kStatement[k] + " '" +
                               quote_token(decode_uri(uri)) + "' not found (looked for " + image.string() + ")");
        if (Status r = check_regular_file(image, kTextureFileLimit); !r)
          return Status::error(name + ": material '" + quote_token(attr.material_names[m]) + "': " + kStatement[k] +
                               ": " + r.message);
      }
      continue;
    }
    MeshMaterial d;
    d.name = attr.material_names[m];
    d.metallic = 0;
    out.push_back(d);
    if (!base_dir.empty())
      attr.warnings.push_back(name + ":" + std::to_string(attr.material_lines[m]) + ": usemtl '" +
                              quote_token(attr.material_names[m]) +
                              "' names no material of the mtllib files; it gets default factors");
  }
  return Status::success();
}

Status parse_and_finish(const std::string& name, const std::string& extension, const uint8_t* data, size_t size,
                        MeshData& out, std::vector<uint8_t>* owned, const fs::path& base_dir = {}) {
  static_assert(std::endian::native == std::endian::little, "the binary readers assume a little-endian host");
  const std::string ext = lower(extension);
  if (size == 0) return Status::error(name + ": file is empty");
  try {
    RawPolygons raw;
    ObjAttributes attr;
    Status s;
    if (ext == ".obj") s = read_obj(name, data, size, raw, attr);
    else if (ext == ".ply") s = read_ply(name, data, size, raw);
    else if (ext == ".off") s = read_off(name, data, size, raw);
    else if (ext == ".stl") s = read_stl(name, data, size, raw);
    else if (ext == ".gltf" || ext == ".glb") return load_gltf_from_memory(name, ext, data, size, {}, out);
    else
      return Status::error(name + ": unknown mesh format '" + extension + "' (expected " + kMeshFormats + ")");
    if (!s) return s;
    if (owned) std::vector<uint8_t>().swap(*owned);
    if (attr.any()) {
      std::vector<MeshMaterial> materials;
      if (Status m = obj_materials(name, base_dir, attr, materials); !m) return m;
      return finish_obj(name, raw, attr, std::move(materials), attr.material_names, out);
    }
    return finish_polygons(name, raw, out, /*obj_numbering=*/ext == ".obj");
  } catch (const std::bad_alloc&) {
    return Status::error(name + ": not enough memory to load it (" + std::to_string(size) + " bytes)");
  }
}
}  // namespace
}  // namespace detail

Status load_mesh_from_memory(const std::string& name, const std::string& extension, const uint8_t* data, size_t size,
                             MeshData& out) {
  return detail::parse_and_finish(name, extension, data, size, out, nullptr);
}

namespace {

// The formats parsed from one file's bytes (glTF's buffers may be files of their own; compressed
// files are refused by name).
bool parses_from_bytes(const std::string& ext) { return ext == ".obj" || ext == ".ply" || ext == ".off" || ext == ".stl"; }

}  // namespace

Status load_mesh(const std::filesystem::path& path, MeshData& out) {
  using namespace detail;
  const std::string what = path.string();
  const std::string ext = lower(path.extension().string());
  if (ext == ".gz" || ext == ".zip" || ext == ".bz2" || ext == ".xz")
    return Status::error(what + ": is compressed ('" + path.extension().string() + "'); decompress it first (" +
                         kMeshFormats + ")");
  if (ext == ".gltf" || ext == ".glb") return load_gltf(path, out);
  if (ext != ".obj" && ext != ".ply" && ext != ".off" && ext != ".stl")
    return Status::error(what + ": unknown mesh format '" + path.extension().string() + "' (expected " + kMeshFormats +
                         ")");
  std::vector<uint8_t> bytes;
  Status r = read_mesh_file(path, bytes);
  if (!r) return r;
  return load_mesh(path, std::move(bytes), out);
}

Status load_mesh(const std::filesystem::path& path, std::vector<uint8_t>&& bytes, MeshData& out) {
  using namespace detail;
  const std::string ext = lower(path.extension().string());
  if (bytes.empty() || !parses_from_bytes(ext)) {  // read (or refused) by path
    std::vector<uint8_t>().swap(bytes);
    return load_mesh(path, out);
  }
  std::vector<uint8_t> owned = std::move(bytes);
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  return parse_and_finish(path.string(), path.extension().string(), owned.data(), owned.size(), out, &owned, dir);
}

Status load_mesh_hashed(const std::filesystem::path& path, MeshData& out, uint64_t& content_hash) {
  using namespace detail;
  if (lower(path.extension().string()) == ".ply") {
    RawPolygons raw;
    bool handled = false;
    uint64_t hash = 0;
    if (Status s = read_plain_ply_file(path, raw, hash, handled); !s) return s;
    if (handled) {
      MeshData m;
      try {
        if (Status s = finish_polygons(path.string(), raw, m, /*obj_numbering=*/false); !s) return s;
      } catch (const std::bad_alloc&) {
        return Status::error(path.string() + ": not enough memory to load it");
      }
      out = std::move(m);
      content_hash = hash;
      return Status::success();
    }
  }
  std::vector<uint8_t> bytes;
  if (Status s = read_mesh_file(path, bytes); !s) return s;
  BytesHasher hasher;  // hash_bytes, without linking the asset code into the readers
  hasher.add(bytes.data(), bytes.size());
  const uint64_t hash = hasher.finish();
  if (Status s = load_mesh(path, std::move(bytes), out); !s) return s;
  content_hash = hash;
  return Status::success();
}

namespace {

// The last token of each line starting with `keyword` (all tokens for mtllib).
std::vector<std::string> statement_files(const std::vector<uint8_t>& bytes, std::string_view keyword, bool all) {
  std::vector<std::string> out;
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  for (size_t pos = 0; pos < text.size();) {
    size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    while (!line.empty() && std::isspace(uint8_t(line.front()))) line.remove_prefix(1);
    if (line.substr(0, keyword.size()) != keyword || line.size() == keyword.size() ||
        !std::isspace(uint8_t(line[keyword.size()])))
      continue;
    std::istringstream words{std::string(line.substr(keyword.size()))};
    std::string w, last;
    while (words >> w) {
      if (all) out.push_back(w);
      last = w;
    }
    if (!all && !last.empty()) out.push_back(last);
  }
  return out;
}

}  // namespace

std::vector<std::filesystem::path> obj_external_files(const std::filesystem::path& path) {
  std::vector<uint8_t> bytes;
  if (!detail::read_mesh_file(path, bytes)) return {};
  const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  std::vector<std::filesystem::path> out;
  for (const std::string& lib : statement_files(bytes, "mtllib", true)) {
    const std::filesystem::path mtl = dir / lib;
    std::error_code ec;
    if (!std::filesystem::exists(mtl, ec)) continue;
    out.push_back(mtl);  // even when it cannot be read: the key's hashing names what it is
    std::vector<uint8_t> m;
    if (!read_regular_file(mtl, kMaterialFileLimit, m) || first_nul_byte(m) != SIZE_MAX) continue;
    for (const char* map : {"map_Kd", "map_Ke", "map_Bump", "map_bump", "bump", "norm", "map_Pm", "map_Pr"})
      for (const std::string& image : statement_files(m, map, false)) out.push_back(mtl.parent_path() / image);
  }
  return out;
}

Status save_ply(const std::filesystem::path& path, const float* positions, size_t vertex_count,
                const uint32_t* indices, size_t index_count) {
  const std::string what = path.string();
  if (index_count % 3 != 0) return Status::error(what + ": index count " + std::to_string(index_count) + " is not a multiple of 3");
  for (size_t i = 0; i < index_count; ++i)
    if (indices[i] >= vertex_count)
      return Status::error(what + ": triangle " + std::to_string(i / 3) + " references vertex " +
                           std::to_string(indices[i]) + " of " + std::to_string(vertex_count));
  const std::string header = "ply\nformat binary_little_endian 1.0\ncomment lodkit\nelement vertex " +
                             std::to_string(vertex_count) +
                             "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                             std::to_string(index_count / 3) +
                             "\nproperty list uchar int vertex_indices\nend_header\n";
  static_assert(std::endian::native == std::endian::little, "save_ply writes host-order floats");
  std::vector<uint8_t> bytes(header.begin(), header.end());
  const size_t body = header.size();
  bytes.resize(body + vertex_count * 12 + index_count / 3 * 13);
  std::memcpy(bytes.data() + body, positions, vertex_count * 12);
  uint8_t* face = bytes.data() + body + vertex_count * 12;
  for (size_t t = 0; t < index_count / 3; ++t, face += 13) {
    face[0] = 3;
    std::memcpy(face + 1, indices + 3 * t, 12);
  }
  return write_file_atomic(path, bytes);
}

namespace {

// usemtl / newmtl names: no blanks (OBJ splits on them), unique by the index in front.
std::string obj_material_name(const std::vector<ObjMaterialView>& materials, int32_t m) {
  if (m < 0) return "lodkit_default";
  std::string s = "m";  // appended piecewise: GCC 12 warns (-Wrestrict) on "m" + to_string
  s += std::to_string(m);
  if (!materials[size_t(m)].name.empty()) s += '_';
  for (unsigned char c : materials[size_t(m)].name) s += std::isalnum(c) || c == '-' || c == '.' ? char(c) : '_';
  return s.substr(0, 128);
}

Status check_surfaces(const std::string& what, const ObjSurfaces& s, size_t index_count) {
  size_t covered = 0;
  for (size_t i = 0; i < s.submeshes.size(); ++i) {
    const ObjSubmeshView& r = s.submeshes[i];
    if (r.first_index != covered || r.index_count % 3 != 0 || r.index_count > index_count - covered)
      return Status::error(what + ": submesh " + std::to_string(i) + " does not continue the runs before it");
    if (r.material < -1 || (r.material >= 0 && size_t(r.material) >= s.materials.size()))
      return Status::error(what + ": submesh " + std::to_string(i) + " names material " + std::to_string(r.material) +
                           " of " + std::to_string(s.materials.size()));
    covered += r.index_count;
  }
  if (covered != index_count)
    return Status::error(what + ": submeshes cover " + std::to_string(covered) + " of " + std::to_string(index_count) +
                         " indices");
  return Status::success();
}

// <stem>.mtl and the images it names, copied next to it.
Status write_mtl(const std::filesystem::path& obj, const ObjSurfaces& s) {
  std::string text = "# lodkit\nnewmtl lodkit_default\nKd 1 1 1\nd 1\n";
  char line[200];
  // Where each copy came from: a file, or bytes in memory (then the pointer is set).
  std::vector<std::pair<std::filesystem::path, const EmbeddedImage*>> copied;
  // The copy's name next to the .mtl, empty when the image is missing or too large (said).
  // `embedded`, when set, holds the image (`image` is then ignored).
  auto copy_image = [&](size_t i, const std::filesystem::path& image, const EmbeddedImage* embedded,
                        std::string& name) -> Status {
    name.clear();
    const std::pair source(embedded ? std::filesystem::path() : image, embedded);
    if (embedded && (image_type_of(embedded->bytes) == ImageType::unknown || embedded->bytes.size() > kMaxEmbeddedImageBytes)) {
      if (s.notes)
        s.notes->push_back(obj.string() + ": material " + std::to_string(i) +
                           ": embedded texture is neither PNG nor JPEG or larger than 256 MiB; written without it");
      return Status::success();
    }
    if (!embedded) {
      if (Status r = check_regular_file(image, kTextureFileLimit); !r) {
        if (s.notes)
          s.notes->push_back(obj.string() + ": material " + std::to_string(i) + ": texture " + r.message +
                             "; written without it");
        return Status::success();
      }
    }
    auto known = std::find(copied.begin(), copied.end(), source);
    const size_t k = size_t(known - copied.begin());
    const std::string extension = embedded ? file_extension(embedded->type) : image.extension().string();
    name = obj.stem().string() + "-image" + std::to_string(k) + extension;
    if (known == copied.end()) {
      std::vector<uint8_t> bytes;
      if (embedded) bytes = embedded->bytes;
      else if (Status r = read_regular_file(image, kTextureFileLimit, bytes); !r) return r;
      if (Status w = write_file_atomic(obj.parent_path() / name, bytes); !w) return w;
      copied.push_back(source);
    }
    return Status::success();
  };
  for (size_t i = 0; i < s.materials.size(); ++i) {
    const ObjMaterialView& m = s.materials[i];
    text += "newmtl " + obj_material_name(s.materials, int32_t(i)) + "\n";
    std::snprintf(line, sizeof line, "Kd %.6g %.6g %.6g\nd %.6g\nKe %.6g %.6g %.6g\nPm %.6g\nPr %.6g\n", m.base_color[0],
                  m.base_color[1], m.base_color[2], m.base_color[3], m.emissive[0], m.emissive[1], m.emissive[2],
                  m.metallic, m.roughness);
    text += line;
    std::string name;
    if (!m.base_color_image.empty() || m.embedded_images[0]) {
      if (Status r = copy_image(i, m.base_color_image, m.embedded_images[0], name); !r) return r;
      if (!name.empty()) text += "map_Kd " + name + "\n";
    }
    if (!m.normal_image.empty() || m.embedded_images[2]) {
      if (Status r = copy_image(i, m.normal_image, m.embedded_images[2], name); !r) return r;
      std::snprintf(line, sizeof line, "map_Bump -bm %.6g ", m.normal_scale);
      if (!name.empty()) text += line + name + "\n";
    }
    if (!m.emissive_image.empty() || m.embedded_images[4]) {
      if (Status r = copy_image(i, m.emissive_image, m.embedded_images[4], name); !r) return r;
      if (!name.empty()) text += "map_Ke " + name + "\n";
    }
    if (!m.metallic_roughness_image.empty() || m.embedded_images[1]) {
      if (Status r = copy_image(i, m.metallic_roughness_image, m.embedded_images[1], name); !r) return r;
      if (!name.empty()) text += "map_Pm -imfchan b " + name + "\nmap_Pr -imfchan g " + name + "\n";
    }
    if ((!m.occlusion_image.empty() || m.embedded_images[3]) && s.notes)
      s.notes->push_back(obj.string() + ": material " + std::to_string(i) + ": occlusion texture " +
                         (m.embedded_images[3] ? std::string("(embedded image)") : m.occlusion_image.string()) +
                         " not written (MTL has no occlusion statement)");
  }
  std::filesystem::path mtl = obj;
  mtl.replace_extension(".mtl");
  return write_file_atomic(mtl, text);
}

// The OBJ colour extension is sRGB as displayed (MeshLab); MeshData::colors are linear.
float linear_to_srgb(float c) {
  c = std::clamp(c, 0.0f, 1.0f);
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1 / 2.4f) - 0.055f;
}

Status save_obj_text(const std::filesystem::path& path, const float* positions, const float* normals,
                     size_t vertex_count, const uint32_t* indices, size_t index_count, const float* uvs,
                     const float* colors, const ObjSurfaces* surfaces) {
  const std::string what = path.string();
  if (index_count % 3 != 0) return Status::error(what + ": index count " + std::to_string(index_count) + " is not a multiple of 3");
  for (size_t i = 0; i < index_count; ++i)
    if (indices[i] >= vertex_count)
      return Status::error(what + ": triangle " + std::to_string(i / 3) + " references vertex " +
                           std::to_string(indices[i]) + " of " + std::to_string(vertex_count));
  if (surfaces)
    if (Status s = check_surfaces(what, *surfaces, index_count); !s) return s;
  std::string text = "# lodkit\n";
  if (surfaces) {
    std::filesystem::path mtl = path.filename();
    mtl.replace_extension(".mtl");
    text += "mtllib " + mtl.string() + "\n";
  }
  char line[160];
  for (size_t v = 0; v < vertex_count; ++v) {
    const float* p = positions + 3 * v;
    if (colors) {
      const float* c = colors + 4 * v;
      std::snprintf(line, sizeof line, "v %.9g %.9g %.9g %.6g %.6g %.6g\n", p[0], p[1], p[2], linear_to_srgb(c[0]),
                    linear_to_srgb(c[1]), linear_to_srgb(c[2]));
    } else {
      std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", p[0], p[1], p[2]);
    }
    text += line;
  }
  if (uvs)
    for (size_t v = 0; v < vertex_count; ++v) {
      std::snprintf(line, sizeof line, "vt %.9g %.9g\n", uvs[2 * v], 1.0f - uvs[2 * v + 1]);
      text += line;
    }
  if (normals)
    for (size_t v = 0; v < vertex_count; ++v) {
      const float* n = normals + 3 * v;
      std::snprintf(line, sizeof line, "vn %.6g %.6g %.6g\n", n[0], n[1], n[2]);
      text += line;
    }
  size_t run = 0;
  for (size_t t = 0; t < index_count / 3; ++t) {
    if (surfaces && run < surfaces->submeshes.size() && surfaces->submeshes[run].first_index == 3 * t) {
      text += "usemtl " + obj_material_name(surfaces->materials, surfaces->submeshes[run].material) + "\n";
      ++run;
    }
    const unsigned long a = indices[3 * t] + 1ul, b = indices[3 * t + 1] + 1ul, c = indices[3 * t + 2] + 1ul;
    if (normals && uvs)
      std::snprintf(line, sizeof line, "f %lu/%lu/%lu %lu/%lu/%lu %lu/%lu/%lu\n", a, a, a, b, b, b, c, c, c);
    else if (uvs)
      std::snprintf(line, sizeof line, "f %lu/%lu %lu/%lu %lu/%lu\n", a, a, b, b, c, c);
    else if (normals)
      std::snprintf(line, sizeof line, "f %lu//%lu %lu//%lu %lu//%lu\n", a, a, b, b, c, c);
    else
      std::snprintf(line, sizeof line, "f %lu %lu %lu\n", a, b, c);
    text += line;
  }
  if (surfaces)
    if (Status s = write_mtl(path, *surfaces); !s) return s;
  return write_file_atomic(path, text);
}

}  // namespace

Status save_obj(const std::filesystem::path& path, const float* positions, const float* normals, size_t vertex_count,
                const uint32_t* indices, size_t index_count, const float* uvs, const float* colors) {
  return save_obj_text(path, positions, normals, vertex_count, indices, index_count, uvs, colors, nullptr);
}

Status save_obj(const std::filesystem::path& path, const float* positions, const float* normals, size_t vertex_count,
                const uint32_t* indices, size_t index_count, const float* uvs, const ObjSurfaces& surfaces,
                const float* colors) {
  return save_obj_text(path, positions, normals, vertex_count, indices, index_count, uvs, colors, &surfaces);
}

}  // namespace lod
