// What every bake does first, on a 4M-triangle sphere made in code: reading a binary PLY and
// cleaning it (each rank of a distributed bake repeats both, so their time bounds
// the speed-up); LOD_BENCH_MESH=FILE.ply takes a real mesh instead. Baselines in the same run:
//   BM_ReadBytes          the file's bytes into memory (the floor for BM_LoadPly)
//   BM_ReadHashParse      read whole, hashed, parsed: the baseline for BM_LoadPlyHashedStreamed
//                         (load_mesh_hashed: the same mesh and hash, streamed into the arrays)
//   BM_FaceGroupsSorted   repeated faces found by sorting (key, index) pairs (the former clean)
//   BM_FaceGroupsHashed   the same answer by hash groups (first_of_equal, the clean before)
//   BM_FaceGroupsByLeastCorner   by groups of one least corner (first_of_equal_grouped: what
//                         clean uses; a quarter of the memory, no hashing)
//   BM_Clean/indexed      clean_mesh of the indexed sphere (nothing to weld)
//   BM_Clean/soup         clean_mesh of the same triangles, three vertices each (all to weld)
//   BM_SurfaceBuild / BM_SurfaceQuery   the closest-point BVH over it: build, and queries;
//                         /sah (the former builder) is the baseline for /morton (the default)
//   BM_SurfaceParts       what an HLOD bake builds instead of BM_SurfaceBuild/morton (its
//                         baseline): 4^3 parts, each a cell grown by a sixteenth of its half-edge,
//                         listed in one pass and built one after another in the same memory
//                         (13.9M, one core: 0.98x of the one BVH's time, 1.18x its triangles;
//                         the bake's gain is the memory it does not take)
//   BM_EntryChecksumConcatenated / BM_EntryChecksumPieces   the cleaned-mesh cache entry's
//                         checksum: its arrays copied into one buffer and hashed (the former
//                         store), against hashed where they lie (BytesHasher, what it does now)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <compare>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "preprocess/first_of_equal.h"
#include "preprocess/mesh_clean.h"
#include "preprocess/mesh_io.h"
#include "preprocess/mesh_readers.h"
#include "preprocess/surface_error.h"
#include "runtime/bytes_hasher.h"
#include "runtime/lod_asset.h"
#include "vd_meshes.h"

namespace {

using namespace lod;

// LOD_BENCH_MESH=FILE.ply: that mesh instead (e.g. scripts/make-dragon-14m.sh's 13.9M).
const char* bench_mesh() {
  const char* f = std::getenv("LOD_BENCH_MESH");
  return f && *f ? f : nullptr;
}

const MeshData& sphere() {
  static const MeshData m = [] {
    MeshData d;
    if (!bench_mesh()) return test::vd_sphere(1000, 2000);  // 4.0M triangles, 2.0M vertices
    if (Status s = load_mesh(bench_mesh(), d); !s)
      std::fprintf(stderr, "%s\n", s.message.c_str()), std::exit(1);
    return d;
  }();
  return m;
}

MeshData soup_of(const MeshData& in) {
  MeshData m;
  m.source = "soup";
  for (uint32_t v : in.indices)
    m.positions.insert(m.positions.end(), &in.positions[3 * v], &in.positions[3 * v] + 3);
  for (size_t i = 0; i < in.indices.size(); ++i) m.indices.push_back(uint32_t(i));
  return m;
}

// The sphere as a binary PLY (float xyz, uchar/int face lists), as scanners write them.
const std::filesystem::path& ply_file() {
  static const std::filesystem::path path = [] {
    if (bench_mesh()) return std::filesystem::path(bench_mesh());
    const MeshData& m = sphere();
    auto p = std::filesystem::temp_directory_path() / "lodkit-bench-mesh-input.ply";
    std::ofstream f(p, std::ios::binary);
    f << "ply\nformat binary_little_endian 1.0\nelement vertex " << m.vertex_count()
      << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << m.triangle_count()
      << "\nproperty list uchar int vertex_indices\nend_header\n";
    f.write(reinterpret_cast<const char*>(m.positions.data()), std::streamsize(m.positions.size() * 4));
    for (size_t t = 0; t < m.triangle_count(); ++t) {
      const char three = 3;
      f.write(&three, 1);
      f.write(reinterpret_cast<const char*>(&m.indices[3 * t]), 12);
    }
    return p;
  }();
  return path;
}

void BM_ReadBytes(benchmark::State& state) {
  for (auto _ : state) {
    std::vector<uint8_t> bytes;
    if (!detail::read_mesh_file(ply_file(), bytes)) state.SkipWithError("cannot read the bench file");
    benchmark::DoNotOptimize(bytes.data());
  }
}

void BM_LoadPly(benchmark::State& state) {
  for (auto _ : state) {
    MeshData m;
    if (Status s = load_mesh(ply_file(), m); !s) state.SkipWithError(s.message.c_str());
    benchmark::DoNotOptimize(m.indices.data());
  }
  state.counters["triangles"] = double(sphere().triangle_count());
}

// What a bake did before the streamed read: the file whole, hashed, parsed (the baseline).
void BM_ReadHashParse(benchmark::State& state) {
  for (auto _ : state) {
    std::vector<uint8_t> bytes;
    if (!detail::read_mesh_file(ply_file(), bytes)) state.SkipWithError("cannot read the bench file");
    const uint64_t hash = hash_bytes(bytes.data(), bytes.size());
    MeshData m;
    if (Status s = load_mesh(ply_file(), std::move(bytes), m); !s) state.SkipWithError(s.message.c_str());
    benchmark::DoNotOptimize(hash);
    benchmark::DoNotOptimize(m.indices.data());
  }
}

// The same mesh and hash by load_mesh_hashed: the scanners' layout streamed into the arrays.
void BM_LoadPlyHashedStreamed(benchmark::State& state) {
  for (auto _ : state) {
    MeshData m;
    uint64_t hash = 0;
    if (Status s = load_mesh_hashed(ply_file(), m, hash); !s) state.SkipWithError(s.message.c_str());
    benchmark::DoNotOptimize(hash);
    benchmark::DoNotOptimize(m.indices.data());
  }
}

struct FaceKey {
  std::array<uint32_t, 3> v;
  auto operator<=>(const FaceKey&) const = default;
};

std::vector<FaceKey> face_keys() {
  const MeshData& m = sphere();
  std::vector<FaceKey> keys(m.triangle_count());
  for (size_t t = 0; t < keys.size(); ++t) {
    keys[t].v = {m.indices[3 * t], m.indices[3 * t + 1], m.indices[3 * t + 2]};
    std::sort(keys[t].v.begin(), keys[t].v.end());
  }
  return keys;
}

void BM_FaceGroupsSorted(benchmark::State& state) {
  const std::vector<FaceKey> keys = face_keys();
  std::vector<uint64_t> all(keys.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  for (auto _ : state) {
    std::vector<uint32_t> first(keys.size());
    benchmark::DoNotOptimize(detail::first_in_group_sorted(
        all.data(), all.size(), [&](size_t i) { return keys[i]; }, [&first](uint32_t i, uint32_t j) { first[i] = j; }));
  }
}

void BM_FaceGroupsHashed(benchmark::State& state) {
  const std::vector<FaceKey> keys = face_keys();
  for (auto _ : state) {
    std::vector<uint32_t> first;
    benchmark::DoNotOptimize(detail::first_of_equal(
        keys.size(), [&](size_t i) { return keys[i]; }, first));
  }
}

void BM_FaceGroupsByLeastCorner(benchmark::State& state) {
  const std::vector<FaceKey> keys = face_keys();
  const size_t vertices = sphere().vertex_count();
  for (auto _ : state) {
    std::vector<uint8_t> repeats(keys.size(), 0);
    benchmark::DoNotOptimize(detail::first_of_equal_grouped(
        keys.size(), vertices, [&](size_t i) { return keys[i].v[0]; }, [&](size_t i) { return keys[i]; },
        [&repeats](uint32_t i, uint32_t) { repeats[i] = 1; }, [&keys](uint32_t i) { __builtin_prefetch(&keys[i]); }));
  }
}

void BM_Clean(benchmark::State& state) {
  const MeshData input = state.range(0) ? soup_of(sphere()) : sphere();
  size_t welded = 0;
  for (auto _ : state) {
    state.PauseTiming();
    MeshData m = input;
    state.ResumeTiming();
    welded = clean_mesh(m).duplicate_vertices;
  }
  state.counters["welded"] = double(welded);
}

void BM_EntryChecksumConcatenated(benchmark::State& state) {
  const MeshData& m = sphere();
  for (auto _ : state) {
    std::vector<uint8_t> bytes;
    bytes.reserve(4 * (m.positions.size() + m.indices.size()));
    auto put = [&bytes](const auto& v) {
      const auto* p = reinterpret_cast<const uint8_t*>(v.data());
      bytes.insert(bytes.end(), p, p + 4 * v.size());
    };
    put(m.positions);
    put(m.indices);
    benchmark::DoNotOptimize(hash_bytes(bytes.data(), bytes.size()));
  }
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(4 * (m.positions.size() + m.indices.size())));
}

void BM_EntryChecksumPieces(benchmark::State& state) {
  const MeshData& m = sphere();
  for (auto _ : state) {
    BytesHasher h;
    h.add(m.positions.data(), 4 * m.positions.size());
    h.add(m.indices.data(), 4 * m.indices.size());
    benchmark::DoNotOptimize(h.finish());
  }
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(4 * (m.positions.size() + m.indices.size())));
}

// The closest-point BVH every HLOD bake builds over the original (and each rank over its part).
BvhBuilder builder_of(const benchmark::State& state) {
  return state.range(0) == 0 ? BvhBuilder::morton : BvhBuilder::sah;
}

void BM_SurfaceBuild(benchmark::State& state) {
  const MeshData& m = sphere();
  for (auto _ : state) {
    SurfaceDistance d(builder_of(state));
    if (!d.set_surface({m.positions.data(), m.vertex_count(), m.indices.data(), m.indices.size()}, "bench"))
      state.SkipWithError("the BVH was not built");
  }
  state.counters["triangles"] = double(m.triangle_count());
}

void BM_SurfaceParts(benchmark::State& state) {
  const MeshData& m = sphere();
  const TriangleMeshView whole{m.positions.data(), m.vertex_count(), m.indices.data(), m.indices.size()};
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t v = 0; v < m.vertex_count(); ++v)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], m.positions[3 * v + k]), hi[k] = std::max(hi[k], m.positions[3 * v + k]);
  SurfaceGrid grid;
  grid.edge = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]}) * 1.001f;
  std::copy_n(lo, 3, grid.lo);
  grid.n = 1024;
  const float half = grid.edge / 8, grow = half / 16;
  std::vector<SurfaceBox> boxes;
  for (int z = 0; z < 4; ++z)
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 4; ++x) {
        SurfaceBox b;
        const int at[3] = {x, y, z};
        for (int k = 0; k < 3; ++k) b.lo[k] = lo[k] + float(at[k]) * 2 * half - grow, b.hi[k] = b.lo[k] + 2 * (half + grow);
        boxes.push_back(b);
      }
  size_t held = 0;
  for (auto _ : state) {
    SurfacePartPlan plan;
    if (!plan_surface_parts(whole, grid, boxes, plan, "bench")) state.SkipWithError("not planned");
    SurfaceDistance part;
    std::vector<uint32_t> remap;
    held = 0;
    for (size_t b = 0; b < boxes.size(); ++b) {
      if (!part.set_surface_planned(whole, plan, b, remap, "bench part")) state.SkipWithError("a part was not built");
      held += part.triangles();
    }
  }
  state.counters["triangles"] = double(m.triangle_count());
  state.counters["held"] = double(held);  // the parts' triangles together
}

// Every 7th vertex pushed off the surface by 0.1 %, each query started from a 1 % radius.
void BM_SurfaceQuery(benchmark::State& state) {
  const MeshData& m = sphere();
  SurfaceDistance d(builder_of(state));
  if (!d.set_surface({m.positions.data(), m.vertex_count(), m.indices.data(), m.indices.size()}, "bench"))
    state.SkipWithError("the BVH was not built");
  std::vector<float> points;
  for (size_t v = 0; v < m.vertex_count(); v += 7)
    for (int k = 0; k < 3; ++k) points.push_back(m.positions[3 * v + k] * 1.001f);
  const std::vector<float> known(points.size() / 3, 0.01f);
  for (auto _ : state) {
    SurfaceError e;
    if (!d.from_points(points.data(), points.size() / 3, known.data(), e))
      state.SkipWithError("query failed");
    benchmark::DoNotOptimize(e.max);
  }
  state.counters["queries"] = double(points.size() / 3);
}

BENCHMARK(BM_ReadBytes)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_LoadPly)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_ReadHashParse)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_LoadPlyHashedStreamed)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_FaceGroupsSorted)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_FaceGroupsHashed)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_FaceGroupsByLeastCorner)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_Clean)->ArgName("soup")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_EntryChecksumConcatenated)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_EntryChecksumPieces)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_SurfaceBuild)->ArgName("sah")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_SurfaceParts)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_SurfaceQuery)->ArgName("sah")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(2);

}  // namespace

BENCHMARK_MAIN();
