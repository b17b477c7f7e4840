// The distributed bake's cache entry: a subtree round-trips bit-exactly, and every
// truncation, flipped byte, forged count, wrong key and out-of-mesh vertex is refused.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <vector>

#include <algorithm>
#include <span>

#include "runtime/byte_order.h"
#include "runtime/hlod_asset.h"
#include "runtime/hlod_subtree_entry.h"
#include "runtime/lod_asset.h"  // hash_bytes
#include "test_support.h"

namespace lod {
namespace {

constexpr uint64_t kKey = 0xfeedface12345678ull;
constexpr uint64_t kMeshVertices = 100;

// `triangles` fan triangles around vertex 0 of a fresh range.
LodLevel add_fan(HlodPayload& p, uint32_t triangles, float shift) {
  LodLevel r;
  r.first_vertex = uint32_t(p.positions.size() / 3);
  r.vertex_count = triangles ? triangles + 2 : 0;
  r.first_index = uint32_t(p.indices.size());
  r.index_count = 3 * triangles;
  r.level = level_of_triangles(triangles);
  for (uint32_t v = 0; v < r.vertex_count; ++v) {
    const float a = 0.25f * float(v) + shift;
    p.positions.insert(p.positions.end(), {a, 1 - a, a * a});
    p.normals.insert(p.normals.end(), {0, 1, 0});
  }
  for (uint32_t f = 0; f < triangles; ++f) p.indices.insert(p.indices.end(), {0u, f + 1, f + 2});
  return r;
}

void add_node(HlodSubtree& s, std::vector<uint32_t> tris, std::vector<float> errors, uint32_t patch) {
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
  n.boundary_vertices = p.boundary.vertex_count;
  n.bounds = {{0.5f, 0.25f, -1}, 3};
  n.resident_bytes = 4 * (p.positions.size() + p.normals.size() + p.indices.size());
  s.nodes.push_back(n);
  s.payloads.push_back(std::move(p));
}

// A subtree rooted at depth 3: root (octants 1 and 4) -> two leaves.
HlodSubtree sample() {
  HlodSubtree s;
  add_node(s, {6, 3, 1}, {0.5f, 0.75f, 1.0f}, 3);
  add_node(s, {5, 2}, {0, 0.25f}, 0);
  add_node(s, {4, 2, 1}, {0, 0.25f, 0.5f}, 0);
  HlodNode& root = s.nodes[0];
  root.depth = 3;
  root.box_center[0] = 1.5f, root.box_center[1] = -0.5f, root.box_center[2] = 0.25f;
  root.box_half = 0.5f;
  root.child_mask = 0b00010010, root.child_count = 2, root.first_child = 1;
  const int octants[2] = {1, 4};
  for (int c = 0; c < 2; ++c) {
    HlodNode& n = s.nodes[1 + c];
    n.parent = 0;
    n.depth = 4;
    n.box_half = root.box_half / 2;
    for (int k = 0; k < 3; ++k) n.box_center[k] = root.box_center[k] + ((octants[c] >> k) & 1 ? n.box_half : -n.box_half);
  }
  s.root_source = {7, 42, 99};  // the root's coarsest layer: 1 triangle, 3 vertices
  s.root_reference = {1, 2, 3, 5, 8, 13, 21};
  s.short_layers = 2;
  s.oversized_leaves = 1;
  return s;
}

Status decode(const std::vector<uint8_t>& bytes, HlodSubtree& out, uint64_t key = kKey) {
  return decode_hlod_subtree(bytes, key, kMeshVertices, "cache/abc.hsub", out);
}

TEST(HlodSubtreeEntry, RoundTripIsBitExact) {
  const HlodSubtree s = sample();
  const std::vector<uint8_t> bytes = encode_hlod_subtree(s, kKey);
  HlodSubtree t;
  const Status st = decode(bytes, t);
  ASSERT_TRUE(st) << st.message;
  ASSERT_EQ(t.nodes.size(), s.nodes.size());
  for (size_t i = 0; i < t.nodes.size(); ++i) {
    const HlodNode &a = t.nodes[i], &b = s.nodes[i];
    EXPECT_EQ(a.depth, b.depth);
    EXPECT_EQ(a.parent, b.parent);
    EXPECT_EQ(a.first_child, b.first_child);
    EXPECT_EQ(a.child_mask, b.child_mask);
    EXPECT_EQ(std::memcmp(a.box_center, b.box_center, sizeof a.box_center), 0);
    EXPECT_EQ(a.box_half, b.box_half);
    EXPECT_EQ(a.resident_bytes, b.resident_bytes);
    EXPECT_EQ(a.payload_offset, 0u);
    EXPECT_EQ(t.payloads[i].indices, s.payloads[i].indices);
    EXPECT_EQ(t.payloads[i].positions, s.payloads[i].positions);
  }
  EXPECT_EQ(t.root_source, s.root_source);
  EXPECT_EQ(t.root_reference, s.root_reference);
  EXPECT_EQ(t.short_layers, 2u);
  EXPECT_EQ(t.oversized_leaves, 1u);
  EXPECT_EQ(encode_hlod_subtree(t, kKey), bytes);
}

TEST(HlodSubtreeEntry, RefusesTruncationAtEveryLength) {
  const std::vector<uint8_t> bytes = encode_hlod_subtree(sample(), kKey);
  for (size_t n = 0; n < bytes.size(); ++n) {
    HlodSubtree t;
    t.short_layers = 77;
    const std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + std::ptrdiff_t(n));
    ASSERT_FALSE(decode(cut, t)) << "accepted " << n << " of " << bytes.size() << " bytes";
    ASSERT_EQ(t.short_layers, 77u) << "output touched";
  }
}

TEST(HlodSubtreeEntry, RefusesEverySingleFlippedByte) {
  const std::vector<uint8_t> bytes = encode_hlod_subtree(sample(), kKey);
  for (size_t i = 0; i < bytes.size(); ++i) {
    std::vector<uint8_t> bad = bytes;
    bad[i] ^= 0x20;
    HlodSubtree t;
    ASSERT_FALSE(decode(bad, t)) << "accepted a flipped byte at " << i;
  }
}

TEST(HlodSubtreeEntry, RefusesAnEntryWrittenForAnotherKey) {
  const std::vector<uint8_t> bytes = encode_hlod_subtree(sample(), kKey);
  HlodSubtree t;
  const Status st = decode(bytes, t, kKey + 1);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("another key"), std::string::npos) << st.message;
}

TEST(HlodSubtreeEntry, RefusesVerticesOutsideTheMesh) {
  HlodSubtree s = sample();
  s.root_source[1] = uint32_t(kMeshVertices);
  HlodSubtree t;
  Status st = decode(encode_hlod_subtree(s, kKey), t);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("vertex source 100"), std::string::npos) << st.message;
  s = sample();
  s.root_reference.back() = 1u << 31;
  EXPECT_FALSE(decode(encode_hlod_subtree(s, kKey), t));
}

// Counts rewritten with the entry's checksum recomputed: validation, not the checksum, refuses.
TEST(HlodSubtreeEntry, RefusesForgedCountsUnderARecomputedChecksum) {
  const HlodSubtree s = sample();
  const std::vector<uint8_t> good = encode_hlod_subtree(s, kKey);
  const size_t head = 56 + 4 * (s.root_source.size() + s.root_reference.size());
  auto forge = [&](size_t at, uint32_t value) {
    std::vector<uint8_t> bad = good;
    detail::ByteWriter w;
    w.u32(value);
    std::memcpy(&bad[at], w.bytes.data(), 4);
    w.bytes.clear();
    w.u64(hash_bytes(bad.data(), head));
    std::memcpy(&bad[head], w.bytes.data(), 8);
    return bad;
  };
  HlodSubtree t;
  EXPECT_FALSE(decode(forge(12, 30), t)) << "depth 30";
  EXPECT_FALSE(decode(forge(12, 24), t)) << "children below the depth limit";
  EXPECT_FALSE(decode(forge(40, 0xffffffffu), t)) << "huge source count";
  EXPECT_FALSE(decode(forge(44, 0x40000000u), t)) << "huge reference count";
  EXPECT_FALSE(decode(forge(48, 1), t)) << "asset size";
  EXPECT_FALSE(decode(forge(8, 1), t)) << "version 1 (before uvs and materials)";
  EXPECT_FALSE(decode(forge(8, 2), t)) << "version 2 (before colours and uv1)";
  EXPECT_FALSE(decode(forge(8, 4), t)) << "version 4";
  EXPECT_TRUE(decode(forge(12, 3), t)) << "the forger itself";
}

// The root alone from the entry's first bytes (what the levels above need), asked for in steps.
Status decode_root(const std::vector<uint8_t>& bytes, HlodSubtree& out, size_t* used = nullptr) {
  std::vector<uint8_t> prefix(bytes.begin(), bytes.begin() + std::ptrdiff_t(std::min<size_t>(bytes.size(), 16)));
  for (int step = 0; step < 8; ++step) {
    const uint64_t need = hlod_subtree_entry_root_bytes(prefix, bytes.size());
    if (need == 0 || need <= prefix.size() || need > bytes.size()) break;
    prefix.assign(bytes.begin(), bytes.begin() + std::ptrdiff_t(need));
  }
  if (used) *used = prefix.size();
  return decode_hlod_subtree_root(prefix, bytes.size(), kKey, kMeshVertices, "cache/abc.hsub", out);
}

TEST(HlodSubtreeEntry, RootAloneFromTheFirstBytesMatchesTheFullDecode) {
  const std::vector<uint8_t> bytes = encode_hlod_subtree(sample(), kKey);
  HlodSubtree full, root;
  ASSERT_TRUE(decode(bytes, full));
  size_t used = 0;
  const Status st = decode_root(bytes, root, &used);
  ASSERT_TRUE(st) << st.message;
  EXPECT_LT(used, bytes.size()) << "the leaves' payloads are not read";
  ASSERT_EQ(root.nodes.size(), full.nodes.size());
  ASSERT_EQ(root.payloads.size(), 1u);
  EXPECT_EQ(root.payloads[0].positions, full.payloads[0].positions);
  EXPECT_EQ(root.payloads[0].indices, full.payloads[0].indices);
  for (size_t i = 0; i < root.nodes.size(); ++i) {
    EXPECT_EQ(root.nodes[i].depth, full.nodes[i].depth);
    EXPECT_EQ(root.nodes[i].first_child, full.nodes[i].first_child);
    EXPECT_EQ(root.nodes[i].layers[0].error, full.nodes[i].layers[0].error);
  }
  EXPECT_EQ(root.root_source, full.root_source);
  EXPECT_EQ(root.root_reference, full.root_reference);
  EXPECT_EQ(root.short_layers, full.short_layers);
}

TEST(HlodSubtreeEntry, RootAloneRefusesTruncationsAndFlippedBytesInWhatItReads) {
  const std::vector<uint8_t> bytes = encode_hlod_subtree(sample(), kKey);
  size_t used = 0;
  HlodSubtree t;
  ASSERT_TRUE(decode_root(bytes, t, &used));
  for (size_t n = 0; n < bytes.size(); ++n) {
    const std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + std::ptrdiff_t(n));
    HlodSubtree u;
    ASSERT_FALSE(decode_root(cut, u)) << "accepted " << n << " of " << bytes.size() << " bytes";
  }
  for (size_t i = 0; i < used; ++i) {
    std::vector<uint8_t> bad = bytes;
    bad[i] ^= 0x20;
    HlodSubtree u;
    ASSERT_FALSE(decode_root(bad, u)) << "accepted a flipped byte at " << i;
  }
  HlodSubtree u;
  const std::vector<uint8_t> prefix(bytes.begin(), bytes.begin() + std::ptrdiff_t(used - 1));
  EXPECT_FALSE(decode_hlod_subtree_root(prefix, bytes.size(), kKey, kMeshVertices, "e", u)) << "a prefix one byte short";
}

TEST(HlodSubtreeEntry, PayloadSpansAreTheFilesPayloadBytes) {
  const HlodSubtree s = sample();
  const std::vector<uint8_t> bytes = encode_hlod_subtree(s, kKey);
  std::vector<std::span<const uint8_t>> spans;
  ASSERT_TRUE(hlod_subtree_entry_payloads(bytes, "e", spans));
  ASSERT_EQ(spans.size(), s.nodes.size());
  for (size_t i = 0; i < spans.size(); ++i) {
    const std::vector<uint8_t> own = encode_hlod_payload(s.payloads[i]);
    EXPECT_EQ(std::vector<uint8_t>(spans[i].begin(), spans[i].end()), own) << i;
    EXPECT_EQ(own.size(), hlod_payload_bytes(s.nodes[i])) << i;
  }
  EXPECT_FALSE(hlod_subtree_entry_payloads(std::vector<uint8_t>(bytes.begin(), bytes.begin() + 40), "e", spans))
      << "a truncated entry";
}

}  // namespace
}  // namespace lod

namespace lod {
namespace {

// The sample with texture coordinates and every range one run of material 1 of 2: the entry
// carries the material count (not the materials: the .hlod's head has those) and checks the
// runs against it.
HlodSubtree textured() {
  HlodSubtree s = sample();
  s.material_count = 2;
  for (size_t i = 0; i < s.nodes.size(); ++i) {
    HlodPayload& p = s.payloads[i];
    for (size_t v = 0; v < p.positions.size() / 3; ++v) p.uvs.insert(p.uvs.end(), {0.5f, 0.25f * float(v % 4)});
    for (uint32_t r = 0; r <= p.layers.size(); ++r) {
      const LodLevel& range = r < p.layers.size() ? p.layers[r] : p.boundary;
      if (range.index_count) p.runs.push_back({r, 0, range.index_count, 1});
    }
    s.nodes[i].uvs = true;
    s.nodes[i].material_runs = uint32_t(p.runs.size());
    s.nodes[i].resident_bytes = hlod_resident_bytes(s.nodes[i]);
  }
  return s;
}

// The textured subtree with a second uv set and vertex colours.
HlodSubtree coloured() {
  HlodSubtree s = textured();
  for (size_t i = 0; i < s.nodes.size(); ++i) {
    HlodPayload& p = s.payloads[i];
    for (size_t v = 0; v < p.positions.size() / 3; ++v) {
      p.uvs1.insert(p.uvs1.end(), {0.75f, 0.125f * float(v % 8)});
      p.colors.insert(p.colors.end(), {0.25f * float(v % 4), 0.5f, 1, 1});
    }
    s.nodes[i].uvs1 = s.nodes[i].colors = true;
    if (s.nodes[i].layer_count > 1) s.nodes[i].layers[1].color_error = 0.125f, s.nodes[i].layers[1].uv1_error = 0.0625f;
    s.nodes[i].resident_bytes = hlod_resident_bytes(s.nodes[i]);
  }
  return s;
}

TEST(HlodSubtreeEntry, ColouredSubtreeRoundTripsAndItsRootAlone) {
  const HlodSubtree s = coloured();
  const std::vector<uint8_t> bytes = encode_hlod_subtree(s, kKey);
  HlodSubtree t, root;
  ASSERT_TRUE(decode(bytes, t));
  for (size_t i = 0; i < t.nodes.size(); ++i) {
    EXPECT_TRUE(t.nodes[i].uvs1 && t.nodes[i].colors);
    EXPECT_EQ(t.payloads[i].uvs1, s.payloads[i].uvs1);
    EXPECT_EQ(t.payloads[i].colors, s.payloads[i].colors);
    EXPECT_EQ(t.nodes[i].layers[1].color_error, s.nodes[i].layers[1].color_error);
    EXPECT_EQ(t.nodes[i].resident_bytes, s.nodes[i].resident_bytes);
  }
  ASSERT_TRUE(decode_root(bytes, root));
  EXPECT_EQ(root.payloads[0].colors, s.payloads[0].colors);
  EXPECT_EQ(root.payloads[0].uvs1, s.payloads[0].uvs1);
  for (size_t len = 0; len < bytes.size(); len += 5) {
    const std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + std::ptrdiff_t(len));
    ASSERT_FALSE(decode(cut, t)) << len;
  }
  // A colour flag set with no colours in the payloads: the entry's asset is refused.
  HlodSubtree empty = coloured();
  for (HlodPayload& p : empty.payloads) p.colors.clear();
  const Status st = decode(encode_hlod_subtree(empty, kKey), t);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("should be"), std::string::npos) << st.message;
}

TEST(HlodSubtreeEntry, TexturedSubtreeRoundTripsAndItsRootAlone) {
  const HlodSubtree s = textured();
  const std::vector<uint8_t> bytes = encode_hlod_subtree(s, kKey);
  HlodSubtree t, root;
  ASSERT_TRUE(decode(bytes, t));
  EXPECT_EQ(t.material_count, 2u);
  for (size_t i = 0; i < t.nodes.size(); ++i) {
    EXPECT_TRUE(t.nodes[i].uvs);
    EXPECT_EQ(t.payloads[i].uvs, s.payloads[i].uvs);
    ASSERT_EQ(t.payloads[i].runs.size(), s.payloads[i].runs.size());
    for (const LevelSubmesh& r : t.payloads[i].runs) EXPECT_EQ(r.material, 1);
  }
  ASSERT_TRUE(decode_root(bytes, root));
  EXPECT_EQ(root.payloads[0].uvs, s.payloads[0].uvs);
  EXPECT_EQ(root.material_count, 2u);
  // Every truncation refused.
  for (size_t len = 0; len < bytes.size(); len += 7) {
    const std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + std::ptrdiff_t(len));
    ASSERT_FALSE(decode(cut, t)) << len;
  }
  // A run naming a material past the count is refused, even with its checksums forged.
  HlodSubtree bad = s;
  bad.material_count = 1;
  const std::vector<uint8_t> fewer = encode_hlod_subtree(bad, kKey);
  const Status st = decode(fewer, t);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("names material 1 of 1"), std::string::npos) << st.message;
}

}  // namespace
}  // namespace lod

namespace lod {
namespace {

// The fuzz seeds (tests/fuzz/corpus/hsub: e0 the sample, e1 the textured one) are entries of
// the current version; LOD_WRITE_FUZZ_SEEDS=1 rewrites them after a format change.
TEST(HlodSubtreeEntry, TheFuzzSeedsAreCurrent) {
  const std::filesystem::path dir = std::filesystem::path(LOD_SOURCE_DIR) / "tests/fuzz/corpus/hsub";
  if (std::getenv("LOD_WRITE_FUZZ_SEEDS")) {
    test::write_bytes(dir / "e0.hsub", encode_hlod_subtree(sample(), kKey));
    test::write_bytes(dir / "e1.hsub", encode_hlod_subtree(textured(), kKey));
    test::write_bytes(dir / "e2.hsub", encode_hlod_subtree(coloured(), kKey));
  }
  size_t seeds = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    HlodSubtree s;
    const Status st = decode(test::read_bytes(e.path()), s);
    EXPECT_TRUE(st) << st.message;
    ++seeds;
  }
  EXPECT_GE(seeds, 3u);
}

}  // namespace
}  // namespace lod
