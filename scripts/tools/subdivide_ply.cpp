// subdivide-ply IN OUT: two 1-to-4 midpoint subdivisions of a binary little-endian PLY (float xyz
// vertices, uchar/int triangle faces), as bench_hlod_build makes its 14M mesh from the dragon
// (the distributed bake's figures: scripts/make-dragon-14m.sh).
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>
#include <unordered_map>
int main(int argc, char** argv) {
  if (argc != 3) { fprintf(stderr, "usage: subdivide-ply IN.ply OUT.ply\n"); return 2; }
  FILE* f = fopen(argv[1], "rb");
  if (!f) { fprintf(stderr, "%s: cannot be opened\n", argv[1]); return 1; }
  char line[512]; size_t nv = 0, nf = 0;
  while (fgets(line, sizeof line, f)) {
    if (sscanf(line, "element vertex %zu", &nv) == 1) continue;
    if (sscanf(line, "element face %zu", &nf) == 1) continue;
    if (!strncmp(line, "end_header", 10)) break;
  }
  std::vector<float> p(3 * nv);
  if (fread(p.data(), 4, 3 * nv, f) != 3 * nv) { fprintf(stderr, "%s: truncated vertices\n", argv[1]); return 1; }
  std::vector<uint32_t> t; t.reserve(3 * nf);
  for (size_t i = 0; i < nf; ++i) {
    uint8_t n; int32_t v[3];
    if (fread(&n, 1, 1, f) != 1 || n != 3 || fread(v, 4, 3, f) != 3) { fprintf(stderr, "%s: face %zu is not a triangle (or truncated)\n", argv[1], i); return 1; }
    for (int k = 0; k < 3; ++k) if (v[k] < 0 || size_t(v[k]) >= nv) { fprintf(stderr, "%s: face %zu: vertex out of range\n", argv[1], i); return 1; }
    t.insert(t.end(), {uint32_t(v[0]), uint32_t(v[1]), uint32_t(v[2])});
  }
  fclose(f);
  for (int pass = 0; pass < 2; ++pass) {
    std::unordered_map<uint64_t, uint32_t> mid; mid.reserve(t.size() * 2);
    std::vector<uint32_t> o; o.reserve(t.size() * 4);
    auto m = [&](uint32_t a, uint32_t b) {
      uint64_t k = a < b ? (uint64_t(a) << 32 | b) : (uint64_t(b) << 32 | a);
      auto [it, fresh] = mid.emplace(k, uint32_t(p.size() / 3));
      if (fresh) for (int j = 0; j < 3; ++j) p.push_back(0.5f * (p[3 * size_t(a) + j] + p[3 * size_t(b) + j]));
      return it->second;
    };
    for (size_t i = 0; i < t.size(); i += 3) {
      uint32_t a = t[i], b = t[i + 1], c = t[i + 2];
      uint32_t ab = m(a, b), bc = m(b, c), ca = m(c, a);
      o.insert(o.end(), {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca});
    }
    t.swap(o);
  }
  FILE* w = fopen(argv[2], "wb");
  fprintf(w, "ply\nformat binary_little_endian 1.0\nelement vertex %zu\nproperty float x\nproperty float y\nproperty float z\nelement face %zu\nproperty list uchar int vertex_indices\nend_header\n", p.size() / 3, t.size() / 3);
  fwrite(p.data(), 4, p.size(), w);
  std::vector<uint8_t> buf; buf.reserve(13 * t.size() / 3);
  for (size_t i = 0; i < t.size(); i += 3) { buf.push_back(3); buf.insert(buf.end(), (uint8_t*)&t[i], (uint8_t*)&t[i] + 12); }
  fwrite(buf.data(), 1, buf.size(), w);
  fclose(w);
  printf("%zu vertices %zu faces\n", p.size() / 3, t.size() / 3);
}
