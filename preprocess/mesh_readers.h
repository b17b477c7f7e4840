// Internal to preprocess/: the per-format mesh readers behind load_mesh (mesh_io.cpp).
//
// Every reader works on the file's bytes, already in memory (read once, a regular file
// only), in a single pass: declared counts are checked against the bytes left before
// anything is reserved, every value is checked as it is read, and an error names the
// element as the file numbers it. The readers never throw and never index past `size`.
#pragma once
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "preprocess/mesh.h"
#include "runtime/chain_material.h"
#include "runtime/regular_file.h"
#include "runtime/status.h"

namespace lod::detail {

// What a reader produces: vertices and polygons with indices exactly as the file gave them
// (range-checked by finish_polygons, so the message can quote the file's own number).
struct RawPolygons {
  std::vector<float> positions;          // xyz per vertex
  // PLY vertex attributes, each per vertex or empty: normals xyz, colours RGBA from 0 to 1 as
  // stored (sRGB; alpha 1 when absent), texture coordinates as stored (origin bottom left).
  std::vector<float> normals, colors, uvs;
  std::vector<std::string> warnings;     // what the reader skipped
  std::vector<int64_t> corners;          // vertex numbers as written in the file
  std::vector<uint32_t> offsets{0};      // polygon p is corners[offsets[p], offsets[p+1])
  // Instead of corners and offsets, when every polygon is a triangle of 32-bit numbers (binary
  // PLY's usual faces): three per triangle, as stored (int32 ones when `triangles_signed`), so
  // that a scan's indices are read once into the size they keep, not widened and copied.
  std::vector<uint32_t> triangles;
  bool triangles_signed = false;
  size_t vertex_count() const { return positions.size() / 3; }
  size_t polygon_count() const { return triangles.empty() ? offsets.size() - 1 : triangles.size() / 3; }
};

// What an OBJ adds beside its polygons (all empty when it has no vt, vn, usemtl or mtllib).
struct ObjAttributes {
  std::vector<float> texcoords;          // "vt u v", 2 per entry, as written (origin bottom left)
  std::vector<float> normals;            // "vn x y z", 3 per entry
  std::vector<float> colors;             // "v x y z r g b": RGB per vertex as written, from the first coloured
                                         // vertex on (earlier ones and later uncoloured ones: NaN), or empty
  std::vector<int64_t> corner_uv;        // per corner: 0-based vt, -1 none (range-checked later)
  std::vector<int64_t> corner_normal;    // per corner: 0-based vn, -1 none
  std::vector<uint32_t> polygon_line;    // per polygon: its line, for messages
  std::vector<int32_t> polygon_material; // per polygon: index into material_names, -1 default
  std::vector<std::string> material_names;  // usemtl names, in order of first use
  std::vector<uint32_t> material_lines;     // the line of each name's first usemtl
  std::vector<std::string> mtllibs;         // mtllib file names, as written
  std::vector<uint32_t> mtllib_lines;
  std::vector<std::string> warnings;        // what reading the .mtl files skipped
  bool any() const { return !texcoords.empty() || !normals.empty() || !colors.empty() || !material_names.empty() || !mtllibs.empty(); }
};

// Readers: `what` is the name used in messages (the path). On success `raw` holds at least
// one polygon; coordinates are finite.
Status read_ply(const std::string& what, const uint8_t* data, size_t size, RawPolygons& raw);
Status read_off(const std::string& what, const uint8_t* data, size_t size, RawPolygons& raw);
Status read_stl(const std::string& what, const uint8_t* data, size_t size, RawPolygons& raw);
// OBJ: corners are stored 0-based (positive v as v-1, negative resolved against the vertices
// before the face); finish_polygons(..., obj_numbering=true) names them from 1 again.
// vt / vn / usemtl / mtllib go to `attributes`.
Status read_obj(const std::string& what, const uint8_t* data, size_t size, RawPolygons& raw, ObjAttributes& attributes);

// Wavefront MTL (newmtl, Kd, d, Tr, Ke, Pm, Pr, map_Kd, map_Ke, map_Bump, map_Pm / map_Pr) into materials named `names` (as the OBJ uses
// them); `what` is the .mtl file for messages. Texture file names become URIs relative to
// the OBJ's folder (`prefix`: the .mtl's folder relative to it). Other statements are named
// once in `warnings`.
Status read_mtl(const std::string& what, const uint8_t* data, size_t size, const std::string& prefix,
                std::vector<MeshMaterial>& materials, std::vector<std::string>& names, std::vector<std::string>& warnings);

// An OBJ with attributes into `out`: one vertex per distinct (v, vt, vn) corner, uvs in glTF's
// convention (v flipped), normals, submeshes by usemtl; every vt / vn index range-checked
// ("file:line: face 3 references texture coordinate 9 of 4").
Status finish_obj(const std::string& what, RawPolygons& raw, ObjAttributes& attributes,
                  std::vector<MeshMaterial> materials, const std::vector<std::string>& material_names, MeshData& out);

// Range-checks every corner (first bad one reported: "face F references vertex N of V",
// N as the file wrote it) and fan-triangulates into `out` (positions moved out of `raw`).
// With `obj_numbering` the corners are 0-based handles of a file that numbers from 1, and
// the message adds 1 back.
Status finish_polygons(const std::string& what, RawPolygons& raw, MeshData& out, bool obj_numbering = false);

// Opens a mesh file (runtime/regular_file.h: a regular file only, nothing blocks) and checks
// its first bytes against the format its extension names before anything more is read:
// `read_bytes` is how much of it the reader needs (a binary STL or GLB: what its header
// declares). A file that cannot be that format is refused from its head ("f.off: holds binary
// data (a NUL byte at offset 0), not OFF text"), so a sparse multi-GB file is never read whole.
Status open_mesh_file(const std::filesystem::path& path, RegularFile& f, uint64_t& read_bytes);
// open_mesh_file, then the bytes it allows.
Status read_mesh_file(const std::filesystem::path& path, std::vector<uint8_t>& bytes);

// The layout scanners write, binary little-endian PLY with a vertex element of float x, y, z
// alone and a face element of one uchar-counted list of 32-bit indices, every face a triangle:
// read from the file straight into raw.positions and raw.triangles (no copy of the file in
// memory: a 14M-triangle scan's 265 MB) and hashed on the way (content_hash = hash_bytes of
// the whole file). `handled` false, raw and the hash untouched: another layout, or something
// read_ply names (a short file, a non-finite coordinate, another face size); read the file
// whole then. A status only when the file cannot be opened or memory runs out.
Status read_plain_ply_file(const std::filesystem::path& path, RawPolygons& raw, uint64_t& content_hash, bool& handled);

// ---- helpers shared by the text readers ------------------------------------------------

// Vertex colours in OBJ and PLY files are sRGB as displayed; MeshData::colors are linear.
inline float srgb_to_linear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

inline std::string describe_nonfinite(float v) {
  if (std::isnan(v)) return "nan";
  return v > 0 ? "inf" : "-inf";
}

// At most 32 bytes of a token, control bytes shown as '?', for quoting in messages.
std::string quote_token(std::string_view tok);

// Whitespace-separated tokens of a text buffer with line numbers; optional '#' comments
// (OFF has them, PLY's data section does not).
class TextTokens {
 public:
  TextTokens(const uint8_t* data, size_t size, size_t start, size_t line, bool hash_comments)
      : d_(data), n_(size), i_(start), line_(line), comments_(hash_comments) {}
  bool next(std::string_view& tok);
  // Moves to the start of the next line (extra per-element values such as colours).
  void skip_line();
  // True if another token follows on the current line (comments end the line).
  bool more_on_line() const;
  size_t line() const { return line_; }
  size_t offset() const { return i_; }
  size_t remaining() const { return n_ - i_; }

 private:
  const uint8_t* d_;
  size_t n_;
  size_t i_;
  size_t line_;
  bool comments_;
};

// Whole-token parsers: the token must be exactly the number (iostreams would stop inside
// "2-1" and read the rest as the next value).
bool parse_uint(std::string_view tok, uint64_t& out);   // decimal digits only, no overflow
bool parse_int(std::string_view tok, int64_t& out);     // optional '-', no overflow
bool parse_real(std::string_view tok, double& out);     // strtod syntax incl. nan/inf

}  // namespace lod::detail
