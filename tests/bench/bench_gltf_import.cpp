// glTF import speed (target: import of a 1M-triangle GLB <= 1.2x the time tinygltf
// alone takes to parse it). The GLB is made here with the project's writer: a torus of
// 1,001,112 triangles and 501,972 vertices with POSITION, NORMAL and TEXCOORD_0 (float) and
// u32 indices, 28 MB.
//
//   BM_TinyGltfParse   tinygltf::TinyGLTF::LoadBinaryFromFile (the file read, JSON parsed,
//                      the BIN chunk copied into a buffer), no image decoding
//   BM_LodImport       lod::load_gltf: that parse plus every check and the flattening into
//                      MeshData (positions, normals, uvs, indices, submeshes)
//   BM_ImportOverParse both in turn, each iteration; counter `cpu_ratio` = ours / tinygltf's
//                      in thread CPU time, the figure to quote (a shared machine's
//                      wall time is noisy; CPU time of one thread is not)
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <numbers>
#include <vector>

// The header part only: tinygltf's implementation is compiled into preprocess/gltf_io.cpp
// with these settings, and linked from there.
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include "preprocess/gltf_io.h"
#include "preprocess/gltf_write.h"

namespace {

namespace fs = std::filesystem;

fs::path g_file;

double thread_cpu_seconds() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// A (rings x segments) torus, uv-mapped once around each way (seams where u or v wraps).
bool write_torus_glb(const fs::path& file, int rings, int segments) {
  std::vector<float> pos, nrm, uv;
  std::vector<uint32_t> idx;
  const double R = 1.0, r = 0.35;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j) {
      const double a = 2 * std::numbers::pi * i / rings, b = 2 * std::numbers::pi * j / segments;
      const double ca = std::cos(a), sa = std::sin(a), cb = std::cos(b), sb = std::sin(b);
      pos.insert(pos.end(), {float((R + r * cb) * ca), float(r * sb), float((R + r * cb) * sa)});
      nrm.insert(nrm.end(), {float(cb * ca), float(sb), float(cb * sa)});
      uv.insert(uv.end(), {float(i) / float(rings), float(j) / float(segments)});
    }
  const auto at = [&](int i, int j) { return uint32_t(i * (segments + 1) + j); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) idx.insert(idx.end(), {at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i + 1, j)});
  lod::GltfMeshView v;
  v.name = "torus";
  v.positions = pos.data();
  v.normals = nrm.data();
  v.uvs = uv.data();
  v.vertex_count = pos.size() / 3;
  v.indices = idx.data();
  v.index_count = idx.size();
  const lod::Status s = lod::save_gltf(file, v);
  if (!s) std::fprintf(stderr, "bench_gltf_import: %s\n", s.message.c_str());
  return s.ok;
}

bool tinygltf_parse(tinygltf::Model& model) {
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  return loader.LoadBinaryFromFile(&model, &err, &warn, g_file.string());
}

void BM_TinyGltfParse(benchmark::State& state) {
  for (auto _ : state) {
    tinygltf::Model model;
    if (!tinygltf_parse(model)) state.SkipWithError("tinygltf failed");
    benchmark::DoNotOptimize(model.buffers.data());
  }
}

void BM_LodImport(benchmark::State& state) {
  size_t triangles = 0;
  for (auto _ : state) {
    lod::MeshData mesh;
    if (!lod::load_gltf(g_file, mesh)) state.SkipWithError("load_gltf failed");
    triangles = mesh.triangle_count();
  }
  state.counters["triangles"] = double(triangles);
}

void BM_ImportOverParse(benchmark::State& state) {
  double ours = 0, theirs = 0;
  for (auto _ : state) {
    double t0 = thread_cpu_seconds();
    {
      tinygltf::Model model;
      if (!tinygltf_parse(model)) state.SkipWithError("tinygltf failed");
    }
    theirs += thread_cpu_seconds() - t0;
    t0 = thread_cpu_seconds();
    {
      lod::MeshData mesh;
      if (!lod::load_gltf(g_file, mesh)) state.SkipWithError("load_gltf failed");
    }
    ours += thread_cpu_seconds() - t0;
  }
  state.counters["tinygltf_cpu_ms"] = 1e3 * theirs / double(state.iterations());
  state.counters["lod_cpu_ms"] = 1e3 * ours / double(state.iterations());
  state.counters["cpu_ratio"] = theirs > 0 ? ours / theirs : 0;
}

BENCHMARK(BM_TinyGltfParse)->Unit(benchmark::kMillisecond)->MinTime(2);
BENCHMARK(BM_LodImport)->Unit(benchmark::kMillisecond)->MinTime(2);
BENCHMARK(BM_ImportOverParse)->Unit(benchmark::kMillisecond)->Iterations(15);

}  // namespace

int main(int argc, char** argv) {
  g_file = fs::path(LOD_BINARY_DIR) / "bench-data" / "torus-1m.glb";
  std::error_code ec;
  fs::create_directories(g_file.parent_path(), ec);
  if (!write_torus_glb(g_file, 708, 707)) return 1;
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
