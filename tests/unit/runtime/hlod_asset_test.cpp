// The .hlod file: round trips, one node read alone, and every truncation and flipped byte
// refused (by the checksums, or by validation when the checksum is recomputed).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <thread>

#include "runtime/hlod_asset.h"
#include "runtime/lod_asset.h"  // hash_bytes
#include "test_support.h"
#include "unit/runtime/truncation_checks.h"

namespace lod {
namespace {

// `triangles` fan triangles around vertex 0 of a range with triangles + 2 vertices.
LodLevel add_fan(HlodPayload& p, uint32_t triangles, float shift) {
  LodLevel r;
  r.first_vertex = uint32_t(p.positions.size() / 3);
  r.vertex_count = triangles + 2;
  r.first_index = uint32_t(p.indices.size());
  r.index_count = 3 * triangles;
  r.level = level_of_triangles(triangles);
  for (uint32_t v = 0; v < triangles + 2; ++v) {
    const float a = 0.25f * float(v) + shift;
    p.positions.insert(p.positions.end(), {a, 1 - a, a * a});
    p.normals.insert(p.normals.end(), {0, 1, -0.0f});
  }
  for (uint32_t f = 0; f < triangles; ++f) p.indices.insert(p.indices.end(), {0u, f + 1, f + 2});
  return r;
}

// A node with fan layers of `tris` triangles, errors `errors`, and a patch of `patch` triangles.
void add_node(HlodTree& t, std::vector<HlodPayload>& payloads, std::vector<uint32_t> tris, std::vector<float> errors,
              uint32_t patch) {
  HlodNode n;
  HlodPayload p;
  n.layer_count = uint8_t(tris.size());
  for (size_t k = 0; k < tris.size(); ++k) {
    LodLevel r = add_fan(p, tris[k], 0.01f * float(k));
    r.error = errors[k];
    p.layers.push_back(r);
    n.layers[k] = {tris[k], tris[k] + 2, errors[k]};
  }
  p.boundary = add_fan(p, patch, 0.5f);
  n.boundary_triangles = patch;
  n.boundary_vertices = patch ? patch + 2 : 0;
  if (!patch) {  // an empty range has no vertices
    p.positions.resize(3 * size_t(p.boundary.first_vertex));
    p.normals.resize(p.positions.size());
    p.boundary.vertex_count = 0;
  }
  n.bounds = {{0.5f, 0.25f, -1}, 3};
  n.resident_bytes = 4 * (p.positions.size() + p.normals.size() + p.indices.size());
  t.nodes.push_back(n);
  payloads.push_back(std::move(p));
}

// Root (inner: octants 0 and 6) -> a leaf and an inner node (octant 3) -> a leaf.
struct Sample {
  HlodTree tree;
  std::vector<HlodPayload> payloads;
};
Sample sample() {
  Sample s;
  s.tree.name = "bunny";
  s.tree.source_hash = 0x0123456789abcdefull;
  s.tree.min_verts = 12;
  s.tree.source_triangles = 40;
  s.tree.box_center[0] = 0.5f, s.tree.box_center[1] = -2, s.tree.box_center[2] = 1e-40f;  // a denormal
  s.tree.box_half = 4;
  add_node(s.tree, s.payloads, {6, 3, 1}, {0.5f, 0.75f, 1.0f}, 3);
  add_node(s.tree, s.payloads, {5, 2}, {0, 0.25f}, 0);
  add_node(s.tree, s.payloads, {4, 2, 1}, {0.25f, 0.25f, 0.5f}, 2);
  add_node(s.tree, s.payloads, {7, 3, 1}, {0, 0.125f, 0.25f}, 0);
  HlodTree& t = s.tree;
  t.nodes[0].child_mask = 0b01000001, t.nodes[0].child_count = 2, t.nodes[0].first_child = 1;
  t.nodes[1].parent = 0, t.nodes[1].depth = 1;
  t.nodes[2].parent = 0, t.nodes[2].depth = 1;
  t.nodes[2].child_mask = 0b00001000, t.nodes[2].child_count = 1, t.nodes[2].first_child = 3;
  t.nodes[3].parent = 2, t.nodes[3].depth = 2;
  return s;
}

// The sample with texture coordinates, two materials (one textured from a file, one from an
// image embedded in the tree) and each range's triangles in two material runs (its first third
// the default material, the rest alternating 0 and 1).
Sample textured_sample() {
  Sample s = sample();
  s.tree.uvs = true;
  s.tree.material_count = 2;
  s.tree.texture_base = "/data/models";
  ChainMaterial a, b;
  a.name = "bark";
  a.base_color_texture = "bark%20diffuse.png";
  a.base_color[1] = 0.5f;
  b.name = "leaf";
  b.roughness = 0.25f;
  b.double_sided = true;
  b.base_color_texture = embedded_image_uri(0);
  s.tree.materials = {a, b};
  // A PNG signature and a few bytes: the reader checks signatures, not pixels.
  EmbeddedImage png;
  png.type = ImageType::png;
  png.bytes = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a, 0, 0, 0, 13, 'I', 'H', 'D', 'R'};
  s.tree.images = {png};
  for (size_t i = 0; i < s.payloads.size(); ++i) {
    HlodPayload& p = s.payloads[i];
    HlodNode& n = s.tree.nodes[i];
    for (size_t v = 0; v < p.positions.size() / 3; ++v) p.uvs.insert(p.uvs.end(), {0.125f * float(v % 9), 1 - 0.0625f * float(v % 5)});
    const uint32_t ranges = uint32_t(p.layers.size()) + 1;
    for (uint32_t r = 0; r < ranges; ++r) {
      const LodLevel& range = r < p.layers.size() ? p.layers[r] : p.boundary;
      const uint32_t tris = range.index_count / 3, first = tris / 3;
      if (first) p.runs.push_back({r, 0, 3 * first, -1});
      if (tris > first) p.runs.push_back({r, 3 * first, 3 * (tris - first), int32_t((i + r) % 2)});
    }
    n.uvs = true;
    n.material_runs = uint32_t(p.runs.size());
    n.layers[0].uv_error = 0.0f;
    if (n.layer_count > 1) n.layers[1].uv_error = 0.03125f * float(i + 1);
    n.resident_bytes = hlod_resident_bytes(n);
  }
  return s;
}

// The textured sample with a second uv set and vertex colours (linear RGBA), and their errors.
Sample coloured_sample() {
  Sample s = textured_sample();
  s.tree.uvs1 = true;
  s.tree.colors = true;
  for (size_t i = 0; i < s.payloads.size(); ++i) {
    HlodPayload& p = s.payloads[i];
    HlodNode& n = s.tree.nodes[i];
    for (size_t v = 0; v < p.positions.size() / 3; ++v) {
      p.uvs1.insert(p.uvs1.end(), {0.5f + 0.0625f * float(v % 3), 0.25f * float(v % 4)});
      p.colors.insert(p.colors.end(), {0.125f * float(v % 8), 1 - 0.25f * float(v % 4), 0.5f, v % 2 ? 1.0f : 0.75f});
    }
    n.uvs1 = n.colors = true;
    for (uint32_t k = 1; k < n.layer_count; ++k) {
      n.layers[k].uv1_error = 0.015625f * float(i + k);
      n.layers[k].color_error = 0.0625f * float(k);
    }
    n.resident_bytes = hlod_resident_bytes(n);
  }
  return s;
}

// Every sample, for the tests every file must pass.
std::vector<Sample> samples() { return {sample(), textured_sample(), coloured_sample()}; }

HlodTree sentinel() {
  HlodTree t;
  t.name = "untouched";
  return t;
}

void expect_same(const Sample& a, const HlodTree& t, const std::vector<HlodPayload>& p) {
  EXPECT_EQ(t.name, a.tree.name);
  EXPECT_EQ(t.source_hash, a.tree.source_hash);
  EXPECT_EQ(t.min_verts, a.tree.min_verts);
  EXPECT_EQ(t.source_triangles, a.tree.source_triangles);
  EXPECT_EQ(std::memcmp(t.box_center, a.tree.box_center, sizeof t.box_center), 0);
  EXPECT_EQ(t.uvs, a.tree.uvs);
  EXPECT_EQ(t.uvs1, a.tree.uvs1);
  EXPECT_EQ(t.colors, a.tree.colors);
  EXPECT_EQ(t.material_count, a.tree.material_count);
  EXPECT_EQ(t.texture_base, a.tree.texture_base);
  ASSERT_EQ(t.materials.size(), a.tree.materials.size());
  for (size_t m = 0; m < t.materials.size(); ++m) {
    EXPECT_EQ(t.materials[m].name, a.tree.materials[m].name);
    EXPECT_EQ(t.materials[m].base_color_texture, a.tree.materials[m].base_color_texture);
    EXPECT_EQ(t.materials[m].base_color[1], a.tree.materials[m].base_color[1]);
    EXPECT_EQ(t.materials[m].roughness, a.tree.materials[m].roughness);
    EXPECT_EQ(t.materials[m].double_sided, a.tree.materials[m].double_sided);
  }
  ASSERT_EQ(t.images.size(), a.tree.images.size());
  for (size_t k = 0; k < t.images.size(); ++k) {
    EXPECT_EQ(t.images[k].type, a.tree.images[k].type);
    EXPECT_EQ(t.images[k].bytes, a.tree.images[k].bytes);
  }
  ASSERT_EQ(t.nodes.size(), a.tree.nodes.size());
  for (size_t i = 0; i < t.nodes.size(); ++i) {
    const HlodNode &x = t.nodes[i], &y = a.tree.nodes[i];
    EXPECT_EQ(x.parent, y.parent) << i;
    EXPECT_EQ(x.first_child, y.first_child) << i;
    EXPECT_EQ(x.child_count, y.child_count) << i;
    EXPECT_EQ(x.child_mask, y.child_mask) << i;
    EXPECT_EQ(x.depth, y.depth) << i;
    EXPECT_EQ(x.layer_count, y.layer_count) << i;
    EXPECT_EQ(x.boundary_triangles, y.boundary_triangles) << i;
    EXPECT_EQ(x.boundary_vertices, y.boundary_vertices) << i;
    EXPECT_EQ(x.resident_bytes, y.resident_bytes) << i;
    for (uint32_t k = 0; k < x.layer_count; ++k) {
      EXPECT_EQ(x.layers[k].triangles, y.layers[k].triangles);
      EXPECT_EQ(x.layers[k].error, y.layers[k].error);
      EXPECT_EQ(x.layers[k].uv_error, y.layers[k].uv_error);
      EXPECT_EQ(x.layers[k].uv1_error, y.layers[k].uv1_error);
      EXPECT_EQ(x.layers[k].color_error, y.layers[k].color_error);
    }
    EXPECT_EQ(x.uvs1, y.uvs1) << i;
    EXPECT_EQ(x.colors, y.colors) << i;
    EXPECT_EQ(x.material_runs, y.material_runs) << i;
    EXPECT_EQ(p[i].uvs, a.payloads[i].uvs) << i;
    EXPECT_EQ(p[i].uvs1, a.payloads[i].uvs1) << i;
    EXPECT_EQ(p[i].colors, a.payloads[i].colors) << i;
    ASSERT_EQ(p[i].runs.size(), a.payloads[i].runs.size()) << i;
    for (size_t r = 0; r < p[i].runs.size(); ++r) {
      EXPECT_EQ(p[i].runs[r].level, a.payloads[i].runs[r].level);
      EXPECT_EQ(p[i].runs[r].first_index, a.payloads[i].runs[r].first_index);
      EXPECT_EQ(p[i].runs[r].index_count, a.payloads[i].runs[r].index_count);
      EXPECT_EQ(p[i].runs[r].material, a.payloads[i].runs[r].material);
    }
    ASSERT_EQ(p[i].layers.size(), a.payloads[i].layers.size());
    EXPECT_EQ(std::memcmp(p[i].positions.data(), a.payloads[i].positions.data(), 4 * p[i].positions.size()), 0);
    EXPECT_EQ(std::memcmp(p[i].normals.data(), a.payloads[i].normals.data(), 4 * p[i].normals.size()), 0);
    EXPECT_EQ(p[i].indices, a.payloads[i].indices);
    EXPECT_EQ(p[i].boundary.index_count, a.payloads[i].boundary.index_count);
  }
}

TEST(HlodAsset, RoundTripIsBitExact) {
  for (const Sample& s : samples()) {
  const std::vector<uint8_t> bytes = encode_hlod_asset(s.tree, s.payloads);
  HlodTree t;
  std::vector<HlodPayload> p;
  const Status st = decode_hlod_asset(bytes, "bunny.hlod", t, p);
  ASSERT_TRUE(st) << st.message;
  expect_same(s, t, p);
  EXPECT_EQ(t.nodes[3].box_half, 1.0f) << "cells follow from the root cube and the bits";
  EXPECT_EQ(t.nodes[3].box_center[0], 0.5f - 2 + 1);  // octant 6 of the root, then octant 3
  EXPECT_EQ(t.nodes[3].box_center[1], -2.0f + 2 + 1);
  EXPECT_EQ(encode_hlod_asset(t, p), bytes);
  }
}

TEST(HlodAsset, TexturedPayloadsCarryUvsAndRunsPerRange) {
  const Sample s = textured_sample();
  const std::vector<uint8_t> bytes = encode_hlod_asset(s.tree, s.payloads);
  HlodTree t;
  std::vector<HlodPayload> p;
  ASSERT_TRUE(decode_hlod_asset(bytes, "tree.hlod", t, p));
  ASSERT_EQ(t.materials.size(), 2u);
  for (size_t i = 0; i < p.size(); ++i) {
    EXPECT_EQ(p[i].uvs.size(), p[i].positions.size() / 3 * 2);
    for (uint32_t r = 0; r <= p[i].layers.size(); ++r) {
      const LodLevel& range = r < p[i].layers.size() ? p[i].layers[r] : p[i].boundary;
      uint32_t covered = 0;
      for (const LevelSubmesh& run : hlod_range_runs(p[i], r)) covered += run.index_count;
      EXPECT_EQ(covered, range.index_count) << "node " << i << " range " << r;
    }
  }
  // Textured payloads cost 8 bytes a vertex and 16 a run more, the positions-only ones nothing.
  const Sample plain = sample();
  EXPECT_EQ(hlod_payload_bytes(t.nodes[0]) - hlod_payload_bytes(plain.tree.nodes[0]),
            8 * (p[0].positions.size() / 3) + 16 * p[0].runs.size());
}

TEST(HlodAsset, ColouredPayloadsCarryUv1AndColoursAndTheirErrors) {
  const Sample s = coloured_sample();
  const std::vector<uint8_t> bytes = encode_hlod_asset(s.tree, s.payloads);
  HlodTree t;
  std::vector<HlodPayload> p;
  const Status st = decode_hlod_asset(bytes, "tree.hlod", t, p);
  ASSERT_TRUE(st) << st.message;
  EXPECT_TRUE(t.uvs && t.uvs1 && t.colors);
  uint32_t flags = 0;
  std::memcpy(&flags, bytes.data() + 84, 4);
  EXPECT_EQ(flags, 7u) << "uvs, colours and uv1 flagged";
  for (size_t i = 0; i < p.size(); ++i) {
    EXPECT_EQ(p[i].uvs1.size(), p[i].positions.size() / 3 * 2);
    EXPECT_EQ(p[i].colors.size(), p[i].positions.size() / 3 * 4);
    EXPECT_EQ(t.nodes[i].layers[1].color_error, 0.0625f);
  }
  EXPECT_EQ(p[2].colors[4 * 5 + 1], 0.75f) << "vertex 5 of node 2's first layer: 1 - 0.25 x 1";
  // 24 bytes a vertex more than the textured payload (2 + 4 floats), 24 a record (two errors a layer).
  const Sample textured = textured_sample();
  EXPECT_EQ(hlod_payload_bytes(t.nodes[0]) - hlod_payload_bytes(textured.tree.nodes[0]), 24 * (p[0].positions.size() / 3));
  EXPECT_EQ(bytes.size() - encode_hlod_asset(textured.tree, textured.payloads).size(),
            24 * t.nodes.size() + 24 * [&] {
              size_t v = 0;
              for (const HlodPayload& q : p) v += q.positions.size() / 3;
              return v;
            }());
  // Either attribute alone is a file too.
  for (int which = 0; which < 2; ++which) {
    Sample one = coloured_sample();
    one.tree.uvs1 = which == 0, one.tree.colors = which == 1;
    for (size_t i = 0; i < one.payloads.size(); ++i) {
      (which == 0 ? one.payloads[i].colors : one.payloads[i].uvs1).clear();
      one.tree.nodes[i].uvs1 = one.tree.uvs1, one.tree.nodes[i].colors = one.tree.colors;
      for (HlodLayerInfo& l : one.tree.nodes[i].layers) (which == 0 ? l.color_error : l.uv1_error) = 0;
      one.tree.nodes[i].resident_bytes = hlod_resident_bytes(one.tree.nodes[i]);
    }
    HlodTree u;
    std::vector<HlodPayload> q;
    const Status got = decode_hlod_asset(encode_hlod_asset(one.tree, one.payloads), "one.hlod", u, q);
    ASSERT_TRUE(got) << got.message;
    expect_same(one, u, q);
  }
}

TEST(HlodAsset, HeadAndPayloadsInPiecesAreTheWholeFile) {
  for (const Sample& s : samples()) {
  const std::vector<uint8_t> whole = encode_hlod_asset(s.tree, s.payloads);
  std::vector<uint64_t> sizes;
  std::vector<uint8_t> pieces;
  for (size_t i = 0; i < s.payloads.size(); ++i) {
    const std::vector<uint8_t> p = encode_hlod_payload(s.payloads[i]);
    sizes.push_back(p.size());
    EXPECT_EQ(p.size(), hlod_payload_bytes(s.tree.nodes[i])) << "the size follows from the record";
    pieces.insert(pieces.end(), p.begin(), p.end());
  }
  std::vector<uint8_t> bytes = encode_hlod_head(s.tree, sizes);
  bytes.insert(bytes.end(), pieces.begin(), pieces.end());
  EXPECT_EQ(bytes, whole);
  }
}

TEST(HlodAsset, ReadsTheTreeThenOneNodeAtATime) {
  const Sample s = sample();
  const auto dir = test::temp_dir("hlod_asset");
  const auto file = dir / "bunny.hlod";
  ASSERT_TRUE(write_hlod_asset(file, s.tree, s.payloads));
  HlodTree t;
  ASSERT_TRUE(read_hlod_tree(file, t));
  std::vector<HlodPayload> p(t.nodes.size());
  for (size_t i = t.nodes.size(); i-- > 0;) {
    const Status st = read_hlod_node(file, t.nodes[i], p[i]);
    ASSERT_TRUE(st) << st.message;
  }
  expect_same(s, t, p);
  // One open file, several readers at once.
  HlodFile f;
  HlodTree again;
  ASSERT_TRUE(f.open(file, again));
  std::vector<HlodPayload> q(again.nodes.size());
  std::vector<std::thread> readers;
  for (size_t i = 0; i < again.nodes.size(); ++i)
    readers.emplace_back([&, i] { EXPECT_TRUE(f.read_node(again.nodes[i], q[i])); });
  for (auto& r : readers) r.join();
  expect_same(s, again, q);
}

// A payload overwritten with 0xff behind an intact head: the head still opens, and reading that
// node (and only it) fails naming the file, the node and the checksum.
TEST(HlodAsset, ADamagedPayloadNamesTheFileTheNodeAndTheChecksum) {
  const Sample s = sample();
  const auto dir = test::temp_dir("hlod_asset_damaged");
  const auto file = dir / "bunny.hlod";
  ASSERT_TRUE(write_hlod_asset(file, s.tree, s.payloads));
  HlodTree t;
  ASSERT_TRUE(read_hlod_tree(file, t));
  const uint32_t bad = uint32_t(t.nodes.size() - 1);
  std::vector<uint8_t> bytes = test::read_bytes(file);
  std::fill_n(bytes.begin() + std::ptrdiff_t(t.nodes[bad].payload_offset), 16, uint8_t(0xff));
  test::write_bytes(file, bytes);

  HlodFile f;
  HlodTree again;
  ASSERT_TRUE(f.open(file, again)) << "the head is intact";
  for (uint32_t i = 0; i < again.nodes.size(); ++i) {
    HlodPayload p;
    const Status st = f.read_node(i, again.nodes[i], p);
    if (i != bad) {
      EXPECT_TRUE(st) << st.message;
      continue;
    }
    ASSERT_FALSE(st);
    EXPECT_EQ(st.message.rfind(file.string() + ": node " + std::to_string(bad) + ": payload checksum mismatch", 0), 0u)
        << st.message;
  }
  HlodPayload p;
  const Status alone = read_hlod_node(file, bad, t.nodes[bad], p);
  EXPECT_NE(alone.message.find(": node " + std::to_string(bad) + ": payload checksum mismatch"), std::string::npos)
      << alone.message;
}

TEST(HlodAsset, RefusesTruncationAtEveryLength) {
  for (const Sample& s : samples()) {
  const std::vector<uint8_t> bytes = encode_hlod_asset(s.tree, s.payloads);
  const auto dir = test::temp_dir("hlod_trunc");
  test::expect_every_truncation_refused(bytes, "bunny.hlod", [&](std::span<const uint8_t> cut) {
    HlodTree t = sentinel();
    std::vector<HlodPayload> p;
    const Status st = decode_hlod_asset(cut, "bunny.hlod", t, p);
    EXPECT_EQ(t.name, "untouched");
    // From disk: the tree alone is refused too, since its payloads would lie outside the file
    // (every length up to just past the head, then a sample: files are slow).
    const size_t len = cut.size();
    if (len > 512 && len % 29 != 0) return st;
    const auto file = dir / "cut.hlod";
    test::write_bytes(file, std::vector<uint8_t>(cut.begin(), cut.end()));
    HlodTree u = sentinel();
    EXPECT_FALSE(read_hlod_tree(file, u)) << len;
    EXPECT_EQ(u.name, "untouched");
    return st;
  });
  }
}

TEST(HlodAsset, RefusesEverySingleFlippedByte) {
  for (const Sample& s : samples()) {
  const std::vector<uint8_t> bytes = encode_hlod_asset(s.tree, s.payloads);
  for (size_t at = 0; at < bytes.size(); ++at)
    for (uint8_t mask : {0x01, 0x80, 0xff}) {
      std::vector<uint8_t> bad = bytes;
      bad[at] ^= mask;
      HlodTree t = sentinel();
      std::vector<HlodPayload> p;
      ASSERT_FALSE(decode_hlod_asset(bad, "bunny.hlod", t, p)) << "byte " << at << " ^ " << int(mask);
      EXPECT_EQ(t.name, "untouched");
    }
  }
}

// Where each checksum sits and what it covers, so a test can forge it.
struct Layout {
  uint64_t head = 0;  // head bytes; its checksum follows
  std::vector<std::pair<uint64_t, uint64_t>> payloads;  // offset, size (checksum last 8)
};
Layout layout_of(const std::vector<uint8_t>& bytes) {
  Layout l;
  HlodTree t;
  EXPECT_TRUE(decode_hlod_tree(bytes, bytes.size(), "x", t));
  std::memcpy(&l.head, bytes.data() + 12, 4);
  for (const HlodNode& n : t.nodes) l.payloads.push_back({n.payload_offset, n.payload_size});
  return l;
}
void put_u64(std::vector<uint8_t>& b, uint64_t at, uint64_t v) { std::memcpy(b.data() + at, &v, 8); }
// Recomputes whichever checksum covers byte `at` (the head's, or that payload's).
void forge_checksum(std::vector<uint8_t>& b, const Layout& l, uint64_t at) {
  if (at < l.head) {
    put_u64(b, l.head, hash_bytes(b.data(), l.head));
    return;
  }
  for (const auto& [off, size] : l.payloads)
    if (at >= off && at < off + size - 8) put_u64(b, off + size - 8, hash_bytes(b.data() + off, size - 8));
}

// Checksums forged after every single flip: validation alone must stand. Every outcome is a
// clean refusal or a file that decodes into something valid (a flipped mantissa bit of a
// position is still a position); nothing crashes or allocates wildly (ASan in CI).
TEST(HlodAsset, ValidatesEveryFlippedByteUnderAForgedChecksum) {
  for (const Sample& s : samples()) {
  const std::vector<uint8_t> bytes = encode_hlod_asset(s.tree, s.payloads);
  const Layout l = layout_of(bytes);
  size_t refused = 0, accepted = 0;
  const uint64_t table = l.head - 16 * l.payloads.size();
  for (size_t at = 0; at < bytes.size(); ++at)
    for (uint8_t mask : {0x01, 0x10, 0x80, 0xff}) {
      // Node and inner-node counts and the offset table: no flip there is harmless.
      const bool structural = (at >= 72 && at < 80) || (at >= table && at < l.head);
      std::vector<uint8_t> bad = bytes;
      bad[at] ^= mask;
      forge_checksum(bad, l, at);
      HlodTree t = sentinel();
      std::vector<HlodPayload> p;
      const Status st = decode_hlod_asset(bad, "bunny.hlod", t, p);
      EXPECT_TRUE(!st || !structural) << "byte " << at << " ^ " << int(mask) << " accepted";
      if (!st) {
        ++refused;
        EXPECT_EQ(t.name, "untouched");
        EXPECT_EQ(st.message.rfind("bunny.hlod", 0), 0u) << st.message;
        continue;
      }
      ++accepted;
      // Accepted: every index in range, every value finite, the tree consistent.
      ASSERT_EQ(p.size(), t.nodes.size());
      for (size_t i = 0; i < t.nodes.size(); ++i) {
        const HlodNode& n = t.nodes[i];
        ASSERT_LE(n.depth, kHlodMaxDepth);
        if (n.parent >= 0) {
          ASSERT_LT(size_t(n.parent), i);
          const HlodNode& par = t.nodes[size_t(n.parent)];
          ASSERT_GE(i, par.first_child);
          ASSERT_LT(i, par.first_child + par.child_count);
          ASSERT_GE(par.layers[0].error, n.layers[n.layer_count - 1].error);
        }
        for (const LodLevel& r : p[i].layers)
          for (uint32_t k = 0; k < r.index_count; ++k) ASSERT_LT(p[i].indices[r.first_index + k], r.vertex_count);
        for (float v : p[i].positions) ASSERT_TRUE(std::isfinite(v));
        for (float v : p[i].uvs) ASSERT_TRUE(std::isfinite(v));
        for (float v : p[i].uvs1) ASSERT_TRUE(std::isfinite(v));
        for (float v : p[i].colors) ASSERT_TRUE(std::isfinite(v));
        ASSERT_EQ(p[i].uvs1.size(), t.uvs1 ? p[i].positions.size() / 3 * 2 : 0);
        ASSERT_EQ(p[i].colors.size(), t.colors ? p[i].positions.size() / 3 * 4 : 0);
        for (const LevelSubmesh& r : p[i].runs) ASSERT_LT(r.material, int32_t(t.material_count));
        ASSERT_EQ(p[i].uvs.size(), t.uvs ? p[i].positions.size() / 3 * 2 : 0);
      }
    }
  EXPECT_GT(refused, 0u);
  EXPECT_GT(accepted, 0u) << "flipped position bits are still positions: the forged checksums took";
  }
}

TEST(HlodAsset, RefusesHostileFieldsNamingThem) {
  const Sample s = sample();
  const std::vector<uint8_t> bytes = encode_hlod_asset(s.tree, s.payloads);
  const Layout l = layout_of(bytes);
  auto refuse = [&](auto&& edit, const char* expected) {
    std::vector<uint8_t> bad = bytes;
    const uint64_t at = edit(bad);
    forge_checksum(bad, l, at);
    HlodTree t = sentinel();
    std::vector<HlodPayload> p;
    const Status st = decode_hlod_asset(bad, "bunny.hlod", t, p);
    ASSERT_FALSE(st) << expected;
    EXPECT_NE(st.message.find(expected), std::string::npos) << st.message;
  };
  // An index out of range in node 1's first layer (its indices follow 2 x 7 vertices x 12 bytes).
  refuse([&](std::vector<uint8_t>& b) {
    const uint64_t at = l.payloads[1].first + 2 * 7 * 12;
    const uint32_t v = 1000;
    std::memcpy(b.data() + at, &v, 4);
    return at;
  }, "references vertex 1000 of 7");
  // A payload offset pointing into the head.
  refuse([&](std::vector<uint8_t>& b) {
    const uint64_t table = l.head - 16 * l.payloads.size();
    put_u64(b, table + 16, 8);
    return table + 16;
  }, "does not follow the payload before it");
  // A node count of 2^32 - 1: refused by the head's size, before any allocation.
  refuse([&](std::vector<uint8_t>& b) {
    const uint32_t v = 0xffffffffu;
    std::memcpy(b.data() + 72, &v, 4);
    return uint64_t{72};
  }, "does not match its counts");
  // A NaN error.
  refuse([&](std::vector<uint8_t>& b) {
    const uint64_t records = l.head - 16 * l.payloads.size() - 80 * l.payloads.size();
    const float nan = NAN;
    std::memcpy(b.data() + records + 80 * 2 + 28 + 8, &nan, 4);
    return records;
  }, "not a finite distance");
  // A child coarser than its parent (node 3's coarsest error above node 2's finest).
  refuse([&](std::vector<uint8_t>& b) {
    const uint64_t records = l.head - 16 * l.payloads.size() - 80 * l.payloads.size();
    const float big = 0.4f;
    std::memcpy(b.data() + records + 80 * 3 + 28 + 24 + 8, &big, 4);
    return records;
  }, "errors must grow upwards");
  // An OctreeCode naming more children than there are nodes.
  refuse([&](std::vector<uint8_t>& b) {
    const uint64_t code = 96 + 8;  // after the name "bunny", 8-aligned
    b[code] = 0xff;
    return code;
  }, "octree");
}

TEST(HlodAsset, RefusesHostileSurfacesNamingThem) {
  const Sample s = textured_sample();
  const std::vector<uint8_t> bytes = encode_hlod_asset(s.tree, s.payloads);
  const Layout l = layout_of(bytes);
  auto refuse = [&](auto&& edit, const char* expected) {
    std::vector<uint8_t> bad = bytes;
    const uint64_t at = edit(bad);
    forge_checksum(bad, l, at);
    HlodTree t = sentinel();
    std::vector<HlodPayload> p;
    const Status st = decode_hlod_asset(bad, "tree.hlod", t, p);
    ASSERT_FALSE(st) << expected;
    EXPECT_NE(st.message.find(expected), std::string::npos) << st.message;
    EXPECT_EQ(t.name, "untouched");
  };
  // Node 0's runs are the last 16 bytes of each before its checksum.
  const uint64_t runs = l.payloads[0].first + l.payloads[0].second - 8 - 16 * s.payloads[0].runs.size();
  refuse([&](std::vector<uint8_t>& b) {
    const int32_t m = 2;
    std::memcpy(b.data() + runs + 16 * 1 + 12, &m, 4);
    return runs;
  }, "names material 2 of 2");
  refuse([&](std::vector<uint8_t>& b) {
    const uint32_t count = 6;  // run 1 of range 0 shortened: the range is not covered
    std::memcpy(b.data() + runs + 16 * 1 + 8, &count, 4);
    return runs;
  }, "material runs cover");
  refuse([&](std::vector<uint8_t>& b) {
    const uint32_t range = 7;
    std::memcpy(b.data() + runs + 16 * 0, &range, 4);
    return runs;
  }, "out of order");
  // A NaN uv: node 0's layer 0 uvs follow its 8 positions and 8 normals.
  refuse([&](std::vector<uint8_t>& b) {
    const uint64_t at = l.payloads[0].first + 2 * 8 * 12 + 4;
    const float nan = NAN;
    std::memcpy(b.data() + at, &nan, 4);
    return at;
  }, "non-finite uv");
  // A material count the MATL section does not hold, and one past the limit.
  refuse([&](std::vector<uint8_t>& b) {
    const uint32_t v = 3;
    std::memcpy(b.data() + 64, &v, 4);
    return uint64_t{64};
  }, "its MATL section holds 2");
  refuse([&](std::vector<uint8_t>& b) {
    const uint32_t v = 0x7fffffff;
    std::memcpy(b.data() + 64, &v, 4);
    return uint64_t{64};
  }, "materials, at most");
  // A material's factor out of range, in the head's MATL section (its first record's base
  // colour follows the 16-byte section header and the 12-byte texture base).
  refuse([&](std::vector<uint8_t>& b) {
    const uint64_t at = 96 + 8 + 16 + 12 + 8;
    const float v = 2;
    std::memcpy(b.data() + at, &v, 4);
    return at;
  }, "base colour factor outside [0, 1]");
}

// The embedded images: each one's type against its signature, and every "embedded:<k>" of the
// materials against their count, before anything is kept.
TEST(HlodAsset, RefusesHostileEmbeddedImagesNamingThem) {
  const auto refused = [](const Sample& s, auto&& edit, const char* expected) {
    std::vector<uint8_t> bytes = encode_hlod_asset(s.tree, s.payloads);
    const Layout l = layout_of(bytes);
    forge_checksum(bytes, l, edit(bytes));
    HlodTree t = sentinel();
    std::vector<HlodPayload> p;
    const Status st = decode_hlod_asset(bytes, "tree.hlod", t, p);
    ASSERT_FALSE(st) << expected;
    EXPECT_NE(st.message.find(expected), std::string::npos) << st.message;
    EXPECT_EQ(t.name, "untouched");
  };
  const Sample s = textured_sample();
  const std::vector<uint8_t> bytes = encode_hlod_asset(s.tree, s.payloads);
  uint32_t material_bytes = 0, image_bytes = 0;
  std::memcpy(&material_bytes, bytes.data() + 88, 4);
  std::memcpy(&image_bytes, bytes.data() + 92, 4);
  ASSERT_GT(image_bytes, 0u);
  const uint64_t images = 96 + 8 + ((uint64_t{material_bytes} + 7) & ~uint64_t{7});
  // The image's signature broken: its bytes follow the 16-byte section header and its 16-byte entry.
  refused(s, [&](std::vector<uint8_t>& b) { return b[images + 32 + 1] ^= 0x20, images + 32 + 1; },
          "is not the PNG or JPEG its type says");
  // Its type byte (entry offset 8) neither PNG nor JPEG.
  refused(s, [&](std::vector<uint8_t>& b) { return b[images + 16 + 8] = 7, images + 16 + 8; }, "has type 7");
  // A length past the section's bytes.
  refused(s, [&](std::vector<uint8_t>& b) { return b[images + 16] = 200, images + 16; }, "IMGS section");
  // A material naming an image the tree does not hold.
  Sample missing = textured_sample();
  missing.tree.materials[1].base_color_texture = embedded_image_uri(1);
  HlodTree t = sentinel();
  std::vector<HlodPayload> p;
  const Status st = decode_hlod_asset(encode_hlod_asset(missing.tree, missing.payloads), "tree.hlod", t, p);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("names embedded image 'embedded:1' of 1"), std::string::npos) << st.message;
  EXPECT_EQ(t.name, "untouched");
}

// Version 3 only adds flags: a version 2 file (no colour or uv1 flag) reads as it did, and one
// claiming the new flags is refused.
TEST(HlodAsset, ReadsVersionTwoFilesAndRefusesTheNewFlagsInThem) {
  for (const Sample& s : {sample(), textured_sample()}) {
    std::vector<uint8_t> bytes = encode_hlod_asset(s.tree, s.payloads);
    const Layout l = layout_of(bytes);
    bytes[8] = 2;
    forge_checksum(bytes, l, 8);
    HlodTree t;
    std::vector<HlodPayload> p;
    const Status st = decode_hlod_asset(bytes, "v2.hlod", t, p);
    ASSERT_TRUE(st) << st.message;
    expect_same(s, t, p);
  }
  const Sample c = coloured_sample();
  std::vector<uint8_t> bytes = encode_hlod_asset(c.tree, c.payloads);
  const Layout l = layout_of(bytes);
  bytes[8] = 2;
  forge_checksum(bytes, l, 8);
  HlodTree t = sentinel();
  std::vector<HlodPayload> p;
  const Status st = decode_hlod_asset(bytes, "v2.hlod", t, p);
  ASSERT_FALSE(st);
  EXPECT_EQ(t.name, "untouched");
}

// Hostile colour and uv1 fields: a flag set without its data (or data without its flag), a
// non-finite colour or uv1, an error that is not a distance or set beyond the layer count.
TEST(HlodAsset, RefusesHostileColoursAndUv1NamingThem) {
  const Sample s = coloured_sample();
  const std::vector<uint8_t> bytes = encode_hlod_asset(s.tree, s.payloads);
  const Layout l = layout_of(bytes);
  auto refuse = [&](auto&& edit, const char* expected) {
    std::vector<uint8_t> bad = bytes;
    const uint64_t at = edit(bad);
    forge_checksum(bad, l, at);
    HlodTree t = sentinel();
    std::vector<HlodPayload> p;
    const Status st = decode_hlod_asset(bad, "tree.hlod", t, p);
    ASSERT_FALSE(st) << expected;
    EXPECT_NE(st.message.find(expected), std::string::npos) << st.message;
    EXPECT_EQ(t.name, "untouched");
  };
  // Node 0's layer 0 has 8 vertices: positions, normals (2 x 96 bytes), uvs (64), uv1 (64), colours (128).
  const uint64_t layer0 = l.payloads[0].first;
  refuse([&](std::vector<uint8_t>& b) {
    const uint64_t at = layer0 + 2 * 96 + 64 + 4 * 3;
    const float inf = INFINITY;
    std::memcpy(b.data() + at, &inf, 4);
    return at;
  }, "vertex 1 has a non-finite uv1");
  refuse([&](std::vector<uint8_t>& b) {
    const uint64_t at = layer0 + 2 * 96 + 64 + 64 + 4 * 6;
    const float nan = NAN;
    std::memcpy(b.data() + at, &nan, 4);
    return at;
  }, "vertex 1 has a non-finite colour");
  refuse([&](std::vector<uint8_t>& b) {
    const uint64_t at = layer0 + 2 * 96 + 64 + 64 + 4 * 9;
    const float huge = 1e30f;
    std::memcpy(b.data() + at, &huge, 4);
    return at;
  }, "vertex 2 has a non-finite colour");
  // The records grow by 24 bytes (3 uv1 errors, then 3 colour errors) after the 80 of version 2.
  const uint64_t records = l.head - 16 * l.payloads.size() - 104 * l.payloads.size();
  refuse([&](std::vector<uint8_t>& b) {
    const float nan = NAN;
    std::memcpy(b.data() + records + 104 * 1 + 80 + 4, &nan, 4);
    return records;
  }, "layer 1 uv1 error is not a finite distance");
  refuse([&](std::vector<uint8_t>& b) {
    const float negative = -0.5f;
    std::memcpy(b.data() + records + 104 * 0 + 92 + 4, &negative, 4);
    return records;
  }, "layer 1 colour error is not a finite distance");
  refuse([&](std::vector<uint8_t>& b) {  // node 1 has two layers: its third colour error must be 0
    const float set = 0.5f;
    std::memcpy(b.data() + records + 104 * 1 + 92 + 8, &set, 4);
    return records;
  }, "set beyond the layer count");
  // A flag cleared (its data and errors still there) or set anew: the head no longer matches its
  // counts, so the payloads are never read with the wrong stride.
  for (uint32_t flags : {5u, 3u, 1u, 15u})
    refuse([&](std::vector<uint8_t>& b) {
      std::memcpy(b.data() + 84, &flags, 4);
      return uint64_t{84};
    }, flags == 15 ? "flags" : "does not match its counts");
  // Flags set with no data in the payloads: a writer that says colours and gives none makes
  // payloads shorter than the records promise.
  Sample empty = coloured_sample();
  for (HlodPayload& p : empty.payloads) p.colors.clear();
  HlodTree t = sentinel();
  std::vector<HlodPayload> p;
  const Status st = decode_hlod_asset(encode_hlod_asset(empty.tree, empty.payloads), "tree.hlod", t, p);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("should be"), std::string::npos) << st.message;
  EXPECT_EQ(t.name, "untouched");
}

TEST(HlodAsset, RefusesVersionOneAskingForARebake) {
  const Sample s = sample();
  std::vector<uint8_t> bytes = encode_hlod_asset(s.tree, s.payloads);
  bytes[8] = 1;
  HlodTree t;
  std::vector<HlodPayload> p;
  const Status st = decode_hlod_asset(bytes, "old.hlod", t, p);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("hlod version 1 is not supported"), std::string::npos) << st.message;
  EXPECT_NE(st.message.find("rebake it"), std::string::npos) << st.message;
}

TEST(HlodAsset, RefusesWrongMagicAndVersionSayingSo) {
  const Sample s = sample();
  std::vector<uint8_t> bytes = encode_hlod_asset(s.tree, s.payloads);
  HlodTree t;
  std::vector<HlodPayload> p;
  std::vector<uint8_t> bad = bytes;
  bad[0] = 'X';
  Status st = decode_hlod_asset(bad, "a.hlod", t, p);
  EXPECT_NE(st.message.find("bad magic"), std::string::npos) << st.message;
  bad = bytes;
  bad[8] = 9;
  st = decode_hlod_asset(bad, "a.hlod", t, p);
  EXPECT_NE(st.message.find("version 9 is not supported"), std::string::npos) << st.message;
}

TEST(HlodAsset, ReadsRegularFilesOnlyAndNamesMissingOnes) {
  const auto dir = test::temp_dir("hlod_files");
  HlodTree t;
  Status st = read_hlod_tree(dir / "none.hlod", t);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("none.hlod: no such file"), std::string::npos) << st.message;
  st = read_hlod_tree(dir, t);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("not a regular file"), std::string::npos) << st.message;
}

}  // namespace
}  // namespace lod

namespace lod {
namespace {

// The fuzz seeds (tests/fuzz/corpus/hlod: hs0 the sample, hs1 the textured sample) are files of
// the current version, so the fuzzer starts from inputs the reader accepts; LOD_WRITE_FUZZ_SEEDS=1
// rewrites them after a format change.
TEST(HlodAsset, TheFuzzSeedsAreCurrent) {
  const std::filesystem::path dir = std::filesystem::path(LOD_SOURCE_DIR) / "tests/fuzz/corpus/hlod";
  if (std::getenv("LOD_WRITE_FUZZ_SEEDS")) {
    const Sample plain = sample(), textured = textured_sample(), coloured = coloured_sample();
    test::write_bytes(dir / "hs0.hlod", encode_hlod_asset(plain.tree, plain.payloads));
    test::write_bytes(dir / "hs1.hlod", encode_hlod_asset(textured.tree, textured.payloads));
    test::write_bytes(dir / "hs2.hlod", encode_hlod_asset(coloured.tree, coloured.payloads));
  }
  size_t seeds = 0, with_materials = 0, with_colours = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    HlodTree t;
    std::vector<HlodPayload> p;
    const Status st = decode_hlod_asset(test::read_bytes(e.path()), e.path().string(), t, p);
    EXPECT_TRUE(st) << st.message;
    ++seeds;
    with_materials += !t.materials.empty();
    with_colours += t.colors && t.uvs1;
  }
  EXPECT_GE(seeds, 3u);
  EXPECT_GE(with_colours, 1u) << "a seed with colours and a second uv set";
  EXPECT_GE(with_materials, 1u) << "a seed with uvs, materials and runs";
}

}  // namespace
}  // namespace lod
