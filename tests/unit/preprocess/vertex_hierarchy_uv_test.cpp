// Texture coordinates and materials through the vertex hierarchy: every node carries a uv
// (leaves the input's, parents interpolated along their collapse), attribute seams and
// material boundaries are pinned, so no front smears a texture across a seam, and the asset's
// VHAT section keeps them (refused when truncated or forged).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <numeric>

#include "preprocess/vertex_hierarchy.h"
#include "runtime/lod_asset.h"
#include "runtime/vertex_front.h"
#include "test_support.h"
#include "textured_fixture.h"

namespace lod {
namespace {

// An n x n grid of quads in the y = 0 plane cut into two uv charts at column n / 2: that
// column is two copies (one per chart), the left chart's u runs 0..0.4, the right one's
// 0.6..1 (so the seam is a jump in u); v = z / n in both.
MeshData two_chart_grid(int n) {
  MeshData m;
  m.source = "two-chart grid";
  const int half = n / 2;
  auto add_chart = [&](int x0, int x1, float u0) {
    const uint32_t base = uint32_t(m.vertex_count());
    for (int z = 0; z <= n; ++z)
      for (int x = x0; x <= x1; ++x) {
        // A gentle bump, so collapses have something to weigh.
        const float y = 0.05f * std::sin(float(x)) * std::cos(float(z));
        m.positions.insert(m.positions.end(), {float(x) / float(n), y, float(z) / float(n)});
        m.uvs.insert(m.uvs.end(), {u0 + 0.4f * float(x - x0) / float(x1 - x0), float(z) / float(n)});
      }
    const uint32_t w = uint32_t(x1 - x0 + 1);
    for (int z = 0; z < n; ++z)
      for (int x = 0; x < x1 - x0; ++x) {
        const uint32_t a = base + uint32_t(z) * w + uint32_t(x), b = a + 1, c = a + w, d = c + 1;
        m.indices.insert(m.indices.end(), {a, c, b, b, c, d});
      }
  };
  add_chart(0, half, 0.f);
  add_chart(half, n, 0.6f);
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

// Components of the faces joined through shared vertex ids (not positions): the uv charts.
std::vector<uint32_t> vertex_charts(const MeshData& m) {
  std::vector<uint32_t> rep(m.vertex_count());
  std::iota(rep.begin(), rep.end(), 0u);
  auto find = [&](uint32_t v) {
    while (rep[v] != v) v = rep[v] = rep[rep[v]];
    return v;
  };
  for (size_t f = 0; f < m.triangle_count(); ++f)
    for (int k = 1; k < 3; ++k) rep[find(m.indices[3 * f + k])] = find(m.indices[3 * f]);
  for (uint32_t v = 0; v < rep.size(); ++v) rep[v] = find(v);
  return rep;
}

// Leaves below each node (leaf ids in depth-first order).
std::vector<uint32_t> leaf_order(const VertexTree& t) {
  std::vector<uint32_t> order(t.leaf_count);
  for (uint32_t l = 0; l < t.leaf_count; ++l) order[t.leaf_rank[l]] = l;
  return order;
}

// Every node's uv lies in the box of its leaves' uvs, and all its leaves lie in one chart.
void expect_nodes_inside_their_charts(const VertexTree& t, const std::vector<uint32_t>& chart) {
  const std::vector<uint32_t> order = leaf_order(t);
  for (uint32_t v = t.leaf_count; v < t.node_count(); ++v) {
    float lo[2] = {1e30f, 1e30f}, hi[2] = {-1e30f, -1e30f};
    const uint32_t first_chart = chart[order[t.leaf_lo[v]]];
    for (uint32_t r = t.leaf_lo[v]; r < t.leaf_hi[v]; ++r) {
      const uint32_t l = order[r];
      ASSERT_EQ(chart[l], first_chart) << "node " << v << " joins leaves of two charts";
      for (int k = 0; k < 2; ++k) lo[k] = std::min(lo[k], t.uvs[2 * l + k]), hi[k] = std::max(hi[k], t.uvs[2 * l + k]);
    }
    for (int k = 0; k < 2; ++k) {
      ASSERT_GE(t.uvs[2 * size_t(v) + k], lo[k]) << "node " << v;
      ASSERT_LE(t.uvs[2 * size_t(v) + k], hi[k]) << "node " << v;
    }
  }
}

TEST(VertexHierarchyUv, LeavesKeepTheInputUvsAndTheFullFrontDrawsThem) {
  const MeshData m = two_chart_grid(16);
  const VertexTree t = build(m);
  ASSERT_EQ(t.uvs.size(), 2 * size_t(t.node_count()));
  EXPECT_TRUE(t.seams_pinned);
  EXPECT_TRUE(std::equal(m.uvs.begin(), m.uvs.end(), t.uvs.begin()));  // bit for bit
  EXPECT_GT(t.interior_count(), t.leaf_count / 2);  // it did simplify
  VertexFront f;
  front_init(f, t, 1);
  front_refine_all(f, t);
  std::vector<float> uvs(2 * size_t(f.active_count));
  ASSERT_EQ(front_compact_uvs(uvs, f, t, {}), f.active_count);
  ASSERT_EQ(f.active_count, t.leaf_count);
  for (uint32_t k = 0; k < f.active_count; ++k) {
    const uint32_t leaf = f.active[k];
    EXPECT_EQ(uvs[2 * k], m.uvs[2 * leaf]) << "vertex " << leaf;
    EXPECT_EQ(uvs[2 * k + 1], m.uvs[2 * leaf + 1]) << "vertex " << leaf;
  }
}

TEST(VertexHierarchyUv, NoCollapseJoinsTwoChartsAndParentsStayInTheirLeavesRange) {
  const MeshData m = two_chart_grid(16);
  const VertexTree t = build(m);
  expect_nodes_inside_their_charts(t, vertex_charts(m));
  // The seam's copies are never collapsed: both sides keep the shared vertices (no crack).
  const int n = 16, half = 8;
  for (int z = 0; z <= n; ++z) {
    const uint32_t left = uint32_t(z * (half + 1) + half), right = uint32_t((n + 1) * (half + 1) + z * (n - half + 1));
    ASSERT_EQ(std::memcmp(&m.positions[3 * left], &m.positions[3 * right], 12), 0);
    EXPECT_EQ(t.parent[left], kNoNode) << "seam copy " << left;
    EXPECT_EQ(t.parent[right], kNoNode) << "seam copy " << right;
  }
  // Coarsest front: every corner's uv is that of a node inside one chart, the compact mesh's
  // uvs are the active nodes'.
  VertexFront f;
  front_init(f, t, 1);
  front_coarsen_all(f, t);
  std::string msg;
  EXPECT_TRUE(check_front(f, t, EdgeCheck::oriented, &msg)) << msg;
  std::vector<float> uvs(2 * size_t(f.active_count));
  front_compact_uvs(uvs, f, t, {});
  for (uint32_t k = 0; k < f.active_count; ++k) {
    EXPECT_EQ(uvs[2 * k], t.uvs[2 * size_t(f.active[k])]);
    EXPECT_EQ(uvs[2 * k + 1], t.uvs[2 * size_t(f.active[k]) + 1]);
  }
  EXPECT_LT(f.tri_count, m.triangle_count() / 2);
}

TEST(VertexHierarchyUv, MaterialBoundariesAndUvSeamsArePinnedOnTheTexturedSphere) {
  MeshData m = test::two_material_sphere(12, 24);
  m.source = "sphere";
  const VertexTree t = build(m);
  ASSERT_EQ(t.uvs.size(), 2 * size_t(t.node_count()));
  expect_nodes_inside_their_charts(t, vertex_charts(m));
  // Each node's leaves touch faces of one material only.
  std::vector<int32_t> material(m.vertex_count(), -2);
  std::vector<uint8_t> boundary(m.vertex_count(), 0);
  for (const Submesh& s : m.submeshes)
    for (uint32_t f = s.first_triangle; f < s.first_triangle + s.triangle_count; ++f)
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = m.indices[3 * f + k];
        if (material[v] != -2 && material[v] != s.material) boundary[v] = 1;
        material[v] = s.material;
      }
  size_t pinned = 0;
  for (uint32_t v = 0; v < m.vertex_count(); ++v)
    if (boundary[v]) {
      EXPECT_EQ(t.parent[v], kNoNode) << "material boundary vertex " << v;
      ++pinned;
    }
  EXPECT_EQ(pinned, 25u);  // the equator ring, its seam copy included
  const std::vector<uint32_t> order = leaf_order(t);
  for (uint32_t v = t.leaf_count; v < t.node_count(); ++v)
    for (uint32_t r = t.leaf_lo[v]; r < t.leaf_hi[v]; ++r)
      ASSERT_EQ(material[order[r]], material[order[t.leaf_lo[v]]]) << "node " << v;
  // The price of pinning, printed: roots (never collapsed) and the coarsest front.
  VertexFront f;
  front_init(f, t, 1);
  front_coarsen_all(f, t);
  size_t roots = 0;
  for (uint32_t v = 0; v < t.leaf_count; ++v) roots += t.parent[v] == kNoNode;
  std::printf("globe 12 x 24: %zu of %u input vertices never collapse, coarsest front %u of %zu triangles\n", roots,
              t.leaf_count, f.tri_count, m.triangle_count());
}

TEST(VertexHierarchyUv, BadUvsAndSubmeshesAreRefusedNamingTheSource) {
  MeshData m = two_chart_grid(4);
  VertexTree t;
  m.uvs.pop_back();
  Status s = build_vertex_hierarchy(t, m);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("two-chart grid"), std::string::npos) << s.message;
  m = two_chart_grid(4);
  m.uvs[7] = std::nanf("");
  s = build_vertex_hierarchy(t, m);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("vertex 3"), std::string::npos) << s.message;
  m = two_chart_grid(4);
  m.submeshes = {{0, uint32_t(m.triangle_count()) + 1, 0}};
  s = build_vertex_hierarchy(t, m);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("submesh"), std::string::npos) << s.message;
  EXPECT_TRUE(t.empty());
}

// ---- the asset's VHAT section ----------------------------------------------------------------

LodChain textured_chain(int n = 12) {
  const MeshData m = two_chart_grid(n);
  LodChain c;
  c.name = "grid";
  c.positions = m.positions;
  c.indices = m.indices;
  c.uvs = m.uvs;
  c.uv_errors = {0};
  LodLevel lv;
  lv.index_count = uint32_t(m.indices.size());
  lv.vertex_count = uint32_t(m.vertex_count());
  lv.level = level_of_triangles(m.triangle_count());
  lv.bounds.radius = 1;
  c.levels.push_back(lv);
  EXPECT_TRUE(build_vertex_hierarchy(c.hierarchy, m).ok);
  return c;
}

// Table entry of the section tagged `tag` (its offset and size words follow the tag).
size_t table_entry(const std::vector<uint8_t>& bytes, const char* tag) {
  uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 12, 4);
  for (uint32_t s = 0; s < count; ++s)
    if (std::memcmp(bytes.data() + 16 + 24 * size_t(s), tag, 4) == 0) return 16 + 24 * size_t(s);
  return 0;
}

void fix_checksum(std::vector<uint8_t>& bytes) {
  const uint64_t h = hash_bytes(bytes.data(), bytes.size() - 8);
  std::memcpy(bytes.data() + bytes.size() - 8, &h, 8);
}

// Writes `size` bytes of `value` at `at` within the VHAT section, checksum fixed.
template <class T>
std::vector<uint8_t> forge_vhat(std::vector<uint8_t> bytes, size_t at, T value) {
  const size_t e = table_entry(bytes, "VHAT");
  uint64_t off = 0;
  std::memcpy(&off, bytes.data() + e + 8, 8);
  std::memcpy(bytes.data() + off + at, &value, sizeof value);
  fix_checksum(bytes);
  return bytes;
}

Status decode(const std::vector<uint8_t>& bytes, LodChain& out) { return decode_lod_asset(bytes, "grid.lod", out); }

TEST(VertexHierarchyUvAsset, RoundTripKeepsEveryNodesUv) {
  const LodChain c = textured_chain();
  const std::vector<uint8_t> bytes = encode_lod_asset(c);
  ASSERT_NE(table_entry(bytes, "VHAT"), 0u);
  LodChain back;
  const Status s = decode(bytes, back);
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(back.hierarchy.uvs, c.hierarchy.uvs);
  EXPECT_TRUE(back.hierarchy.seams_pinned);
  EXPECT_EQ(back.hierarchy.positions, c.hierarchy.positions);
  // Through a file too.
  const auto path = test::temp_dir("vh-uv-asset") / "grid.lod";
  ASSERT_TRUE(write_lod_asset(path, c).ok);
  LodChain file;
  ASSERT_TRUE(read_lod_asset(path, file).ok);
  EXPECT_EQ(file.hierarchy.uvs, c.hierarchy.uvs);
}

TEST(VertexHierarchyUvAsset, TreesFromBeforeThePinnedSeamsReadWithoutUvs) {
  LodChain c = textured_chain();
  c.hierarchy.uvs.clear();
  c.hierarchy.seams_pinned = false;
  const std::vector<uint8_t> bytes = encode_lod_asset(c);
  EXPECT_EQ(table_entry(bytes, "VHAT"), 0u);  // what older builds wrote
  LodChain back;
  ASSERT_TRUE(decode(bytes, back).ok);
  EXPECT_FALSE(back.hierarchy.empty());
  EXPECT_TRUE(back.hierarchy.uvs.empty());
  EXPECT_FALSE(back.hierarchy.seams_pinned);
}

TEST(VertexHierarchyUvAsset, TruncatedOrForgedUvDataIsRefusedNamingTheSection) {
  const LodChain c = textured_chain();
  const std::vector<uint8_t> good = encode_lod_asset(c);
  const uint64_t nodes = c.hierarchy.node_count();
  auto refused = [&](const std::vector<uint8_t>& bytes, const std::string& want) {
    LodChain back;
    const Status s = decode(bytes, back);
    EXPECT_FALSE(s.ok) << want;
    EXPECT_NE(s.message.find("grid.lod"), std::string::npos) << s.message;
    EXPECT_NE(s.message.find(want), std::string::npos) << s.message;
    EXPECT_TRUE(back.hierarchy.empty());  // never half-loaded
  };
  // The section cut short by one node's uv (its table size says so; the file stays whole).
  {
    std::vector<uint8_t> b = good;
    const size_t e = table_entry(b, "VHAT");
    uint64_t size = 0;
    std::memcpy(&size, b.data() + e + 16, 8);
    size -= 8;
    std::memcpy(b.data() + e + 16, &size, 8);
    fix_checksum(b);
    refused(b, "VHAT section: " + std::to_string(16 + 8 * (nodes - 1)) + " bytes but");
  }
  // Huge and mismatched counts: refused before anything is allocated.
  refused(forge_vhat(good, 8, uint64_t(1) << 60), "VHAT section: uvs for");
  refused(forge_vhat(good, 8, nodes + 1), "VHAT section: uvs for");
  refused(forge_vhat(good, 0, uint32_t(3)), "layout 3 is newer");
  refused(forge_vhat(good, 4, uint32_t(6)), "unknown flags");
  // A non-finite uv, a parent's uv outside its children's, a leaf's unlike level 0's.
  refused(forge_vhat(good, 16 + 8 * (nodes - 1), std::nanf("")), "VHAT section: node");
  const VertexTree& t = c.hierarchy;
  const uint32_t parent = t.leaf_count;
  refused(forge_vhat(good, 16 + 8 * size_t(parent), 5.f), "VHAT section: node " + std::to_string(parent));
  uint32_t leaf = 0;
  while (t.parent[leaf] != kNoNode) ++leaf;  // a root leaf: no parent's range to break first
  refused(forge_vhat(good, 16 + 8 * size_t(leaf), 0.123f), "leaf " + std::to_string(leaf));
  // Uvs in the tree but none in the levels.
  LodChain bare = c;
  bare.uvs.clear();
  bare.uv_errors.clear();
  refused(encode_lod_asset(bare), "the levels have none");
}

}  // namespace
}  // namespace lod
