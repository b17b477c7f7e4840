// load_mesh_hashed: a binary PLY in the scanners' layout is read from the file straight into the
// arrays; every other file (and every one of those the general reader must refuse) whole. Both
// ways give load_mesh's mesh or its refusal, and the hash of the file's bytes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "preprocess/mesh_io.h"
#include "preprocess/mesh_readers.h"
#include "runtime/lod_asset.h"  // hash_bytes
#include "test_support.h"

namespace lod {
namespace {

namespace fs = std::filesystem;

struct PlyParts {
  std::string header_extra;              // lines before end_header (after the face element)
  std::string index_type = "int";        // of the face list
  std::string count_type = "uchar";
  std::vector<float> xyz;
  std::vector<std::vector<uint32_t>> faces;
  std::string tail;                      // bytes after the faces
};

std::vector<uint8_t> ply_bytes(const PlyParts& p) {
  std::string h = "ply\nformat binary_little_endian 1.0\ncomment written by the test\nelement vertex " +
                  std::to_string(p.xyz.size() / 3) + "\nproperty float x\nproperty float y\nproperty float z\n" +
                  "element face " + std::to_string(p.faces.size()) + "\nproperty list " + p.count_type + " " +
                  p.index_type + " vertex_indices\n" + p.header_extra + "end_header\n";
  std::vector<uint8_t> b(h.begin(), h.end());
  const auto* v = reinterpret_cast<const uint8_t*>(p.xyz.data());
  b.insert(b.end(), v, v + 4 * p.xyz.size());
  for (const auto& f : p.faces) {
    b.push_back(uint8_t(f.size()));
    const auto* i = reinterpret_cast<const uint8_t*>(f.data());
    b.insert(b.end(), i, i + 4 * f.size());
  }
  b.insert(b.end(), p.tail.begin(), p.tail.end());
  return b;
}

// A grid of n x n quads as triangles.
PlyParts grid(int n) {
  PlyParts p;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) p.xyz.insert(p.xyz.end(), {float(x), float(y), 0.25f * float((x * y) % 3)});
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const uint32_t a = uint32_t(y * (n + 1) + x), b = a + 1, c = a + uint32_t(n) + 1, d = c + 1;
      p.faces.push_back({a, b, d});
      p.faces.push_back({a, d, c});
    }
  return p;
}

// load_mesh_hashed against load_mesh on the same file: the same status, mesh and hash.
void expect_same_as_load_mesh(const fs::path& file) {
  MeshData whole, streamed;
  const Status a = load_mesh(file, whole);
  uint64_t hash = 0;
  const Status b = load_mesh_hashed(file, streamed, hash);
  ASSERT_EQ(a.ok, b.ok) << file << ": " << a.message << " | " << b.message;
  EXPECT_EQ(a.message, b.message) << file;
  if (!a.ok) return;
  EXPECT_EQ(streamed.positions, whole.positions) << file;
  EXPECT_EQ(streamed.indices, whole.indices) << file;
  EXPECT_EQ(streamed.source, whole.source) << file;
  const std::vector<uint8_t> bytes = test::read_bytes(file);
  EXPECT_EQ(hash, hash_bytes(bytes.data(), bytes.size())) << file;
}

bool streamed(const fs::path& file) {
  detail::RawPolygons raw;
  uint64_t hash = 0;
  bool handled = false;
  EXPECT_TRUE(detail::read_plain_ply_file(file, raw, hash, handled)) << file;
  return handled;
}

TEST(PlainPlyFile, TheScannersLayoutIsStreamedIntoTheSameMeshAndHash) {
  const auto dir = test::temp_dir("plain_ply");
  // 300 x 300 quads: the faces span two of the reader's ~1 MB pieces.
  PlyParts big = grid(300);
  PlyParts unsigned_tail = grid(7);
  unsigned_tail.index_type = "uint32";
  unsigned_tail.count_type = "uint8";
  unsigned_tail.header_extra = "element extra 2\nproperty uchar flag\n";
  unsigned_tail.tail = std::string("\x01\x02", 2);
  const std::pair<const char*, PlyParts> cases[] = {{"big.ply", big}, {"tail.ply", unsigned_tail}};
  for (const auto& [name, parts] : cases) {
    test::write_bytes(dir / name, ply_bytes(parts));
    if (std::string(name) == "big.ply") {
      EXPECT_TRUE(streamed(dir / name)) << name;
    }
    expect_same_as_load_mesh(dir / name);
  }
  // A trailing element is not the scanners' layout: read whole, the same either way.
  EXPECT_FALSE(streamed(dir / "tail.ply"));
  const PlyParts g = grid(5);
  std::vector<uint32_t> idx;
  for (const auto& f : g.faces) idx.insert(idx.end(), f.begin(), f.end());
  ASSERT_TRUE(save_ply(dir / "save.ply", g.xyz.data(), g.xyz.size() / 3, idx.data(), idx.size()));
  EXPECT_TRUE(streamed(dir / "save.ply")) << "lodkit's own binary PLY";
  expect_same_as_load_mesh(dir / "save.ply");
}

// Whatever the general reader names, it names here too (the stream hands those files over).
TEST(PlainPlyFile, WhatTheReaderRefusesIsRefusedInTheSameWords) {
  const auto dir = test::temp_dir("plain_ply_bad");
  PlyParts quad = grid(3);
  quad.faces[4] = {0, 1, 5, 4};  // a quad among the triangles: fan-triangulated, as load_mesh does
  PlyParts nan = grid(3);
  nan.xyz[7] = std::numeric_limits<float>::quiet_NaN();
  PlyParts out_of_range = grid(3);
  out_of_range.faces[2][1] = 999;
  PlyParts negative = grid(3);
  negative.faces[1][0] = uint32_t(-5);  // an int index below 0
  const std::pair<const char*, PlyParts> cases[] = {
      {"quad.ply", quad}, {"nan.ply", nan}, {"range.ply", out_of_range}, {"negative.ply", negative}};
  for (const auto& [name, parts] : cases) {
    test::write_bytes(dir / name, ply_bytes(parts));
    expect_same_as_load_mesh(dir / name);
  }
  EXPECT_FALSE(streamed(dir / "quad.ply"));
  EXPECT_FALSE(streamed(dir / "nan.ply"));
  // Truncated anywhere: in the header, the vertices, the faces, the last byte.
  const std::vector<uint8_t> whole = ply_bytes(grid(4));
  for (size_t cut : {size_t(20), size_t(200), whole.size() / 2, whole.size() - 1}) {
    const fs::path f = dir / ("cut" + std::to_string(cut) + ".ply");
    test::write_bytes(f, std::vector<uint8_t>(whole.begin(), whole.begin() + std::ptrdiff_t(cut)));
    EXPECT_FALSE(streamed(f)) << cut;
    expect_same_as_load_mesh(f);
  }
  // Counts the file cannot hold, and a count that overflows 64 bits.
  for (const char* count : {"99999999", "18446744073709551615", "-3", "1e3"}) {
    std::vector<uint8_t> b = whole;
    const std::string from = "element face 32", to = std::string("element face ") + count;
    std::string text(b.begin(), b.end());
    text.replace(text.find(from), from.size(), to);
    const fs::path f = dir / (std::string("count") + std::to_string(std::strlen(count)) + ".ply");
    test::write_bytes(f, std::vector<uint8_t>(text.begin(), text.end()));
    EXPECT_FALSE(streamed(f)) << count;
    expect_same_as_load_mesh(f);
  }
  // Not a file to stream at all: a directory, a missing file (the same refusal as load_mesh).
  std::filesystem::create_directories(dir / "folder.ply");
  expect_same_as_load_mesh(dir / "folder.ply");
  expect_same_as_load_mesh(dir / "missing.ply");
}

// Other layouts are read whole, with the same result.
TEST(PlainPlyFile, OtherLayoutsAreReadWhole) {
  const auto dir = test::temp_dir("plain_ply_other");
  const std::vector<uint8_t> plain = ply_bytes(grid(3));
  std::string text(plain.begin(), plain.end());
  auto variant = [&](const char* name, const std::string& from, const std::string& to) {
    std::string t = text;
    t.replace(t.find(from), from.size(), to);
    test::write_bytes(dir / name, std::vector<uint8_t>(t.begin(), t.end()));
    EXPECT_FALSE(streamed(dir / name)) << name;
    expect_same_as_load_mesh(dir / name);
  };
  variant("short.ply", "property list uchar int", "property list uchar short");
  variant("big_endian.ply", "binary_little_endian", "binary_big_endian");
  variant("crlf.ply", "end_header\n", "end_header\r\n");
}

}  // namespace
}  // namespace lod
