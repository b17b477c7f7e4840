// libFuzzer target for one mesh format reader: the bytes go through load_mesh_from_memory
// (the same code load_mesh runs after reading a file), built once per format with
// -DLOD_FUZZ_EXT='".ply"' (".off", ".stl", ".obj", ".glb") by scripts/fuzz.sh.
//
// Checks beyond the sanitizers: a load either fails with a message naming the input, or
// gives a mesh whose indices are in range and whose coordinates are finite.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "preprocess/mesh_io.h"

#ifndef LOD_FUZZ_EXT
#error "build with -DLOD_FUZZ_EXT='\".ply\"' (or .off, .stl, .obj, .glb)"
#endif

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  lod::MeshData mesh;
  const lod::Status s = lod::load_mesh_from_memory("fuzz-input", LOD_FUZZ_EXT, data, size, mesh);
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
  return 0;
}
