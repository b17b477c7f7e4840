// TEXCOORD_1, vertex colours and authored normals through the vertex hierarchy: every node
// carries them (leaves the input's bit for bit, parents interpolated along their collapse,
// normals renormalised), copies that differ in any of them are pinned, and the asset's VHAT
// section (layout 2) keeps them, refusing truncated or forged data by name.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "preprocess/vertex_hierarchy.h"
#include "runtime/lod_asset.h"
#include "runtime/vertex_front.h"
#include "test_support.h"
#include "textured_fixture.h"

namespace lod {
namespace {

// coloured_sphere (a colour seam at the equator, TEXCOORD_1) with radial authored normals.
MeshData attributed_sphere(int rings = 16, int segments = 32) {
  MeshData m = test::coloured_sphere(rings, segments);
  m.source = "attributed sphere";
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    const float* p = &m.positions[3 * v];
    const float len = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    m.normals.insert(m.normals.end(), {p[0] / len, p[1] / len, p[2] / len});
  }
  return m;
}

VertexTree build(const MeshData& m) {
  VertexTree t;
  const Status s = build_vertex_hierarchy(t, m);
  EXPECT_TRUE(s.ok) << s.message;
  std::string msg;
  EXPECT_TRUE(validate_vertex_tree(t, &msg)) << msg;
  return t;
}

std::vector<uint32_t> leaf_order(const VertexTree& t) {
  std::vector<uint32_t> order(t.leaf_count);
  for (uint32_t l = 0; l < t.leaf_count; ++l) order[t.leaf_rank[l]] = l;
  return order;
}

// Every node's value of a boxed column lies in the box of its leaves' values.
void expect_inside_leaves_box(const VertexTree& t, const std::vector<float>& column, size_t width,
                              const char* what) {
  const std::vector<uint32_t> order = leaf_order(t);
  for (uint32_t v = t.leaf_count; v < t.node_count(); ++v)
    for (size_t k = 0; k < width; ++k) {
      float lo = 1e30f, hi = -1e30f;
      for (uint32_t r = t.leaf_lo[v]; r < t.leaf_hi[v]; ++r)
        lo = std::min(lo, column[width * order[r] + k]), hi = std::max(hi, column[width * order[r] + k]);
      ASSERT_GE(column[width * v + k], lo) << what << " of node " << v;
      ASSERT_LE(column[width * v + k], hi) << what << " of node " << v;
    }
}

TEST(VertexHierarchyAttributes, LeavesKeepTheInputsBitForBitAndTheFullFrontDrawsThem) {
  const MeshData m = attributed_sphere();
  const VertexTree t = build(m);
  const size_t n = t.node_count();
  ASSERT_EQ(t.uvs1.size(), 2 * n);
  ASSERT_EQ(t.colors.size(), 4 * n);
  ASSERT_EQ(t.normals.size(), 3 * n);
  EXPECT_GT(t.interior_count(), t.leaf_count / 2);  // it did simplify
  EXPECT_EQ(std::memcmp(t.uvs1.data(), m.uvs1.data(), 4 * m.uvs1.size()), 0);
  EXPECT_EQ(std::memcmp(t.colors.data(), m.colors.data(), 4 * m.colors.size()), 0);
  EXPECT_EQ(std::memcmp(t.normals.data(), m.normals.data(), 4 * m.normals.size()), 0);
  VertexFront f;
  front_init(f, t, 1);
  front_refine_all(f, t);
  ASSERT_EQ(f.active_count, t.leaf_count);
  std::vector<float> colors(4 * size_t(f.active_count));
  ASSERT_EQ(front_compact_column(colors, 4, f, t.colors), f.active_count);
  for (uint32_t k = 0; k < f.active_count; ++k)
    for (int c = 0; c < 4; ++c)
      ASSERT_EQ(colors[4 * k + c], m.colors[4 * size_t(f.active[k]) + c]) << "vertex " << k;
}

TEST(VertexHierarchyAttributes, ParentsStayInsideTheirLeavesRangeAndNormalsAreUnit) {
  const MeshData m = attributed_sphere();
  const VertexTree t = build(m);
  expect_inside_leaves_box(t, t.uvs1, 2, "uv1");
  expect_inside_leaves_box(t, t.colors, 4, "colour");
  for (uint32_t v = 0; v < t.node_count(); ++v) {
    const float* q = &t.normals[3 * size_t(v)];
    ASSERT_NEAR(std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]), 1.0, 1e-5) << "node " << v;
    // Radial input normals: a parent's stays near the direction of its position.
    const float* p = &t.positions[3 * size_t(v)];
    const float len = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    EXPECT_GT((q[0] * p[0] + q[1] * p[1] + q[2] * p[2]) / len, 0.5f) << "node " << v;
  }
  // No parent mixes the two colour halves: the equator's copies (a colour seam) never collapse.
  for (uint32_t v = t.leaf_count; v < t.node_count(); ++v) {
    const float* c = &t.colors[4 * size_t(v)];
    const bool red = c[0] == 1 && c[2] == 0 && c[3] == 1,
               blue = c[0] == 0 && c[1] == 0 && c[2] == 1 && c[3] == 0.5f;
    ASSERT_TRUE(red || blue) << "node " << v << " mixes the halves' colours";
  }
}

// An n x n grid in y = 0 whose middle column is two copies, one per side, differing from each
// other only in the attribute `split` sets (every vertex has all three attributes).
MeshData split_grid(int n, int split) {
  MeshData m;
  m.source = "split grid";
  const int half = n / 2;
  auto add_side = [&](int x0, int x1, int side) {
    const uint32_t base = uint32_t(m.vertex_count());
    for (int z = 0; z <= n; ++z)
      for (int x = x0; x <= x1; ++x) {
        const float y = 0.05f * std::sin(float(x)) * std::cos(float(z));
        m.positions.insert(m.positions.end(), {float(x) / float(n), y, float(z) / float(n)});
        const bool seam = x == half;
        const float s = seam ? float(side) : 0.f;
        m.uvs.insert(m.uvs.end(), {float(x) / float(n), float(z) / float(n)});
        m.uvs1.insert(m.uvs1.end(), {0.5f * float(x) / float(n) + (split == 0 ? 0.25f * s : 0.f), 0.5f});
        m.colors.insert(m.colors.end(), {split == 1 ? s : 0.5f, 0.5f, 0.5f, 1});
        const float nx = split == 2 ? 0.6f * (2 * s - 1) : 0.f;
        m.normals.insert(m.normals.end(), {nx, std::sqrt(1 - nx * nx), 0});
      }
    const uint32_t w = uint32_t(x1 - x0 + 1);
    for (int z = 0; z < n; ++z)
      for (int x = 0; x < x1 - x0; ++x) {
        const uint32_t a = base + uint32_t(z) * w + uint32_t(x), b = a + 1, c = a + w, d = c + 1;
        m.indices.insert(m.indices.end(), {a, c, b, b, c, d});
      }
  };
  add_side(0, half, 0);
  add_side(half, n, 1);
  return m;
}

TEST(VertexHierarchyAttributes, CopiesThatDifferInUv1ColourOrNormalArePinned) {
  const int n = 12, half = n / 2;
  for (int split = 0; split < 3; ++split) {
    const MeshData m = split_grid(n, split);
    const VertexTree t = build(m);
    EXPECT_GT(t.interior_count(), 0u) << "split " << split;
    // The seam column: x == half on the left side (last of each row) and the right side (first).
    const uint32_t left_w = uint32_t(half + 1), right_base = uint32_t((n + 1) * (half + 1));
    const uint32_t right_w = uint32_t(n - half + 1);
    for (int z = 0; z <= n; ++z) {
      const uint32_t l = uint32_t(z) * left_w + uint32_t(half), r = right_base + uint32_t(z) * right_w;
      EXPECT_EQ(t.parent[l], kNoNode) << "split " << split << " left copy " << l;
      EXPECT_EQ(t.parent[r], kNoNode) << "split " << split << " right copy " << r;
    }
  }
}

TEST(VertexHierarchyAttributes, OppositeNormalsGiveAUnitParentAndNonUnitInputsAreNormalised) {
  // Every other vertex's normal flipped: many collapses join opposite normals (zero sum).
  MeshData m = split_grid(10, 0);
  for (size_t v = 0; v < m.vertex_count(); v += 2)
    for (int k = 0; k < 3; ++k) m.normals[3 * v + k] = -m.normals[3 * v + k];
  // And one normal twice as long, one zero.
  for (int k = 0; k < 3; ++k) m.normals[3 + k] *= 2;
  for (int k = 0; k < 3; ++k) m.normals[9 + k] = 0;
  const VertexTree t = build(m);
  for (uint32_t v = 0; v < t.node_count(); ++v) {
    const float* q = &t.normals[3 * size_t(v)];
    const double len = std::sqrt(double(q[0]) * q[0] + double(q[1]) * q[1] + double(q[2]) * q[2]);
    if (v == 3) {
      ASSERT_EQ(len, 0.0);  // a zero leaf stays zero
      continue;
    }
    ASSERT_NEAR(len, 1.0, 1e-5) << "node " << v;
  }
  EXPECT_NEAR(t.normals[4], m.normals[4] / 2, 1e-6);
}

TEST(VertexHierarchyAttributes, BadAttributesAreRefusedNamingTheSource) {
  const MeshData good = attributed_sphere(8, 16);
  auto refused = [](const MeshData& m, const std::string& want) {
    VertexTree t;
    const Status s = build_vertex_hierarchy(t, m);
    ASSERT_FALSE(s.ok) << want;
    EXPECT_NE(s.message.find("attributed sphere"), std::string::npos) << s.message;
    EXPECT_NE(s.message.find(want), std::string::npos) << s.message;
    EXPECT_TRUE(t.empty());
  };
  MeshData m = good;
  m.colors.pop_back();
  refused(m, "colour values for");
  m = good;
  m.normals[7] = std::nanf("");
  refused(m, "vertex 2 has a non-finite or huge normal");
  m = good;
  m.uvs1[5] = INFINITY;
  refused(m, "vertex 2 has a non-finite or huge uv1");
}

// ---- the asset's VHAT section, layout 2 -------------------------------------------------------

LodChain attributed_chain() {
  const MeshData m = attributed_sphere(12, 24);
  LodChain c;
  c.name = "ball";
  c.positions = m.positions;
  c.normals = m.normals;
  c.authored_normals = true;
  c.indices = m.indices;
  c.uvs = m.uvs;
  c.uv_errors = {0};
  c.uvs1 = m.uvs1;
  c.uv1_errors = {0};
  c.colors = m.colors;
  c.color_errors = {0};
  LodLevel lv;
  lv.index_count = uint32_t(m.indices.size());
  lv.vertex_count = uint32_t(m.vertex_count());
  lv.level = level_of_triangles(m.triangle_count());
  lv.bounds.radius = 1;
  c.levels.push_back(lv);
  EXPECT_TRUE(build_vertex_hierarchy(c.hierarchy, m).ok);
  return c;
}

size_t table_entry(const std::vector<uint8_t>& bytes, const char* tag) {
  uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 12, 4);
  for (uint32_t s = 0; s < count; ++s)
    if (std::memcmp(bytes.data() + 16 + 24 * size_t(s), tag, 4) == 0) return 16 + 24 * size_t(s);
  return 0;
}

uint64_t vhat_offset(const std::vector<uint8_t>& bytes) {
  uint64_t off = 0;
  std::memcpy(&off, bytes.data() + table_entry(bytes, "VHAT") + 8, 8);
  return off;
}

void fix_checksum(std::vector<uint8_t>& bytes) {
  const uint64_t h = hash_bytes(bytes.data(), bytes.size() - 8);
  std::memcpy(bytes.data() + bytes.size() - 8, &h, 8);
}

template <class T>
std::vector<uint8_t> forge_vhat(std::vector<uint8_t> bytes, size_t at, T value) {
  std::memcpy(bytes.data() + vhat_offset(bytes) + at, &value, sizeof value);
  fix_checksum(bytes);
  return bytes;
}

Status decode(const std::vector<uint8_t>& bytes, LodChain& out) {
  return decode_lod_asset(bytes, "ball.lod", out);
}

TEST(VertexHierarchyAttributesAsset, RoundTripKeepsEveryColumnBitForBit) {
  const LodChain c = attributed_chain();
  const std::vector<uint8_t> bytes = encode_lod_asset(c);
  uint32_t layout = 0, flags = 0;
  std::memcpy(&layout, bytes.data() + vhat_offset(bytes), 4);
  std::memcpy(&flags, bytes.data() + vhat_offset(bytes) + 4, 4);
  EXPECT_EQ(layout, 2u);
  EXPECT_EQ(flags, 15u);
  LodChain back;
  const Status s = decode(bytes, back);
  ASSERT_TRUE(s.ok) << s.message;
  const VertexTree& a = c.hierarchy;
  const VertexTree& b = back.hierarchy;
  for (const auto& [x, y] :
       {std::pair{&a.uvs, &b.uvs}, {&a.uvs1, &b.uvs1}, {&a.colors, &b.colors}, {&a.normals, &b.normals}}) {
    ASSERT_EQ(x->size(), y->size());
    EXPECT_EQ(std::memcmp(x->data(), y->data(), 4 * x->size()), 0);
  }
  // A tree with uvs only is still written as layout 1 (what older builds read).
  LodChain uv_only = c;
  uv_only.hierarchy.uvs1.clear(), uv_only.hierarchy.colors.clear(), uv_only.hierarchy.normals.clear();
  const std::vector<uint8_t> old = encode_lod_asset(uv_only);
  std::memcpy(&layout, old.data() + vhat_offset(old), 4);
  EXPECT_EQ(layout, 1u);
  LodChain back1;
  ASSERT_TRUE(decode(old, back1).ok);
  EXPECT_TRUE(back1.hierarchy.colors.empty());
  EXPECT_EQ(back1.hierarchy.uvs, c.hierarchy.uvs);
}

TEST(VertexHierarchyAttributesAsset, TruncatedOrForgedColumnsAreRefusedNamingTheSection) {
  const LodChain c = attributed_chain();
  const std::vector<uint8_t> good = encode_lod_asset(c);
  const VertexTree& t = c.hierarchy;
  const size_t nodes = t.node_count();
  auto refused = [&](const std::vector<uint8_t>& bytes, const std::string& want) {
    LodChain back;
    const Status s = decode(bytes, back);
    EXPECT_FALSE(s.ok) << want;
    EXPECT_NE(s.message.find("ball.lod"), std::string::npos) << s.message;
    EXPECT_NE(s.message.find(want), std::string::npos) << s.message;
    EXPECT_TRUE(back.hierarchy.empty());
  };
  // Cut short by one node's normal (the table's size says so).
  {
    std::vector<uint8_t> b = good;
    const size_t e = table_entry(b, "VHAT");
    uint64_t size = 0;
    std::memcpy(&size, b.data() + e + 16, 8);
    size -= 12;
    std::memcpy(b.data() + e + 16, &size, 8);
    fix_checksum(b);
    refused(b, "(truncated?)");
  }
  // Flags: a column the bytes do not hold, a bit no layout has, layout 1 with layout 2's bits.
  refused(forge_vhat(good, 4, uint32_t(7)), "(truncated?)");
  refused(forge_vhat(good, 4, uint32_t(31)), "unknown flags 31");
  refused(forge_vhat(good, 0, uint32_t(1)), "unknown flags 15 for layout 1");
  // Values: columns follow the 16-byte head and the uvs, in the order uv1, colour, normal.
  const size_t uv1_at = 16 + 8 * nodes, color_at = uv1_at + 8 * nodes, normal_at = color_at + 16 * nodes;
  refused(forge_vhat(good, uv1_at + 8 * (nodes - 1), std::nanf("")),
          "VHAT section: node " + std::to_string(nodes - 1));
  const uint32_t parent = t.leaf_count;
  refused(forge_vhat(good, color_at + 16 * size_t(parent), 7.f),
          "node " + std::to_string(parent) + " colour lies outside");
  refused(forge_vhat(good, normal_at + 12 * size_t(parent), 2.f),
          "node " + std::to_string(parent) + " normal has length");
  uint32_t leaf = 0;
  while (t.parent[leaf] != kNoNode) ++leaf;  // a root leaf: no parent's range to break first
  refused(forge_vhat(good, color_at + 16 * size_t(leaf), 0.25f),
          "leaf " + std::to_string(leaf) + " colour differs");
  refused(forge_vhat(good, uv1_at + 8 * size_t(leaf), 0.3f), "leaf " + std::to_string(leaf) + " uv1 differs");
  refused(forge_vhat(good, normal_at + 12 * size_t(leaf) + 8, -t.normals[3 * size_t(leaf) + 2]),
          "leaf " + std::to_string(leaf) + " normal differs");
  // Normals in the tree but level 0's not flagged authored.
  LodChain computed = c;
  computed.authored_normals = false;
  refused(encode_lod_asset(computed), "level 0's are not authored");
  // Colours in the tree but none in the levels.
  LodChain bare = c;
  bare.colors.clear();
  bare.color_errors.clear();
  refused(encode_lod_asset(bare), "the levels have none (COL0)");
}

// The fuzz seed for layout 2 (tests/fuzz/corpus/lod/vd2.lod: a small coloured sphere with
// TEXCOORD_1 and authored normals) reads with every column.
TEST(VertexHierarchyAttributesAsset, TheLayoutTwoFuzzSeedReads) {
  LodChain c;
  const Status s = read_lod_asset(std::filesystem::path(LOD_SOURCE_DIR) / "tests/fuzz/corpus/lod/vd2.lod", c);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_TRUE(c.authored_normals);
  const size_t n = c.hierarchy.node_count();
  EXPECT_GT(n, c.hierarchy.leaf_count);
  EXPECT_EQ(c.hierarchy.uvs1.size(), 2 * n);
  EXPECT_EQ(c.hierarchy.colors.size(), 4 * n);
  EXPECT_EQ(c.hierarchy.normals.size(), 3 * n);
}

}  // namespace
}  // namespace lod
