// libFuzzer target for one mesh format reader: the bytes go through load_mesh_from_memory
// (the same code load_mesh runs after reading a file), built once per format with
// -DLOD_FUZZ_EXT='".ply"' (".off", ".stl", ".obj", ".glb") by scripts/fuzz.sh.
//
// Checks beyond the sanitizers: a load either fails with a message naming the input, or
// gives a mesh whose indices are in range and whose coordinates are finite; for PLY, reading
// the same bytes from a file (load_mesh_hashed) agrees; cleaning the mesh leaves faces in
// range, none degenerate by index, no two on one corner set, the counts adding up, and a
// second clean with nothing to do.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include <unistd.h>

#include <string>

#include <algorithm>
#include <array>
#include <set>

#include "preprocess/mesh_clean.h"
#include "preprocess/mesh_io.h"
#include "runtime/bytes_hasher.h"

#ifndef LOD_FUZZ_EXT
#error "build with -DLOD_FUZZ_EXT='\".ply\"' (or .off, .stl, .obj, .glb)"
#endif

// PLY only: the same bytes as a file through load_mesh_hashed, whose scanners'-layout path reads
// the file itself (preprocess/plain_ply_file.cpp). It must agree with the reader above: loaded
// or refused alike, the same mesh, and the hash of the bytes.
void check_file_read(const uint8_t* data, size_t size, const lod::Status& from_memory, const lod::MeshData& expected) {
  if (std::string(LOD_FUZZ_EXT) != ".ply" || size == 0) return;
  static const std::string path = "/tmp/lod-fuzz-" + std::to_string(::getpid()) + ".ply";
  static const struct Gone {
    ~Gone() { std::remove(path.c_str()); }  // at exit
  } gone;
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f || std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
  lod::MeshData mesh;
  uint64_t hash = 0;
  const lod::Status s = lod::load_mesh_hashed(path, mesh, hash);
  if (s.ok != from_memory.ok) {
    std::fprintf(stderr, "file read %s, memory read %s: %s | %s\n", s.ok ? "loads" : "refuses",
                 from_memory.ok ? "loads" : "refuses", s.message.c_str(), from_memory.message.c_str());
    std::abort();
  }
  if (!s.ok) {
    if (s.message.find(path) == std::string::npos) std::abort();
    return;
  }
  lod::BytesHasher h;
  h.add(data, size);
  if (hash != h.finish() || mesh.positions != expected.positions || mesh.indices != expected.indices) std::abort();
}

void check_clean(lod::MeshData mesh) {
  const size_t triangles = mesh.triangle_count();
  const lod::CleanReport report = lod::clean_mesh(mesh);
  if (mesh.indices.size() % 3 != 0 || triangles - report.degenerate_faces - report.duplicate_faces != mesh.triangle_count())
    std::abort();
  std::set<std::array<uint32_t, 3>> corners;
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    std::array<uint32_t, 3> f = {mesh.indices[3 * t], mesh.indices[3 * t + 1], mesh.indices[3 * t + 2]};
    std::sort(f.begin(), f.end());
    if (f[2] >= mesh.vertex_count() || f[0] == f[1] || f[1] == f[2] || !corners.insert(f).second) std::abort();
  }
  const lod::MeshData once = mesh;
  if (lod::clean_mesh(mesh).changed() || mesh.indices != once.indices || mesh.positions != once.positions) std::abort();
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  lod::MeshData mesh;
  const lod::Status s = lod::load_mesh_from_memory("fuzz-input", LOD_FUZZ_EXT, data, size, mesh);
  check_file_read(data, size, s, mesh);
  if (!s.ok) {
    if (s.message.find("fuzz-input") == std::string::npos) {
      std::fprintf(stderr, "refusal does not name the input: %s\n", s.message.c_str());
      std::abort();
    }
    return 0;
  }
  if (mesh.indices.empty() || mesh.indices.size() % 3 != 0) std::abort();
  for (uint32_t i : mesh.indices)
    if (i >= mesh.vertex_count()) std::abort();
  for (float c : mesh.positions)
    if (!std::isfinite(c)) std::abort();
  check_clean(mesh);
  return 0;
}
