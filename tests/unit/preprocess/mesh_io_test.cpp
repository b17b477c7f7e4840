#include "preprocess/mesh_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <atomic>
#include <iostream>
#include <thread>

#include "test_support.h"

namespace lod {
namespace {

namespace fs = std::filesystem;

// A refusal must name the file (its file name at least) and leave `out` untouched.
void expect_refused(const fs::path& file, const std::string& needle = "") {
  MeshData out;
  out.source = "untouched";
  const Status s = load_mesh(file, out);
  EXPECT_FALSE(s.ok) << file;
  EXPECT_NE(s.message.find(file.filename().string()), std::string::npos) << s.message;
  if (!needle.empty()) {
    EXPECT_NE(s.message.find(needle), std::string::npos) << s.message;
  }
  EXPECT_EQ(out.source, "untouched");
  EXPECT_TRUE(out.indices.empty());
}

std::vector<uint8_t> binary_ply(uint32_t vertices, uint32_t faces, const std::vector<float>& xyz,
                                const std::vector<uint32_t>& tris) {
  std::string header = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(vertices) +
                       "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                       std::to_string(faces) + "\nproperty list uchar int vertex_indices\nend_header\n";
  std::vector<uint8_t> bytes(header.begin(), header.end());
  const auto* p = reinterpret_cast<const uint8_t*>(xyz.data());
  bytes.insert(bytes.end(), p, p + xyz.size() * 4);
  for (size_t t = 0; t < tris.size() / 3; ++t) {
    bytes.push_back(3);
    const auto* q = reinterpret_cast<const uint8_t*>(&tris[3 * t]);
    bytes.insert(bytes.end(), q, q + 12);
  }
  return bytes;
}

// Binary STL, one record per triangle (normal left zero), header not starting with "solid".
std::vector<uint8_t> binary_stl(const std::vector<float>& xyz, const std::vector<uint32_t>& tris) {
  std::vector<uint8_t> bytes(80, 'x');
  const uint32_t n = uint32_t(tris.size() / 3);
  bytes.insert(bytes.end(), reinterpret_cast<const uint8_t*>(&n), reinterpret_cast<const uint8_t*>(&n) + 4);
  for (uint32_t t = 0; t < n; ++t) {
    float rec[12] = {};
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) rec[3 + 3 * k + d] = xyz[3 * tris[3 * t + k] + d];
    const auto* p = reinterpret_cast<const uint8_t*>(rec);
    bytes.insert(bytes.end(), p, p + 48);
    bytes.push_back(0);
    bytes.push_back(0);
  }
  return bytes;
}

const std::vector<float> kQuadXyz = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
const std::vector<uint32_t> kQuadTris = {0, 1, 2, 0, 2, 3};

TEST(MeshIo, LoadsEachFormatIntoFlatArrays) {
  const fs::path dir = test::temp_dir("io-formats");
  test::write_text(dir / "quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
  test::write_text(dir / "quad.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n");
  test::write_text(dir / "quad.ply",
                   "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                   "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                   "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n");
  test::write_bytes(dir / "quadb.ply", binary_ply(4, 2, kQuadXyz, kQuadTris));
  test::write_text(dir / "quad.stl",
                   "solid q\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nendloop\n"
                   "endfacet\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\n"
                   "endfacet\nendsolid q\n");
  test::write_bytes(dir / "quadb.stl", binary_stl(kQuadXyz, kQuadTris));
  for (const char* name : {"quad.obj", "quad.off", "quad.ply", "quadb.ply", "quad.stl", "quadb.stl"}) {
    MeshData m;
    const Status s = load_mesh(dir / name, m);
    ASSERT_TRUE(s.ok) << name << ": " << s.message;
    EXPECT_EQ(m.triangle_count(), 2u) << name;
    EXPECT_EQ(m.vertex_count(), 4u) << name;
    EXPECT_EQ(m.source, (dir / name).string());
    for (uint32_t i : m.indices) EXPECT_LT(i, m.vertex_count());
  }
}

TEST(MeshIo, FanTriangulatesPolygons) {
  const fs::path dir = test::temp_dir("io-fan");
  test::write_text(dir / "hex.obj", "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 2 0\nv -1 1 0\nf 1 2 3 4 5 6\n");
  MeshData m;
  ASSERT_TRUE(load_mesh(dir / "hex.obj", m).ok);
  ASSERT_EQ(m.triangle_count(), 4u);
  for (size_t t = 0; t < 4; ++t) {
    EXPECT_EQ(m.indices[3 * t], 0u);
    EXPECT_EQ(m.indices[3 * t + 1], t + 1);
    EXPECT_EQ(m.indices[3 * t + 2], t + 2);
  }
}

TEST(MeshIo, KeepsNonManifoldFaces) {
  // Three triangles on one edge (0,1) and a repeated face: a TriMesh would refuse some.
  const fs::path dir = test::temp_dir("io-nm");
  test::write_text(dir / "fin.off",
                   "OFF\n5 4 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n3 0 1 2\n3 1 0 3\n3 0 1 4\n3 0 1 2\n");
  MeshData m;
  const Status s = load_mesh(dir / "fin.off", m);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(m.triangle_count(), 4u);
}

TEST(MeshIo, RefusesMissingFile) { expect_refused(test::temp_dir("io-missing") / "nothing.obj", "no such file"); }

TEST(MeshIo, RefusesUnknownExtension) {
  const fs::path dir = test::temp_dir("io-ext");
  test::write_text(dir / "mesh.xyz", "v 0 0 0\n");
  expect_refused(dir / "mesh.xyz", "unknown mesh format");
  test::write_text(dir / "noext", "v 0 0 0\n");
  expect_refused(dir / "noext", "unknown mesh format");
  test::write_text(dir / "mesh.ply.gz", "\x1f\x8b");
  expect_refused(dir / "mesh.ply.gz", "decompress it first");
}

TEST(MeshIo, RefusesEmptyFiles) {
  const fs::path dir = test::temp_dir("io-empty");
  for (const char* name : {"e.obj", "e.ply", "e.off", "e.stl"}) {
    test::write_text(dir / name, "");
    expect_refused(dir / name, "empty");
  }
}

TEST(MeshIo, RefusesPointsOnly) {
  const fs::path dir = test::temp_dir("io-points");
  test::write_text(dir / "p.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  expect_refused(dir / "p.obj", "no faces");
  test::write_text(dir / "p.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n");
  expect_refused(dir / "p.off", "no faces");
  test::write_text(dir / "p.ply",
                   "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                   "end_header\n0 0 0\n1 0 0\n0 1 0\n");
  expect_refused(dir / "p.ply", "no faces");
}

TEST(MeshIo, RefusesObjIndexOutOfRange) {
  const fs::path dir = test::temp_dir("io-range");
  test::write_text(dir / "x.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 9\n");
  expect_refused(dir / "x.obj", "face 1 references vertex 9 of 4 (OBJ numbering, from 1)");
  test::write_text(dir / "zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
  expect_refused(dir / "zero.obj", "face 0 (line 4) has a corner without a valid vertex index ('0')");
}

TEST(MeshIo, RefusesOffAndPlyIndexOutOfRange) {
  const fs::path dir = test::temp_dir("io-range2");
  test::write_text(dir / "x.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 7\n");
  expect_refused(dir / "x.off", "face 1 references vertex 7 of 3");
  test::write_bytes(dir / "x.ply", binary_ply(4, 2, kQuadXyz, {0, 1, 2, 0, 2, 90211}));
  expect_refused(dir / "x.ply", "face 1 references vertex 90211 of 4");
}

TEST(MeshIo, BinaryPlyTrianglesThenAPolygonKeepEveryFaceInOrder) {
  // Triangles are read straight into 32-bit corners until a face is not one; from there the
  // general reader goes on with what was read so far.
  const fs::path dir = test::temp_dir("io-ply-spill");
  std::vector<uint8_t> bytes = binary_ply(5, 4, {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 2, 0, 0}, {0, 1, 2, 0, 2, 3});
  auto face = [&bytes](std::initializer_list<uint32_t> corners) {
    bytes.push_back(uint8_t(corners.size()));
    for (uint32_t v : corners)
      bytes.insert(bytes.end(), reinterpret_cast<const uint8_t*>(&v), reinterpret_cast<const uint8_t*>(&v) + 4);
  };
  face({1, 4, 2, 0});  // a quad, then one more triangle
  face({3, 2, 4});
  test::write_bytes(dir / "mixed.ply", bytes);
  MeshData m;
  ASSERT_TRUE(load_mesh(dir / "mixed.ply", m).ok);
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 1, 4, 2, 1, 2, 0, 3, 2, 4}));
}

TEST(MeshIo, BinaryPlyNegativeIndexIsQuotedAsWritten) {
  const fs::path dir = test::temp_dir("io-ply-negative");
  test::write_bytes(dir / "neg.ply", binary_ply(4, 2, kQuadXyz, {0, 1, 2, 0, 2, uint32_t(-1)}));
  expect_refused(dir / "neg.ply", "face 1 references vertex -1 of 4");
}

TEST(MeshIo, RefusesNonFiniteCoordinates) {
  const fs::path dir = test::temp_dir("io-nan");
  test::write_text(dir / "x.obj", "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n");
  expect_refused(dir / "x.obj", "vertex 1 (line 2) has a non-finite coordinate (nan)");
  test::write_text(dir / "x.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 inf 0\n3 0 1 2\n");
  expect_refused(dir / "x.off", "vertex 2 (line 5) has a non-finite coordinate (inf)");
  test::write_text(dir / "a.ply",
                   "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                   "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                   "0 0 0\n1 0 0\n0 1 nan\n3 0 1 2\n");
  expect_refused(dir / "a.ply", "non-finite");
  std::vector<float> xyz = kQuadXyz;
  xyz[7] = std::nanf("");
  test::write_bytes(dir / "b.ply", binary_ply(4, 2, xyz, kQuadTris));
  expect_refused(dir / "b.ply", "vertex 2 has a non-finite coordinate (nan)");
  xyz[7] = -INFINITY;
  test::write_bytes(dir / "c.ply", binary_ply(4, 2, xyz, kQuadTris));
  expect_refused(dir / "c.ply", "vertex 2 has a non-finite coordinate (-inf)");
}

TEST(MeshIo, RefusesTruncatedBinaryPlyAtEveryLength) {
  const fs::path dir = test::temp_dir("io-trunc-bin");
  const std::vector<uint8_t> full = binary_ply(4, 2, kQuadXyz, kQuadTris);
  MeshData m;
  test::write_bytes(dir / "full.ply", full);
  ASSERT_TRUE(load_mesh(dir / "full.ply", m).ok);
  for (size_t n = 0; n < full.size(); ++n) {
    const std::vector<uint8_t> cut(full.begin(), full.begin() + std::ptrdiff_t(n));
    test::write_bytes(dir / "cut.ply", cut);
    expect_refused(dir / "cut.ply");
  }
}

TEST(MeshIo, RefusesTruncatedAsciiPly) {
  const fs::path dir = test::temp_dir("io-trunc-ascii");
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
  test::write_text(dir / "faces.ply", head + "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n");
  expect_refused(dir / "faces.ply", "truncated");
  test::write_text(dir / "verts.ply", head + "0 0 0\n1 0 0\n");
  expect_refused(dir / "verts.ply", "truncated");
  test::write_text(dir / "header.ply", "ply\nformat ascii 1.0\nelement vertex 4\n");
  expect_refused(dir / "header.ply", "end_header");
}

TEST(MeshIo, RefusesValuesThatAreNotWholeNumbers) {
  // iostreams read "2-1" as 2 and then -1 as the next face's corner count: OpenMesh would
  // then try to read four billion corners.
  const fs::path dir = test::temp_dir("io-tokens");
  test::write_text(dir / "x.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2-1\n3 0 2 3\n");
  expect_refused(dir / "x.off", "face 0 (line 7) has a vertex index that is not an integer ('2-1')");
  test::write_text(dir / "y.off", "OFF\n3 1 0\n0 0 0\n1 0x 0\n0 1 0\n3 0 1 2\n");
  expect_refused(dir / "y.off", "vertex 1 (line 4) has a coordinate that is not a number ('0x')");
  test::write_text(dir / "z.ply",
                   "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                   "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                   "0 0 0\n1 0 0\n0 1 0\n3 0 1 2-1\n");
  expect_refused(dir / "z.ply", "face 0 (line 13) has a value that is not an integer ('2-1')");
}

TEST(MeshIo, RefusesTruncatedOffAndStlAndNanStl) {
  const fs::path dir = test::temp_dir("io-trunc-off");
  test::write_text(dir / "x.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n");
  expect_refused(dir / "x.off", "truncated");
  test::write_text(dir / "huge.off", "OFF\n353535235358 6 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  expect_refused(dir / "huge.off", "353535235358");
  std::vector<uint8_t> stl = binary_stl(kQuadXyz, kQuadTris);
  stl.resize(stl.size() - 1);
  test::write_bytes(dir / "x.stl", stl);
  expect_refused(dir / "x.stl", "truncated");
  std::vector<float> nan_xyz = kQuadXyz;
  nan_xyz[4] = NAN;
  test::write_bytes(dir / "nan.stl", binary_stl(nan_xyz, kQuadTris));
  expect_refused(dir / "nan.stl", "non-finite");
}

TEST(MeshIo, RefusesObjCornersWithoutAVertexIndex) {
  // OpenMesh's OBJ reader asserts (aborting the process) on such a corner.
  const fs::path dir = test::temp_dir("io-corner");
  test::write_text(dir / "c.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf /1/1 2 3\n");
  expect_refused(dir / "c.obj", "face 0 (line 5) has a corner without a valid vertex index ('/1/1')");
  test::write_text(dir / "d.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n");
  expect_refused(dir / "d.obj", "('x')");
}

TEST(MeshIo, RefusesMalformedPlyHeaders) {
  // OpenMesh's PLY header parser can spin forever on these; each is refused up front.
  const fs::path dir = test::temp_dir("io-header");
  const std::string props = "property float x\nproperty float y\nproperty float z\n";
  const std::string tail = "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const struct {
    const char* name;
    std::string text;
    const char* needle;
  } cases[] = {
      {"version.ply", "ply\nformat ascii ment VCG\nelement vertex 3\n" + props + tail, "line 2: malformed format line"},
      {"keyword.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperoat x property\n" + props + tail, "line 4: unknown keyword 'properoat'"},
      {"type.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty floot x\nproperty float y\nproperty float z\n" + tail, "line 4: malformed property"},
      {"list.ply", "ply\nformat ascii 1.0\nelement vertex 3\n" + props + "element face 1\nproperty list uchar int1vertex_indices\nend_header\n", "line 8: malformed list property"},
      {"count.ply", "ply\nformat ascii 1.0\nelement vertex -3\n" + props + tail, "bad count '-3'"},
      {"noindex.ply", "ply\nformat ascii 1.0\nelement vertex 3\n" + props + "element face 1\nproperty list uchar int corners\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "no 'vertex_indices'"},
      {"magic.ply", "plx\nformat ascii 1.0\n", "not a PLY file"},
  };
  for (const auto& c : cases) {
    test::write_text(dir / c.name, c.text);
    expect_refused(dir / c.name, c.needle);
  }
}

TEST(MeshIo, RefusesPlyTristripsClearly) {
  const fs::path dir = test::temp_dir("io-strips");
  test::write_text(dir / "s.ply",
                   "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                   "element tristrips 1\nproperty list int int vertex_indices\nend_header\n"
                   "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 3 2\n");
  expect_refused(dir / "s.ply", "tristrips");
}

TEST(MeshIo, KeepsOpenMeshChatterOffTheTerminal) {
  // An undefined material makes OpenMesh's OBJ reader complain on omerr(); the load still
  // succeeds and nothing reaches std::cerr.
  const fs::path dir = test::temp_dir("io-quiet");
  test::write_text(dir / "m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl nothing\nf 1 2 3\n");
  testing::internal::CaptureStderr();
  MeshData m;
  const Status s = load_mesh(dir / "m.obj", m);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_TRUE(s.ok) << s.message;
  EXPECT_EQ(err, "");
}

TEST(MeshIo, SavePlyRoundTrips) {
  const fs::path dir = test::temp_dir("io-save");
  ASSERT_TRUE(save_ply(dir / "q.ply", kQuadXyz.data(), 4, kQuadTris.data(), kQuadTris.size()).ok);
  MeshData m;
  ASSERT_TRUE(load_mesh(dir / "q.ply", m).ok);
  EXPECT_EQ(m.positions, kQuadXyz);
  EXPECT_EQ(m.indices, kQuadTris);
  const std::vector<uint32_t> bad = {0, 1, 4};
  const Status s = save_ply(dir / "bad.ply", kQuadXyz.data(), 4, bad.data(), bad.size());
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("references vertex 4 of 4"), std::string::npos) << s.message;
}

TEST(MeshIo, LoadsConcurrentlyWithTheSameResults) {
  // OpenMesh's readers are singletons with per-read state: loads from several threads must
  // still each get their own mesh.
  const fs::path dir = test::temp_dir("io-threads");
  test::write_text(dir / "a.off", test::sphere_off(20, 30));
  test::write_bytes(dir / "b.ply", binary_ply(4, 2, kQuadXyz, kQuadTris));
  MeshData ref_a, ref_b;
  ASSERT_TRUE(load_mesh(dir / "a.off", ref_a).ok);
  ASSERT_TRUE(load_mesh(dir / "b.ply", ref_b).ok);
  std::vector<std::thread> threads;
  std::atomic<int> mismatches{0};
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int i = 0; i < 10; ++i) {
        MeshData m;
        const bool a = (t + i) % 2 == 0;
        if (!load_mesh(dir / (a ? "a.off" : "b.ply"), m).ok || m.indices != (a ? ref_a : ref_b).indices ||
            m.positions != (a ? ref_a : ref_b).positions)
          ++mismatches;
      }
    });
  for (std::thread& th : threads) th.join();
  EXPECT_EQ(mismatches.load(), 0);
}

TEST(MeshIo, SurvivesMutatedFiles) {
  // Seeded mutation of small valid files (byte flips, cuts, inserted tokens such as "nan"
  // or "/"): every result is either a valid mesh or a refusal naming the file. A crash or
  // hang here is a loader bug (OpenMesh aborts or spins on some inputs it is never given).
  const fs::path dir = test::temp_dir("io-mutate");
  std::vector<std::pair<std::string, std::vector<uint8_t>>> seeds;
  auto text = [](const std::string& s) { return std::vector<uint8_t>(s.begin(), s.end()); };
  seeds.emplace_back(".obj", text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\nf 1 3 4\n"));
  seeds.emplace_back(".off", text("OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n"));
  seeds.emplace_back(".ply", text("ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                                  "property float z\nelement face 2\nproperty list uchar int vertex_indices\n"
                                  "end_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n"));
  seeds.emplace_back(".ply", binary_ply(4, 2, kQuadXyz, kQuadTris));
  seeds.emplace_back(".stl", binary_stl(kQuadXyz, kQuadTris));
  const char* tokens[] = {"nan", "-1", "0", "/", "4294967295", "99999999999", " ", "\n", "inf", "1e39", "//", "f "};
  uint64_t state = 0x9E3779B97F4A7C15ull;
  auto next = [&state] {
    state ^= state << 13, state ^= state >> 7, state ^= state << 17;
    return state;
  };
  size_t loaded = 0, refused = 0;
  for (const auto& [ext, base] : seeds)
    for (int i = 0; i < 200; ++i) {
      std::vector<uint8_t> b = base;
      const uint64_t kind = next() % 4;
      for (uint64_t k = 0, n = 1 + next() % 3; k < n && !b.empty(); ++k) {
        const size_t pos = next() % b.size();
        if (kind == 0) {
          b[pos] = uint8_t(next());
        } else if (kind == 1) {
          b.resize(pos);
        } else if (kind == 2) {
          const std::string t = tokens[next() % std::size(tokens)];
          b.insert(b.begin() + std::ptrdiff_t(pos), t.begin(), t.end());
        } else {
          b.erase(b.begin() + std::ptrdiff_t(pos), b.begin() + std::ptrdiff_t(std::min(b.size(), pos + 1 + next() % 8)));
        }
      }
      const fs::path p = dir / ("m" + ext);
      test::write_bytes(p, b);
      MeshData m;
      const Status s = load_mesh(p, m);
      if (s.ok) {
        ++loaded;
        ASSERT_GT(m.triangle_count(), 0u);
        for (uint32_t v : m.indices) ASSERT_LT(v, m.vertex_count());
        for (float c : m.positions) ASSERT_TRUE(std::isfinite(c));
      } else {
        ++refused;
        ASSERT_NE(s.message.find("m" + ext), std::string::npos) << s.message;
      }
    }
  EXPECT_GT(loaded, 0u);
  EXPECT_GT(refused, 0u);
}

TEST(MeshIo, HandlesEveryEdgeCaseFileWithoutCrashing) {
  if (test::shared_meshes().empty() || !fs::exists(test::shared_meshes() / "edge-cases"))
    GTEST_SKIP() << "needs ../shared/data/meshes/edge-cases (absent on this machine)";
  size_t files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(test::shared_meshes() / "edge-cases")) {
    if (!entry.is_regular_file()) continue;
    const fs::path& p = entry.path();
    ++files;
    MeshData m;
    const Status s = load_mesh(p, m);
    if (s.ok) {
      EXPECT_GT(m.triangle_count(), 0u) << p;
      for (uint32_t i : m.indices) ASSERT_LT(i, m.vertex_count()) << p;
      for (float c : m.positions) ASSERT_TRUE(std::isfinite(c)) << p;
    } else {
      EXPECT_NE(s.message.find(p.filename().string()), std::string::npos) << s.message;
    }
    std::cout << "  " << p.filename().string() << ": "
              << (s.ok ? "loaded " + std::to_string(m.triangle_count()) + " triangles" : s.message) << "\n";
  }
  EXPECT_GT(files, 0u);
}

struct RealMesh {
  const char* file;
  size_t vertices;
  size_t triangles;
};

TEST(MeshIo, LoadsRealMeshesWithTheirPublishedCounts) {
  // Counts from ../shared/data/meshes/STATS.jsonl; the dragons and the buddha contain
  // non-manifold and duplicate faces, which the loader must keep.
  const RealMesh meshes[] = {{"stanford-bunny.obj", 35947, 69451},
                             {"cow.obj", 2903, 5804},
                             {"stanford-dragon-res3.ply", 22998, 47794},
                             {"stanford-dragon-res4.ply", 5205, 11102},
                             {"stanford-dragon-res2.ply", 100250, 202520},
                             {"happy-buddha-res3.ply", 32328, 67240},
                             {"horse.ply", 48485, 96966},
                             {"teapot.obj", 3644, 6320},
                             {"spot.obj", 3225, 5856},  // 2,930 positions; one vertex per distinct v/vt (uv seams)
                             {"fandisk.obj", 6475, 12946},
                             {"mountain.obj", 25600, 50562},
                             {"rocker-arm.obj", 10044, 20088},
                             {"stanford-armadillo-100k.obj", 49990, 99976},
                             {"stanford-dragon.ply", 437645, 871414}};
  size_t checked = 0;
  for (const RealMesh& r : meshes) {
    const fs::path p = test::shared_meshes() / r.file;
    if (test::shared_meshes().empty() || !fs::exists(p)) continue;
    MeshData m;
    const Status s = load_mesh(p, m);
    ASSERT_TRUE(s.ok) << s.message;
    EXPECT_EQ(m.triangle_count(), r.triangles) << r.file;
    EXPECT_EQ(m.vertex_count(), r.vertices) << r.file;
    ++checked;
  }
  if (checked == 0) GTEST_SKIP() << "needs ../shared/data/meshes (absent on this machine)";
}

TEST(MeshIo, IgeaTristripsAreRefusedClearly) {
  LOD_REQUIRE_SHARED_MESH(p, "igea-tristrips.ply");
  MeshData m;
  const Status s = load_mesh(p, m);
  // OpenMesh's PLY reader has no tristrips support; the message must say so.
  ASSERT_FALSE(s.ok);
  EXPECT_NE(s.message.find("tristrips"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("igea-tristrips.ply"), std::string::npos) << s.message;
}

}  // namespace
}  // namespace lod
