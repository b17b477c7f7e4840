// The mesh readers on hostile input: regular files only, counts checked against
// the file before anything is allocated, BOMs skipped, bad indices reported the same way
// every run, and thousands of small hostile variants each refused or loaded quickly in
// bounded memory. Also the PLY/OFF/STL variants the single-pass readers must accept.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "preprocess/mesh_io.h"
#include "test_support.h"

namespace lod {
namespace {

namespace fs = std::filesystem;

std::vector<uint8_t> bytes_of(const std::string& s) { return {s.begin(), s.end()}; }

Status load_text(const std::string& name, const std::string& ext, const std::string& text, MeshData& m) {
  return load_mesh_from_memory(name, ext, reinterpret_cast<const uint8_t*>(text.data()), text.size(), m);
}

void expect_message(const Status& s, const std::string& needle) {
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find(needle), std::string::npos) << s.message;
}

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAsan = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAsan = true;
#else
constexpr bool kAsan = false;
#endif
#else
constexpr bool kAsan = false;
#endif

long max_rss_kb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

const char* kPlyHead =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n";

// ---- regular files only -------------------------------------------------------------------

TEST(MeshReaders, RefusesADirectoryByName) {
  const fs::path dir = test::temp_dir("rd-dir");
  fs::create_directories(dir / "cow.off");
  MeshData m;
  const Status s = load_mesh(dir / "cow.off", m);
  expect_message(s, "cow.off: is a directory");
}

TEST(MeshReaders, RefusesAFifoWithoutBlocking) {
  // The old loader opened the FIFO and waited for a writer forever.
  const fs::path dir = test::temp_dir("rd-fifo");
  const fs::path p = dir / "mesh.ply";
  fs::remove(p);
  ASSERT_EQ(mkfifo(p.c_str(), 0600), 0) << std::strerror(errno);
  MeshData m;
  const Status s = load_mesh(p, m);
  expect_message(s, "mesh.ply: is a FIFO");
}

TEST(MeshReaders, RefusesADevice) {
  // /dev/zero would never end; /dev/null reads as empty.
  for (const char* dev : {"/dev/zero", "/dev/null"}) {
    if (!fs::exists(dev)) continue;
    const fs::path dir = test::temp_dir("rd-dev");
    const fs::path link = dir / (std::string(dev + 5) + ".stl");
    fs::remove(link);
    fs::create_symlink(dev, link);
    MeshData m;
    expect_message(load_mesh(link, m), ": is a character device, not a regular file");
  }
}

TEST(MeshReaders, RefusesAMissingFileAndAFileUnderAFile) {
  const fs::path dir = test::temp_dir("rd-missing");
  test::write_text(dir / "plain.txt", "x");
  MeshData m;
  expect_message(load_mesh(dir / "plain.txt" / "m.obj", m), "m.obj: no such file");
  expect_message(load_mesh(dir / "none.off", m), "none.off: no such file");
}

TEST(MeshReaders, ObjMtllibNamingAFifoDoesNotBlock) {
  // OpenMesh's OBJ reader opened the file a "mtllib" line names (a FIFO there blocked the
  // load); materials are not used, so lodkit's reader never follows the line.
  const fs::path dir = test::temp_dir("rd-mtl");
  const fs::path fifo = dir / "materials.mtl";
  fs::remove(fifo);
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  const std::string text = "mtllib " + fifo.string() + "\n  mtllib " + fifo.string() +
                           "\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n";
  MeshData m;
  const Status s = load_text("mtl.obj", ".obj", text, m);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(m.triangle_count(), 1u);
}

// ---- byte-order marks ---------------------------------------------------------------------

TEST(MeshReaders, SkipsAUtf8BomBeforeAnObj) {
  // The BOM used to glue onto the first "v", dropping that vertex and shifting every index.
  const std::string body = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\n";
  MeshData plain, bom;
  ASSERT_TRUE(load_text("plain.obj", ".obj", body, plain).ok);
  const Status s = load_text("bom.obj", ".obj", "\xEF\xBB\xBF" + body, bom);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(bom.positions, plain.positions);
  EXPECT_EQ(bom.indices, plain.indices);
  EXPECT_EQ(bom.vertex_count(), 4u);
}

TEST(MeshReaders, SkipsAUtf8BomBeforeAnAsciiStl) {
  // Used to read as "binary STL declares 1695166496 triangles".
  const std::string body =
      "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n"
      "endsolid t\n";
  MeshData m;
  const Status s = load_text("bom.stl", ".stl", "\xEF\xBB\xBF" + body, m);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(m.triangle_count(), 1u);
  EXPECT_EQ(m.vertex_count(), 3u);
}

// ---- bad indices: the same message every run, the number as the file gives it ---------------

TEST(MeshReaders, ReportsIndexMinusOneTheSameWayEveryRun) {
  const fs::path dir = test::temp_dir("rd-minus1");
  test::write_text(dir / "m.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n");
  test::write_text(dir / "m.ply", std::string(kPlyHead) + "0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n");
  test::write_text(dir / "m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n");
  const std::pair<const char*, const char*> cases[] = {
      {"m.off", "face 0 references vertex -1 of 3"},
      {"m.ply", "face 0 references vertex -1 of 3"},
      {"m.obj", "face 0 references vertex -4 (relative) of 3 before it, on line 4"},
  };
  for (const auto& [name, needle] : cases) {
    std::string first;
    for (int run = 0; run < 5; ++run) {
      MeshData m;
      const Status s = load_mesh(dir / name, m);
      expect_message(s, needle);
      if (run == 0) first = s.message;
      EXPECT_EQ(s.message, first);
    }
  }
}

TEST(MeshReaders, ReportsHugeIndicesAsWritten) {
  MeshData m;
  expect_message(load_text("u.ply", ".ply",
                           "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                           "element face 1\nproperty list uchar uint vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n"
                           "3 0 1 4294967295\n",
                           m),
                 "face 0 references vertex 4294967295 of 3");
  expect_message(load_text("u.obj", ".obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2147483648\n", m),
                 "face 0 references vertex 2147483648 of 3 (OBJ numbering, from 1)");
  expect_message(load_text("u.off", ".off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 99999999999\n", m),
                 "face 0 references vertex 99999999999 of 3");
  // A negative OBJ index that reaches a vertex before the face is fine (-1 = the last one).
  ASSERT_TRUE(load_text("rel.obj", ".obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n", m).ok);
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2}));
}

// ---- what the issue found, one by one -----------------------------------------------------

TEST(MeshReaders, TinyFilesWithHugeCountsAreRefusedWithoutAllocating) {
  const long before = max_rss_kb();
  MeshData m;
  // 21 bytes that drove RSS to 8 GB.
  expect_message(load_text("h.off", ".off", "OFF\n999999999 9999999\n", m), "truncated or corrupt");
  expect_message(load_text("h.ply", ".ply",
                           "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
                           "property float y\nproperty float z\nelement face 4000000000\n"
                           "property list uchar int vertex_indices\nend_header\n\x01\x02",
                           m),
                 "element 'vertex' declares 4000000000 rows");
  expect_message(load_text("f.ply", ".ply",
                           "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
                           "property float y\nproperty float z\nelement face 1\n"
                           "property list uint int vertex_indices\nend_header\n" +
                               std::string(36, '\0') + "\xff\xff\xff\x7f",
                           m),
                 "truncated: the data ends inside face 0 of 1");
  expect_message(load_text("c.off", ".off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4000000000 0 1 2\n", m),
                 "declares 4000000000 corners");
  EXPECT_LT(max_rss_kb() - before, (64 + (kAsan ? 256 : 0)) * 1024);
}

TEST(MeshReaders, PlyElementWithoutPropertiesAndAHugeCountIsSkippedAtOnce) {
  // Spun forever in the old pre-check (2^64-1 rows of nothing).
  for (const char* format : {"ascii", "binary_little_endian"}) {
    const std::string head = std::string("ply\nformat ") + format +
                             " 1.0\nelement nothing 18446744073709551615\nelement vertex 3\nproperty float x\n"
                             "property float y\nproperty float z\nelement face 1\n"
                             "property list uchar int vertex_indices\nend_header\n";
    std::string body;
    if (std::string(format) == "ascii") {
      body = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    } else {
      const float xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
      body.assign(reinterpret_cast<const char*>(xyz), sizeof xyz);
      const int32_t tri[3] = {0, 1, 2};
      body += '\x03';
      body.append(reinterpret_cast<const char*>(tri), sizeof tri);
    }
    MeshData m;
    const auto t0 = std::chrono::steady_clock::now();
    const Status s = load_text("empty-element.ply", ".ply", head + body, m);
    ASSERT_TRUE(s.ok) << format << ": " << s.message;
    EXPECT_EQ(m.triangle_count(), 1u);
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));
  }
}

TEST(MeshReaders, UnknownPlyHeaderWordsAreSkippedOrRefusedNeverLooped) {
  // OpenMesh's header parser looped forever on an unknown word.
  MeshData m;
  const std::string rest =
      "element vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  ASSERT_TRUE(load_text("w.ply", ".ply", "ply\nformat ascii 1.0\nCreated by some exporter\n" + rest, m).ok);
  expect_message(load_text("w.ply", ".ply", "ply\nformat ascii 1.0\nfoo element vertex 3\n" + rest, m),
                 "line 3: unknown keyword 'foo' before 'element'");
  expect_message(load_text("w.ply", ".ply", "ply\nformat ascii 1.0\n" + rest.substr(0, 17) + "property floaty x\n", m),
                 "malformed property");
  expect_message(load_text("w.ply", ".ply", "ply\nformat utf8 1.0\n" + rest, m), "unknown format 'utf8'");
  expect_message(load_text("w.ply", ".ply", "ply\n" + rest, m), "no 'format' line");
}

// ---- fuzzing findings (scripts/fuzz.sh), each kept as a regression test ------------------

TEST(MeshReaders, FuzzObjCornerWithoutIndexAfterCarriageReturn) {
  // fuzz_obj, crash-2aeb9546: "f\r/1" is a face for iostreams (CR ends the keyword), and
  // OpenMesh's reader asserted (!vhandles.empty()) on the corner "/1": the process aborted.
  const uint8_t crash[] = {0x76, 0x20, 0x30, 0x20, 0x31, 0x20, 0x30, 0x0d, 0x0d, 0x0a, 0x66, 0x20, 0x20, 0x2d, 0x31, 0x20,
                           0x2d, 0x31, 0x2f, 0x0d, 0x0d, 0x0d, 0x0a, 0x66, 0x0d, 0x2f, 0x31, 0x0d, 0x31, 0x34, 0x0d, 0x12};
  MeshData m;
  const Status s = load_mesh_from_memory("crash.obj", ".obj", crash, sizeof crash, m);
  expect_message(s, "face 1 (line 3) has a corner without a valid vertex index ('/1')");
}

TEST(MeshReaders, ObjKeywordsEndAtAnyBlankAndLinesContinue) {
  MeshData m;
  Status s = load_text("cr.obj", ".obj", "v\t0 0 0\nv\r1 0 0\nv 0\f1 0\nf\t1\r2 3\n", m);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(m.positions, (std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}));
  s = load_text("cont.obj", ".obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 \\\n  3 \\  \n 4\nf 9\n", m);
  expect_message(s, "face 1 references vertex 9 of 4");
}

TEST(MeshReaders, ObjRepeatedCornersOfAFaceAreDropped) {
  // As OpenMesh's reader did: "f 1 2 3 4 1 2 3 4" is the quad 1 2 3 4 (2 triangles), also
  // for a long face (the set path) and with relative indices.
  MeshData m;
  std::string longface = "f";
  for (int r = 0; r < 10; ++r) longface += " 1 2 3 4";
  const Status s = load_text("rep.obj", ".obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n" + longface + "\nf 1 -3 2 -1\n", m);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 0, 1, 3}));
}

// ---- formats the single-pass readers read ---------------------------------------------------

TEST(MeshReaders, PlyBigEndianDoublesAndSkippedElementsAndProperties) {
  // Big-endian doubles, an element before the vertices, a list in the vertex element,
  // int counts with uint indices under the name "vertex_index", and a face property first.
  std::string head =
      "ply\nformat binary_big_endian 1.0\ncomment c\nobj_info i\nelement camera 2\nproperty short a\nproperty list uchar "
      "int l\nelement vertex 3\nproperty double x\nproperty uchar red\nproperty double y\nproperty double z\nproperty "
      "list ushort float uv\nelement face 1\nproperty uchar flags\nproperty list int uint vertex_index\nelement edge 9\n"
      "property int v1\nend_header\n";
  std::vector<uint8_t> b = bytes_of(head);
  auto put = [&b](const void* p, size_t n) {
    const auto* q = static_cast<const uint8_t*>(p);
    for (size_t i = 0; i < n; ++i) b.push_back(q[n - 1 - i]);  // big endian
  };
  for (int c = 0; c < 2; ++c) {
    const int16_t a = 7;
    put(&a, 2);
    b.push_back(1);
    const int32_t l = -5;
    put(&l, 4);
  }
  const double xyz[9] = {0, 0, 0, 2.5, 0, 0, 0, -3, 1};
  for (int v = 0; v < 3; ++v) {
    put(&xyz[3 * v], 8);
    b.push_back(200);
    put(&xyz[3 * v + 1], 8);
    put(&xyz[3 * v + 2], 8);
    const uint16_t n = uint16_t(v);
    put(&n, 2);
    for (int k = 0; k < v; ++k) {
      const float uv = 0.5f;
      put(&uv, 4);
    }
  }
  b.push_back(0);
  const int32_t n = 3;
  put(&n, 4);
  for (uint32_t i : {2u, 1u, 0u}) put(&i, 4);
  // The edge element is not there at all: nothing after the faces is read.
  MeshData m;
  const Status s = load_mesh_from_memory("be.ply", ".ply", b.data(), b.size(), m);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(m.positions, (std::vector<float>{0, 0, 0, 2.5f, 0, 0, 0, -3, 1}));
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{2, 1, 0}));
}

TEST(MeshReaders, PlyAsciiWithFacesBeforeVerticesAndCrLf) {
  const std::string text =
      "ply\r\nformat ascii 1.0\r\nelement face 1\r\nproperty list uchar int vertex_indices\r\nelement vertex 3\r\n"
      "property float x\r\nproperty float y\r\nproperty float z\r\nend_header\r\n4 0 1 2 1\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n";
  MeshData m;
  const Status s = load_text("crlf.ply", ".ply", text, m);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(m.triangle_count(), 2u);
  EXPECT_EQ(m.vertex_count(), 3u);
}

TEST(MeshReaders, PlyNegativeListLengthAndFloatIndicesAreRefused) {
  MeshData m;
  expect_message(load_text("n.ply", ".ply", std::string(kPlyHead) + "0 0 0\n1 0 0\n0 1 0\n-3 0 1 2\n", m),
                 "face 0 (line 13) has a bad list length '-3'");
  std::string head = kPlyHead;
  head.replace(head.find("uchar int"), 9, "uchar float");
  expect_message(load_text("f.ply", ".ply", head + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", m), "non-integer index type");
  expect_message(load_text("d.ply", ".ply", std::string(kPlyHead) + "0 0 0\n1 0 0\n0 1 1e39\n3 0 1 2\n", m),
                 "vertex 2 (line 12) has a non-finite coordinate (inf)");
}

TEST(MeshReaders, OffVariants) {
  MeshData m;
  ASSERT_TRUE(load_text("c.off", ".off", "COFF\n3 1 0\n0 0 0 1 0 0 1\n1 0 0 0 1 0 1\n0 1 0 0 0 1 1\n3 0 1 2 9 9 9\n", m).ok);
  EXPECT_EQ(m.triangle_count(), 1u);
  ASSERT_TRUE(load_text("n.off", ".off", "NOFF 3 1\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n", m).ok);
  ASSERT_TRUE(load_text("s.off", ".off", "STCNOFF\n# c\n3 1 0 # counts\n0 0 0 0 0 1 1 1 1 1 0 0\n1 0 0 0 0 1 1 1 1 1 1 0\n"
                                         "0 1 0 0 0 1 1 1 1 1 0 1\n3 0 1 2\n", m).ok);
  expect_message(load_text("4.off", ".off", "4OFF\n3 1 0\n", m), "4D vertices");
  expect_message(load_text("nd.off", ".off", "nOFF\n3\n3 1 0\n", m), "'nOFF'");
  expect_message(load_text("b.off", ".off", "OFF BINARY\n", m), "binary OFF is not supported");
  expect_message(load_text("x.off", ".off", "XOFF\n3 1 0\n", m), "not an OFF file (first word is 'XOFF')");
  expect_message(load_text("e.off", ".off", "OFF\n3 1 x\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", m), "bad edge count 'x'");
}

TEST(MeshReaders, StlAsciiAndBinaryWeldIdenticalCorners) {
  MeshData m;
  const std::string two =
      "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nendloop\nendfacet\n"
      "facet normal 0 0 1\nouter loop\nvertex -0 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid s\n";
  ASSERT_TRUE(load_text("w.stl", ".stl", two, m).ok);
  EXPECT_EQ(m.vertex_count(), 4u);
  EXPECT_EQ(m.triangle_count(), 2u);
  expect_message(load_text("t.stl", ".stl", two.substr(0, two.find("vertex 1 1 0\nvertex 0 1 0")), m),
                 "triangle 1 has only 1 of its 3 vertices");
  expect_message(load_text("v.stl", ".stl", "solid s\nvertex 0 0\n", m), "vertex without three numeric coordinates");
  expect_message(load_text("e.stl", ".stl", "solid s\nendsolid s\n", m), "has no faces");
}

// ---- every file under 1 KB: refused or loaded, quickly, in bounded memory -------------------

// Seeds: one small valid file per reader variant.
std::vector<std::pair<std::string, std::vector<uint8_t>>> seeds() {
  std::vector<std::pair<std::string, std::vector<uint8_t>>> s;
  s.emplace_back(".ply", bytes_of(std::string(kPlyHead) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"));
  {
    std::string h =
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
    const float xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    h.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
    const int32_t tri[3] = {0, 1, 2};
    h += '\x03';
    h.append(reinterpret_cast<const char*>(tri), sizeof tri);
    s.emplace_back(".ply", bytes_of(h));
  }
  s.emplace_back(".off", bytes_of("OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n"));
  s.emplace_back(".off", bytes_of("COFF 3 1 0\n0 0 0 1 1 1 1\n1 0 0 1 1 1 1\n0 1 0 1 1 1 1\n3 0 1 2\n"));
  s.emplace_back(".obj", bytes_of("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\nf -3 -2 -1\n"));
  s.emplace_back(".stl", bytes_of("solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                                  "endloop\nendfacet\nendsolid s\n"));
  {
    std::vector<uint8_t> b(80, 'x');
    const uint32_t n = 1;
    b.insert(b.end(), reinterpret_cast<const uint8_t*>(&n), reinterpret_cast<const uint8_t*>(&n) + 4);
    const float rec[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    b.insert(b.end(), reinterpret_cast<const uint8_t*>(rec), reinterpret_cast<const uint8_t*>(rec) + 48);
    b.push_back(0);
    b.push_back(0);
    s.emplace_back(".stl", b);
  }
  return s;
}

// Hostile variants of a seed, each under 1 KB: every truncation, every number token replaced
// by hostile numbers, garbage words inserted at every line start, NaN/inf inserted, bytes
// flipped to 0xFF / 0x00 at every position.
std::vector<std::vector<uint8_t>> hostile_variants(const std::vector<uint8_t>& seed) {
  std::vector<std::vector<uint8_t>> out;
  for (size_t n = 0; n < seed.size(); ++n) out.emplace_back(seed.begin(), seed.begin() + std::ptrdiff_t(n));
  const char* numbers[] = {"0", "-1", "-3", "4294967295", "4294967296", "2147483648", "9223372036854775807",
                           "18446744073709551615", "18446744073709551616", "99999999999999999999999", "nan", "inf",
                           "1e39", "-1e309", "0x10", "1.5"};
  for (size_t i = 0; i < seed.size(); ++i) {
    if (!std::isdigit(seed[i]) || (i > 0 && (std::isdigit(seed[i - 1]) || seed[i - 1] == '.'))) continue;
    size_t e = i;
    while (e < seed.size() && (std::isdigit(seed[e]) || seed[e] == '.')) ++e;
    for (const char* num : numbers) {
      std::vector<uint8_t> v(seed.begin(), seed.begin() + std::ptrdiff_t(i));
      v.insert(v.end(), num, num + std::strlen(num));
      v.insert(v.end(), seed.begin() + std::ptrdiff_t(e), seed.end());
      out.push_back(std::move(v));
    }
  }
  const char* words[] = {"garbage ", "element ", "property ", "end_header\n", "format ascii 1.0\n", "OFF ",
                         "solid ",   "vertex ",  "f ",         "v nan ",        "\xEF\xBB\xBF",   "#",
                         "\r",       "\n",       "element x 18446744073709551615\n", "property list uint int vertex_indices\n"};
  for (size_t i = 0; i <= seed.size(); ++i) {
    if (i != 0 && seed[i - 1] != '\n' && seed[i - 1] != ' ') continue;
    for (const char* w : words) {
      std::vector<uint8_t> v = seed;
      v.insert(v.begin() + std::ptrdiff_t(i), w, w + std::strlen(w));
      out.push_back(std::move(v));
    }
  }
  for (size_t i = 0; i < seed.size(); ++i)
    for (uint8_t b : {uint8_t(0xFF), uint8_t(0x00), uint8_t(0x7F)}) {
      std::vector<uint8_t> v = seed;
      v[i] = b;
      out.push_back(std::move(v));
    }
  return out;
}

TEST(MeshReaders, EverySmallHostileFileIsRefusedOrLoadedQuicklyInBoundedMemory) {
  const fs::path dir = test::temp_dir("rd-hostile");
  const long rss_before = max_rss_kb();
  size_t files = 0, loaded = 0, refused = 0;
  double slowest_ms = 0, total_ms = 0;
  std::string slowest;
  for (const auto& [ext, seed] : seeds()) {
    for (const std::vector<uint8_t>& v : hostile_variants(seed)) {
      ASSERT_LT(v.size(), 1024u);
      const fs::path p = dir / ("h" + ext);
      test::write_bytes(p, v);
      MeshData m;
      const auto t0 = std::chrono::steady_clock::now();
      const Status s = load_mesh(p, m);
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      ++files;
      total_ms += ms;
      if (ms > slowest_ms) slowest_ms = ms, slowest = ext + " " + std::to_string(v.size()) + " bytes";
      if (s.ok) {
        ++loaded;
        ASSERT_GT(m.triangle_count(), 0u);
        for (uint32_t i : m.indices) ASSERT_LT(i, m.vertex_count());
        for (float c : m.positions) ASSERT_TRUE(std::isfinite(c));
      } else {
        ++refused;
        ASSERT_NE(s.message.find("h" + ext), std::string::npos) << s.message;
      }
    }
  }
  const long growth_kb = max_rss_kb() - rss_before;
  std::cout << "  " << files << " hostile files under 1 KB: " << loaded << " loaded, " << refused << " refused; "
            << "mean " << total_ms / double(files) << " ms, slowest " << slowest_ms << " ms (" << slowest
            << "); peak RSS growth " << growth_kb << " KB\n";
  EXPECT_GT(loaded, 0u);
  EXPECT_GT(refused, 0u);
  // Peak RSS of the whole run bounds every single load's peak. AddressSanitizer keeps freed
  // blocks in its quarantine (256 MB by default), so there the bound allows for it; the
  // fuzz targets check single allocations against 64 MB under ASan (-malloc_limit_mb=64).
  EXPECT_LT(growth_kb, (64 + (kAsan ? 256 : 0)) * 1024);
}

}  // namespace
}  // namespace lod
