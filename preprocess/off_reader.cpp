// OFF reader (ASCII; OFF, COFF, NOFF, CNOFF, STOFF and their combinations), single pass.
//
// Replaces OpenMesh's OFF reader, which reserves whatever the header declares (a 21-byte
// file took 8 GB) and reads "-1" or a truncated face as whatever was in memory. Layout:
// the magic word, then "vertices faces [edges]", then one vertex per line (x y z first;
// colours, normals or texture coordinates after them on the line are skipped), then one
// face per line ("n i0 .. in-1", optional colour after). '#' starts a comment. The counts are
// checked against the bytes after the header before anything is reserved: a vertex takes at
// least 6 bytes ("0 0 0\n"), a face at least 2 ("0\n").
#include <limits>

#include "preprocess/mesh_readers.h"

namespace lod::detail {

Status read_off(const std::string& what, const uint8_t* data, size_t size, RawPolygons& raw) {
  TextTokens t(data, size, 0, 1, /*hash_comments=*/true);
  std::string_view tok;
  if (!t.next(tok)) return Status::error(what + ": file is empty");
  // [ST][C][N][4][n]OFF, e.g. "OFF", "COFF", "NOFF", "STCNOFF"
  std::string_view prefix = tok;
  if (prefix.size() < 3 || prefix.substr(prefix.size() - 3) != "OFF")
    return Status::error(what + ": not an OFF file (first word is '" + quote_token(tok) + "')");
  prefix.remove_suffix(3);
  if (prefix.substr(0, 2) == "ST") prefix.remove_prefix(2);
  if (!prefix.empty() && prefix[0] == 'C') prefix.remove_prefix(1);
  if (!prefix.empty() && prefix[0] == 'N') prefix.remove_prefix(1);
  if (prefix == "4") return Status::error(what + ": OFF with 4D vertices ('4OFF') is not supported");
  if (!prefix.empty() && prefix.back() == 'n')
    return Status::error(what + ": OFF with a vertex dimension ('nOFF') is not supported");
  if (!prefix.empty()) return Status::error(what + ": not an OFF file (first word is '" + quote_token(tok) + "')");
  if (t.more_on_line()) {
    TextTokens peek = t;
    std::string_view word;
    if (peek.next(word) && word == "BINARY") return Status::error(what + ": binary OFF is not supported");
  }
  uint64_t nv = 0, nf = 0;
  std::string_view a, b;
  if (!t.next(a) || !t.next(b) || !parse_uint(a, nv) || !parse_uint(b, nf))
    return Status::error(what + ": OFF header has no vertex and face counts");
  if (t.more_on_line()) {
    std::string_view edges;
    uint64_t ne = 0;
    t.next(edges);
    if (!parse_uint(edges, ne))
      return Status::error(what + ": OFF header line " + std::to_string(t.line()) + ": bad edge count '" +
                           quote_token(edges) + "'");
  }
  const size_t left = t.remaining();
  if (nv > (left + 1) / 6 || nf > (left + 2) / 2 || (nv * 6 + nf * 2) > left + 2)
    return Status::error(what + ": truncated or corrupt: the header declares " + std::to_string(nv) + " vertices and " +
                         std::to_string(nf) + " faces, more than the " + std::to_string(left) +
                         " bytes after it can hold");
  if (nf == 0) return Status::error(what + ": has no faces (points only: " + std::to_string(nv) + " vertices)");
  if (nv > std::numeric_limits<uint32_t>::max())
    return Status::error(what + ": declares " + std::to_string(nv) + " vertices, more than 2^32-1");
  raw.positions.reserve(size_t(nv) * 3);
  raw.offsets.reserve(size_t(nf) + 1);
  for (uint64_t v = 0; v < nv; ++v) {
    t.skip_line();
    float xyz[3];
    size_t line = 0;
    for (int k = 0; k < 3; ++k) {
      if (!t.next(tok))
        return Status::error(what + ": truncated: the data ends inside vertex " + std::to_string(v) + " of " +
                             std::to_string(nv) + " declared");
      double d = 0;
      if (!parse_real(tok, d))
        return Status::error(what + ": vertex " + std::to_string(v) + " (line " + std::to_string(t.line()) +
                             ") has a coordinate that is not a number ('" + quote_token(tok) + "')");
      xyz[k] = float(d);
      line = t.line();
    }
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(xyz[k]))
        return Status::error(what + ": vertex " + std::to_string(v) + " (line " + std::to_string(line) +
                             ") has a non-finite coordinate (" + describe_nonfinite(xyz[k]) + ")");
    raw.positions.insert(raw.positions.end(), xyz, xyz + 3);
  }
  for (uint64_t f = 0; f < nf; ++f) {
    t.skip_line();
    uint64_t n = 0;
    if (!t.next(tok))
      return Status::error(what + ": truncated: the data ends before face " + std::to_string(f) + " of " +
                           std::to_string(nf) + " declared");
    if (!parse_uint(tok, n))
      return Status::error(what + ": face " + std::to_string(f) + " (line " + std::to_string(t.line()) +
                           ") has a bad corner count '" + quote_token(tok) + "'");
    if (n > (t.remaining() + 1) / 2)
      return Status::error(what + ": truncated: face " + std::to_string(f) + " (line " + std::to_string(t.line()) +
                           ") declares " + std::to_string(n) + " corners, more than the rest of the file holds");
    for (uint64_t k = 0; k < n; ++k) {
      if (!t.next(tok))
        return Status::error(what + ": truncated: the data ends inside face " + std::to_string(f) + " of " +
                             std::to_string(nf) + " declared");
      int64_t idx = 0;
      if (!parse_int(tok, idx))
        return Status::error(what + ": face " + std::to_string(f) + " (line " + std::to_string(t.line()) +
                             ") has a vertex index that is not an integer ('" + quote_token(tok) + "')");
      raw.corners.push_back(idx);
    }
    if (raw.corners.size() > std::numeric_limits<uint32_t>::max())
      return Status::error(what + ": more than 2^32-1 face corners");
    raw.offsets.push_back(uint32_t(raw.corners.size()));
  }
  return Status::success();
}

}  // namespace lod::detail
