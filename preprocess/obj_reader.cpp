// OBJ reader, single pass over the bytes in memory.
//
// Replaces OpenMesh's OBJ reader, which asserts (aborts the process) on a corner without a
// vertex index ("f /1/1 ..."; also "f\r/1" since any blank ends a keyword), drops a 'v' line
// it cannot parse (shifting every later index), opens whatever file a "mtllib" line names (a
// FIFO blocks) and turns an out-of-range relative index into handle arithmetic.
//
// Read: "v x y z" (a fourth number, w, is ignored; three more are a vertex colour, RGB as
// MeshLab writes them, from 0 to 1, or 0 to 255 when some value is above 1) and
// "f c0 c1 c2 ..." with corners "v", "v/vt", "v//vn" or "v/vt/vn"; a negative v counts back
// from the last vertex before the face (-1 = that vertex). "vt u [v [w]]", "vn x y z",
// "usemtl NAME" and "mtllib FILE..." go to ObjAttributes (corners' vt / vn numbers likewise,
// negative ones resolved the same way); arrays for them are only kept once a file uses them,
// so a geometry-only OBJ costs nothing more. Other statements (g, o, s, l, p, ...) are ignored. A line ending in '\' continues on the next one.
// Keywords and values are separated by any blank (space, tab, CR, VT, FF), as iostreams do.
// A UTF-8 byte-order mark before the first line is skipped; UTF-16 is refused. A vertex
// repeated within one face is dropped after its first corner (as OpenMesh's reader did).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <unordered_map>
#include <unordered_set>

#include "preprocess/mesh_readers.h"

namespace lod::detail {
namespace {

bool blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// How many numbers follow `at` on a 'v' line (up to 4 read; the first 3 into rgb): 3 is
// "v x y z r g b", the vertex colour extension MeshLab, ZBrush and Open3D write; 1 is w.
int trailing_numbers(std::string_view line, size_t at, std::string& number, float rgb[3]) {
  int n = 0;
  for (; n < 4; ++n) {
    while (at < line.size() && blank(line[at])) ++at;
    size_t e = at;
    while (e < line.size() && !blank(line[e])) ++e;
    if (e == at) break;
    number.assign(line.substr(at, std::min<size_t>(e - at, 64)));
    char* stop = nullptr;
    const double v = std::strtod(number.c_str(), &stop);
    if (stop == number.c_str()) break;
    if (n < 3) rgb[n] = float(v);
    at = e;
  }
  return n;
}

// A vertex without a colour in a file where others have one (a file cannot write NaN: refused).
constexpr float kNoColour = std::numeric_limits<float>::quiet_NaN();

// Vertex `v`'s colour (earlier vertices without one are marked kNoColour).
Status add_vertex_colour(const std::string& where, size_t v, const float rgb[3], ObjAttributes& attr) {
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(rgb[c]))
      return Status::error(where + ": vertex " + std::to_string(v) + " has a non-finite colour component (" +
                           describe_nonfinite(rgb[c]) + ")");
  if (attr.colors.empty()) attr.colors.assign(3 * v, kNoColour);
  attr.colors.insert(attr.colors.end(), rgb, rgb + 3);
  return Status::success();
}

}  // namespace

Status read_obj(const std::string& what, const uint8_t* data, size_t size, RawPolygons& raw, ObjAttributes& attr) {
  if (size >= 2 && ((data[0] == 0xFE && data[1] == 0xFF) || (data[0] == 0xFF && data[1] == 0xFE)))
    return Status::error(what + ": is UTF-16 text; OBJ files must be ASCII or UTF-8");
  if (size >= 3 && data[0] == 0xEF && data[1] == 0xBB && data[2] == 0xBF) data += 3, size -= 3;
  const char* text = reinterpret_cast<const char*>(data);
  size_t pos = 0, line_no = 0;
  uint64_t faces = 0;
  std::string joined;  // a statement continued over several lines
  std::string number;  // one coordinate, NUL-terminated for strtod
  std::unordered_set<int64_t> seen;  // corners of a long face
  bool tracking = false;             // attr's per-corner / per-polygon arrays are being kept
  int32_t material = -1;             // current usemtl
  auto track = [&] {
    if (tracking) return;
    tracking = true;
    attr.corner_uv.assign(raw.corners.size(), -1);
    attr.corner_normal.assign(raw.corners.size(), -1);
    attr.polygon_material.assign(raw.polygon_count(), -1);
  };
  // "file:line" for messages about one statement.
  auto at_line = [&](size_t line) { return what + ":" + std::to_string(line); };
  // The next whitespace-separated token of `line` from `at`, or empty.
  auto token = [](std::string_view line, size_t& at) {
    while (at < line.size() && blank(line[at])) ++at;
    size_t e = at;
    while (e < line.size() && !blank(line[e])) ++e;
    const std::string_view t = line.substr(at, e - at);
    at = e;
    return t;
  };
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
      float rgb[3];
      if (const int extra = trailing_numbers(line, at, number, rgb); extra == 3) {
        if (Status c = add_vertex_colour(at_line(first_line), raw.vertex_count(), rgb, attr); !c) return c;
      } else if (!attr.colors.empty()) {
        attr.colors.insert(attr.colors.end(), 3, kNoColour);  // white, said in finish_obj
      }
      raw.positions.insert(raw.positions.end(), xyz, xyz + 3);
    } else if (keyword == "vt" || keyword == "vn") {
      track();
      const int dims = keyword == "vt" ? 2 : 3;
      float xyz[3] = {0, 0, 0};
      size_t at = k;
      for (int d = 0; d < dims; ++d) {
        number.assign(token(line, at).substr(0, 64));
        char* stop = nullptr;
        const double v = number.empty() ? 0 : std::strtod(number.c_str(), &stop);
        // "vt u" alone is legal (v = 0); anything else must be a number.
        if (number.empty() && keyword == "vt" && d == 1) break;
        if (number.empty() || stop == number.c_str() || !std::isfinite(float(v)))
          return Status::error(at_line(first_line) + ": '" + std::string(keyword) + "' needs " + std::to_string(dims) +
                               " finite numbers" + (number.empty() ? "" : ", not '" + quote_token(number) + "'"));
        xyz[d] = float(v);
      }
      std::vector<float>& out = keyword == "vt" ? attr.texcoords : attr.normals;
      if (out.size() / size_t(dims) >= std::numeric_limits<uint32_t>::max())
        return Status::error(at_line(first_line) + ": more than 2^32-1 '" + std::string(keyword) + "' entries");
      out.insert(out.end(), xyz, xyz + dims);
    } else if (keyword == "usemtl") {
      track();
      size_t at = k;
      const std::string name(token(line, at));
      if (name.empty()) return Status::error(at_line(first_line) + ": usemtl without a material name");
      const auto it = std::find(attr.material_names.begin(), attr.material_names.end(), name);
      material = int32_t(it - attr.material_names.begin());
      if (it == attr.material_names.end()) {
        if (attr.material_names.size() >= kMaxMaterials)
          return Status::error(at_line(first_line) + ": more than " + std::to_string(kMaxMaterials) + " materials");
        attr.material_names.push_back(name);
        attr.material_lines.push_back(uint32_t(first_line));
      }
    } else if (keyword == "mtllib") {
      size_t at = k;
      for (std::string_view t = token(line, at); !t.empty(); t = token(line, at)) {
        if (attr.mtllibs.size() >= 64) return Status::error(at_line(first_line) + ": more than 64 mtllib files");
        attr.mtllibs.emplace_back(t);
        attr.mtllib_lines.push_back(uint32_t(first_line));
      }
    } else if (keyword == "f") {
      const int64_t before = int64_t(raw.vertex_count());
      const size_t face_begin = raw.corners.size();
      seen.clear();
      // A vertex repeated within a face is dropped after its first corner, as OpenMesh's
      // reader did ("f 1 2 3 4 1 2 3 4" is the quad 1 2 3 4).
      auto add = [&](int64_t idx, int64_t uv, int64_t nrm) {
        const size_t n = raw.corners.size() - face_begin;
        if (n < 16) {
          for (size_t c = face_begin; c < raw.corners.size(); ++c)
            if (raw.corners[c] == idx) return;
        } else {
          if (seen.empty()) seen.insert(raw.corners.begin() + std::ptrdiff_t(face_begin), raw.corners.end());
          if (!seen.insert(idx).second) return;
        }
        raw.corners.push_back(idx);
        if (tracking) attr.corner_uv.push_back(uv), attr.corner_normal.push_back(nrm);
      };
      size_t at = k;
      for (;;) {
        while (at < line.size() && blank(line[at])) ++at;
        if (at >= line.size()) break;
        size_t e = at;
        while (e < line.size() && !blank(line[e])) ++e;
        const std::string_view corner = line.substr(at, e - at);
        at = e;
        const size_t slash = corner.find('/');
        const std::string_view index = corner.substr(0, slash);
        // "v/vt/vn", "v//vn", "v/vt": the other two numbers, 0-based (-1 when absent).
        int64_t uv = -1, nrm = -1;
        if (slash != std::string_view::npos) {
          const std::string_view rest = corner.substr(slash + 1);
          const size_t slash2 = rest.find('/');
          const std::string_view parts[2] = {rest.substr(0, slash2),
                                             slash2 == std::string_view::npos ? std::string_view() : rest.substr(slash2 + 1)};
          const int64_t counts[2] = {int64_t(attr.texcoords.size() / 2), int64_t(attr.normals.size() / 3)};
          int64_t* outs[2] = {&uv, &nrm};
          for (int q = 0; q < 2; ++q) {
            if (parts[q].empty()) continue;
            int64_t x = 0;
            if (!parse_int(parts[q], x) || x == 0)
              return Status::error(at_line(first_line) + ": face " + std::to_string(faces) + " has a corner with an invalid " +
                                   (q == 0 ? "texture coordinate" : "normal") + " number ('" + quote_token(corner) + "')");
            if (x < 0 && x < -counts[q])
              return Status::error(at_line(first_line) + ": face " + std::to_string(faces) + " references " +
                                   (q == 0 ? "texture coordinate " : "normal ") + std::to_string(x) + " (relative) of " +
                                   std::to_string(counts[q]) + " before it");
            *outs[q] = x < 0 ? counts[q] + x : x - 1;
          }
          if (uv >= 0 || nrm >= 0) track();
        }
        int64_t v = 0;
        if (!parse_int(index, v) || v == 0)
          return Status::error(what + ": face " + std::to_string(faces) + " (line " + std::to_string(first_line) +
                               ") has a corner without a valid vertex index ('" + quote_token(corner) + "')");
        if (v < 0) {
          if (v < -before)
            return Status::error(what + ": face " + std::to_string(faces) + " references vertex " +
                                 std::to_string(v) + " (relative) of " + std::to_string(before) +
                                 " before it, on line " + std::to_string(first_line));
          add(before + v, uv, nrm);
        } else {
          add(v - 1, uv, nrm);  // checked against the final count by finish_polygons
        }
      }
      if (raw.corners.size() > std::numeric_limits<uint32_t>::max())
        return Status::error(what + ": more than 2^32-1 face corners");
      raw.offsets.push_back(uint32_t(raw.corners.size()));
      attr.polygon_line.push_back(uint32_t(std::min<size_t>(first_line, UINT32_MAX)));
      if (tracking) attr.polygon_material.push_back(material);
      ++faces;
    }
  }
  if (faces == 0)
    return Status::error(what + ": has no faces (points only: " + std::to_string(raw.vertex_count()) + " vertices)");
  return Status::success();
}

}  // namespace lod::detail

namespace lod::detail {
namespace {

struct CornerKey {
  int64_t v, uv, n;
  bool operator==(const CornerKey&) const = default;
};
struct CornerHash {
  size_t operator()(const CornerKey& k) const {
    return size_t((uint64_t(k.v) * 0x9e3779b97f4a7c15ull) ^ (uint64_t(k.uv) * 0xc2b2ae3d27d4eb4full) ^
                  (uint64_t(k.n) * 0x165667b19e3779f9ull));
  }
};

// The 'v' lines' colours as linear RGBA per vertex (MeshData::colors), or empty. They are sRGB as
// written; a file with a value above 1 wrote 0-255; vertices without one get white. Said.
std::vector<float> linear_vertex_colours(const std::string& what, const std::vector<float>& rgb, size_t vertices,
                                         std::vector<std::string>& warnings) {
  if (rgb.empty()) return {};
  float top = 0;  // NaN (no colour) compares false
  for (float x : rgb) top = x > top ? x : top;
  const float scale = top > 1 ? 1.0f / 255 : 1.0f;
  if (top > 1) warnings.push_back(what + ": vertex colours above 1: read as 0-255");
  std::vector<float> out(4 * vertices, 1.0f);
  size_t missing = 0, clamped = 0;
  for (size_t v = 0; v < vertices; ++v) {
    if (3 * v + 2 >= rgb.size() || std::isnan(rgb[3 * v])) {
      ++missing;
      continue;
    }
    for (int c = 0; c < 3; ++c) {
      const float x = rgb[3 * v + size_t(c)] * scale;
      clamped += x < 0 || x > 1;
      out[4 * v + size_t(c)] = srgb_to_linear(std::clamp(x, 0.0f, 1.0f));
    }
  }
  if (missing)
    warnings.push_back(what + ": " + std::to_string(missing) + " of " + std::to_string(vertices) +
                       " vertices have no colour where others have one; they get white");
  if (clamped) warnings.push_back(what + ": " + std::to_string(clamped) + " vertex colour values outside 0..1 clamped");
  return out;
}

// Every corner's three numbers within their lists, the message naming file:line.
Status check_corners(const std::string& what, const RawPolygons& raw, const ObjAttributes& a) {
  const int64_t counts[3] = {int64_t(raw.vertex_count()), int64_t(a.texcoords.size() / 2), int64_t(a.normals.size() / 3)};
  const char* names[3] = {"vertex", "texture coordinate", "normal"};
  for (size_t f = 0; f < raw.polygon_count(); ++f)
    for (uint32_t i = raw.offsets[f]; i < raw.offsets[f + 1]; ++i) {
      const int64_t idx[3] = {raw.corners[i], a.corner_uv[i], a.corner_normal[i]};
      for (int q = 0; q < 3; ++q) {
        if (idx[q] < (q == 0 ? 0 : -1) || idx[q] >= counts[q])
          return Status::error(what + ":" + std::to_string(a.polygon_line[f]) + ": face " + std::to_string(f) +
                               " references " + names[q] + " " + std::to_string(idx[q] + 1) + " of " +
                               std::to_string(counts[q]) + " (OBJ numbering, from 1)");
      }
    }
  return Status::success();
}

}  // namespace

Status finish_obj(const std::string& what, RawPolygons& raw, ObjAttributes& a, std::vector<MeshMaterial> materials,
                  const std::vector<std::string>& material_names, MeshData& out) {
  a.corner_uv.resize(raw.corners.size(), -1);
  a.corner_normal.resize(raw.corners.size(), -1);
  a.polygon_material.resize(raw.polygon_count(), -1);
  if (raw.polygon_count() == 0) return Status::error(what + ": has no faces");
  if (Status s = check_corners(what, raw, a); !s) return s;
  MeshData mesh;
  mesh.source = what;
  size_t without_uv = 0, without_normal = 0;
  for (size_t i = 0; i < raw.corners.size(); ++i) without_uv += a.corner_uv[i] < 0, without_normal += a.corner_normal[i] < 0;
  const bool uvs = !a.texcoords.empty() && without_uv < raw.corners.size();
  const bool normals = !a.normals.empty() && without_normal == 0;
  if (uvs && without_uv > 0)
    mesh.warnings.push_back(what + ": " + std::to_string(without_uv) + " face corners have no texture coordinate; they get (0, 0)");
  if (!a.normals.empty() && without_normal > 0)
    mesh.warnings.push_back(what + ": normals dropped: " + std::to_string(without_normal) +
                            " face corners have none (they are recomputed when baking)");
  const std::vector<float> colors = linear_vertex_colours(what, a.colors, raw.vertex_count(), mesh.warnings);
  // One vertex per distinct (v, vt, vn) the faces use, in order of first use.
  std::unordered_map<CornerKey, uint32_t, CornerHash> ids;
  std::vector<uint32_t> corner_vertex(raw.corners.size());
  for (size_t i = 0; i < raw.corners.size(); ++i) {
    const CornerKey key{raw.corners[i], uvs ? a.corner_uv[i] : -1, normals ? a.corner_normal[i] : -1};
    auto [it, fresh] = ids.try_emplace(key, uint32_t(mesh.vertex_count()));
    if (fresh) {
      const float* p = &raw.positions[3 * size_t(key.v)];
      mesh.positions.insert(mesh.positions.end(), p, p + 3);
      if (uvs) {
        const float* t = key.uv >= 0 ? &a.texcoords[2 * size_t(key.uv)] : nullptr;
        mesh.uvs.insert(mesh.uvs.end(), {t ? t[0] : 0.0f, t ? 1.0f - t[1] : 0.0f});  // OBJ: origin bottom left
      }
      if (normals) mesh.normals.insert(mesh.normals.end(), &a.normals[3 * size_t(key.n)], &a.normals[3 * size_t(key.n)] + 3);
      if (!colors.empty()) mesh.colors.insert(mesh.colors.end(), &colors[4 * size_t(key.v)], &colors[4 * size_t(key.v)] + 4);
    }
    corner_vertex[i] = it->second;
  }
  // Fan triangulation, runs of one material as submeshes.
  for (size_t f = 0; f < raw.polygon_count(); ++f) {
    const uint32_t begin = raw.offsets[f], end = raw.offsets[f + 1];
    if (end - begin < 3) continue;
    const int32_t m = a.polygon_material[f];
    if (mesh.submeshes.empty() || mesh.submeshes.back().material != m)
      mesh.submeshes.push_back({uint32_t(mesh.triangle_count()), 0, m});
    for (uint32_t i = begin + 1; i + 1 < end; ++i) {
      mesh.indices.insert(mesh.indices.end(), {corner_vertex[begin], corner_vertex[i], corner_vertex[i + 1]});
      mesh.submeshes.back().triangle_count++;
    }
  }
  if (mesh.indices.empty()) return Status::error(what + ": has no triangles (every face has fewer than 3 corners)");
  if (material_names.empty()) mesh.submeshes.clear();
  mesh.materials = std::move(materials);
  for (std::string& w : a.warnings) mesh.warnings.push_back(std::move(w));
  out = std::move(mesh);
  return Status::success();
}

}  // namespace lod::detail
