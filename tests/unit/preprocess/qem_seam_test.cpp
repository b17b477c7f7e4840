// Attribute seams in the QEM simplifier: a seam (one position, a copy of the vertex per side,
// each with its own uv) is simplified along its length, both copies together, never across
// or off it; where it meets a border or branches (three charts at one point) it stays put.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>
#include <numeric>
#include <set>
#include <thread>
#include <tuple>

#include "preprocess/mesh_clean.h"
#include "preprocess/mesh_io.h"
#include "preprocess/qem_simplifier.h"
#include "test_support.h"

namespace lod {
namespace {

// A gently curved (n+1)^2 grid on the unit square cut into uv charts: each vertex gets one
// copy per chart its faces belong to, with that chart's uv. chart(x, y) of a cell names its
// chart; chart c's uvs are the cell's position scaled into [c/4 + 0.02, c/4 + 0.23] in u, so a
// uv blended across charts lands in a gap between the charts' ranges.
struct ChartGrid {
  std::vector<float> positions, uvs;
  std::vector<uint32_t> indices;
  std::vector<int> chart;  // per vertex
  size_t vertex_count() const { return positions.size() / 3; }
  size_t triangle_count() const { return indices.size() / 3; }
};

template <class ChartOf>
ChartGrid chart_grid(int n, ChartOf chart_of) {
  ChartGrid g;
  std::map<std::tuple<int, int, int>, uint32_t> id;  // (x, y, chart) -> vertex
  auto vertex = [&](int x, int y, int c) {
    const auto key = std::make_tuple(x, y, c);
    if (auto it = id.find(key); it != id.end()) return it->second;
    const float u = float(x) / float(n), v = float(y) / float(n);
    g.positions.insert(g.positions.end(), {u, v, 0.15f * std::sin(3 * u) * std::cos(2 * v)});
    g.uvs.insert(g.uvs.end(), {0.25f * float(c) + 0.02f + 0.21f * u, v});
    g.chart.push_back(c);
    return id[key] = uint32_t(g.chart.size() - 1);
  };
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const int c = chart_of(x, y);
      const uint32_t a = vertex(x, y, c), b = vertex(x + 1, y, c), d = vertex(x + 1, y + 1, c), e = vertex(x, y + 1, c);
      g.indices.insert(g.indices.end(), {a, b, d, a, d, e});
    }
  return g;
}

QemOptions uv_options(const ChartGrid& g) {
  QemOptions o;
  o.attributes = g.uvs.data();
  o.attribute_count = 2;
  o.attribute_weight = 0.2f;
  return o;
}

using Key = std::tuple<float, float, float>;
Key key_of(const float* p) { return {p[0], p[1], p[2]}; }

// Input positions held by more than one vertex, with how many.
std::map<Key, int> copies_of(const std::vector<float>& positions) {
  std::map<Key, int> n;
  for (size_t v = 0; v < positions.size() / 3; ++v) n[key_of(&positions[3 * v])]++;
  std::erase_if(n, [](const auto& e) { return e.second < 2; });
  return n;
}

// What must hold for every level of a chart grid: each face lies in one chart (its corners
// descend from one chart's vertices) and its uvs stay in that chart's range; a seam vertex
// comes with all its copies, at one position, each still in its own chart; positions welded,
// the surface has no crack (every interior edge has two faces, the outline one).
void expect_seams_closed(const ChartGrid& g, const ChainLevelOut& level, int n) {
  const size_t nv = level.positions.size() / 3;
  for (size_t t = 0; t < level.triangle_count(); ++t) {
    const uint32_t* f = &level.indices[3 * t];
    const int c = g.chart[level.source_vertex[f[0]]];
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(g.chart[level.source_vertex[f[k]]], c) << "face " << t << " spans two charts";
      const float u = level.attributes[2 * size_t(f[k])];
      EXPECT_GE(u, 0.25f * float(c) + 0.02f - 1e-5f) << "uv smeared out of chart " << c;
      EXPECT_LE(u, 0.25f * float(c) + 0.23f + 1e-5f) << "uv smeared out of chart " << c;
    }
  }
  // Copies at every position of the level, against the input's: a position the level keeps
  // has as many copies as the input had there (no copy left behind or moved alone).
  const std::map<Key, int> in = copies_of(g.positions);
  std::map<Key, int> out;
  for (size_t v = 0; v < nv; ++v) out[key_of(&level.positions[3 * v])]++;
  for (const auto& [p, count] : out) {
    const auto it = in.find(p);
    EXPECT_EQ(count, it == in.end() ? 1 : it->second) << "position (" << std::get<0>(p) << ", " << std::get<1>(p) << ")";
  }
  // Welded by position, every edge inside the square has two faces (one each way).
  std::map<Key, uint32_t> weld;
  std::vector<uint32_t> welded(nv);
  for (size_t v = 0; v < nv; ++v) welded[v] = weld.emplace(key_of(&level.positions[3 * v]), uint32_t(weld.size())).first->second;
  std::map<std::pair<uint32_t, uint32_t>, int> edges;
  for (size_t t = 0; t < level.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) edges[{welded[level.indices[3 * t + k]], welded[level.indices[3 * t + (k + 1) % 3]]}]++;
  auto on_outline = [&](uint32_t v) {
    const float* p = nullptr;
    for (size_t i = 0; i < nv && !p; ++i)
      if (welded[i] == v) p = &level.positions[3 * i];
    return p[0] == 0.f || p[0] == 1.f || p[1] == 0.f || p[1] == 1.f;
  };
  for (const auto& [e, count] : edges) {
    EXPECT_EQ(count, 1) << "edge repeated";
    if (!edges.count({e.second, e.first})) {
      EXPECT_TRUE(on_outline(e.first) && on_outline(e.second)) << "a crack inside the surface (n = " << n << ")";
    }
  }
}

// Vertices of the level on the line x = 0.5 (the seam of a two-chart grid).
size_t on_seam_line(const std::vector<float>& positions) {
  size_t k = 0;
  for (size_t v = 0; v < positions.size() / 3; ++v) k += positions[3 * v] == 0.5f;
  return k;
}

TEST(QemSeams, ASeamIsSimplifiedAlongItsLengthAndStaysClosed) {
  const int n = 40;
  const ChartGrid g = chart_grid(n, [n](int x, int) { return x < n / 2 ? 0 : 1; });
  ASSERT_EQ(copies_of(g.positions).size(), size_t(n + 1));
  const std::vector<size_t> targets = {g.triangle_count() / 2, g.triangle_count() / 8, g.triangle_count() / 16};
  std::vector<ChainLevelOut> levels(targets.size());
  qem_simplify_chain(levels.data(), g.positions.data(), g.vertex_count(), g.indices.data(), g.indices.size(),
                     targets.data(), targets.size(), uv_options(g));
  for (size_t l = 0; l < levels.size(); ++l) {
    SCOPED_TRACE("level " + std::to_string(l));
    EXPECT_LE(double(levels[l].triangle_count()), 1.02 * double(targets[l]));
    expect_seams_closed(g, levels[l], n);
    // The seam's ends (where it meets the border) never move.
    std::set<Key> where;
    for (size_t v = 0; v < levels[l].positions.size() / 3; ++v) where.insert(key_of(&levels[l].positions[3 * v]));
    const float z0 = 0.15f * std::sin(1.5f), z1 = 0.15f * std::sin(1.5f) * std::cos(2.f);
    EXPECT_TRUE(where.count({0.5f, 0.f, z0}) && where.count({0.5f, 1.f, z1})) << "a seam end moved";
  }
  // At 1/16 of the triangles (~50 vertices per chart) the 41 vertex pairs of the seam are
  // down to a handful, not held at full detail.
  const size_t seam_start = on_seam_line(g.positions);
  EXPECT_EQ(seam_start, 2u * size_t(n + 1));
  EXPECT_LT(on_seam_line(levels.back().positions), seam_start / 3);
  EXPECT_GE(on_seam_line(levels.back().positions), 4u) << "both ends, both copies";
}

TEST(QemSeams, ABranchPointOfThreeChartsStaysPut) {
  // Chart 0 left, 1 bottom right, 2 top right: at (0.5, 0.5) three copies meet.
  const int n = 30;
  const ChartGrid g = chart_grid(n, [n](int x, int y) { return x < n / 2 ? 0 : y < n / 2 ? 1 : 2; });
  const size_t target = g.triangle_count() / 12;
  ChainLevelOut level;
  qem_simplify_chain(&level, g.positions.data(), g.vertex_count(), g.indices.data(), g.indices.size(), &target, 1,
                     uv_options(g));
  expect_seams_closed(g, level, n);
  size_t at_branch = 0;
  for (size_t v = 0; v < level.positions.size() / 3; ++v)
    at_branch += level.positions[3 * v] == 0.5f && level.positions[3 * v + 1] == 0.5f;
  EXPECT_EQ(at_branch, 3u) << "the branch point keeps its three copies";
  EXPECT_LE(double(level.triangle_count()), 1.02 * double(target));
}

// Past 20,000 triangles the chain runs on two halves (part seams locked, then merged): the
// uv seam is simplified the same whether the halves ran in parallel or not, and stays closed.
TEST(QemSeams, SplitHalvesKeepTheSeamClosedInParallel) {
  const int n = 110;
  const ChartGrid g = chart_grid(n, [n](int x, int) { return x < n / 2 ? 0 : 1; });
  ASSERT_GT(g.triangle_count(), 20000u);
  const std::vector<size_t> targets = {g.triangle_count() / 4, g.triangle_count() / 40};
  const ParallelFor serial = [](size_t count, const std::function<void(size_t)>& body) {
    for (size_t i = 0; i < count; ++i) body(i);
  };
  const ParallelFor threads = [](size_t count, const std::function<void(size_t)>& body) {
    std::vector<std::thread> ts;
    for (size_t i = 0; i < count; ++i) ts.emplace_back(body, i);
    for (auto& t : ts) t.join();
  };
  std::vector<ChainLevelOut> one(targets.size()), two(targets.size());
  qem_simplify_chain_split(one.data(), g.positions.data(), g.vertex_count(), g.indices.data(), g.indices.size(),
                           targets.data(), targets.size(), uv_options(g), serial);
  qem_simplify_chain_split(two.data(), g.positions.data(), g.vertex_count(), g.indices.data(), g.indices.size(),
                           targets.data(), targets.size(), uv_options(g), threads);
  for (size_t l = 0; l < targets.size(); ++l) {
    SCOPED_TRACE("level " + std::to_string(l));
    EXPECT_EQ(one[l].indices, two[l].indices);
    EXPECT_EQ(one[l].positions, two[l].positions);
    EXPECT_EQ(one[l].attributes, two[l].attributes);
    EXPECT_LE(double(one[l].triangle_count()), 1.02 * double(targets[l]));
    expect_seams_closed(g, one[l], n);
  }
  EXPECT_LT(on_seam_line(one.back().positions), size_t(n + 1)) << "simplified along its length";
}

// Spot's uv charts (../shared): at 6 % of its triangles every face still lies in one chart,
// every seam vertex comes with its copy at one position, and the seams (a large share of
// spot's vertices) are simplified along their length instead of staying at full detail.
TEST(QemSeams, SpotKeepsItsChartsApartAndSimplifiesItsSeams) {
  LOD_REQUIRE_SHARED_MESH(file, "spot.obj");
  MeshData m;
  ASSERT_TRUE(load_mesh(file, m).ok);
  clean_mesh(m);
  ASSERT_EQ(m.uvs.size(), 2 * m.vertex_count());
  // Charts: faces joined through shared vertex ids.
  std::vector<uint32_t> root(m.vertex_count());
  std::iota(root.begin(), root.end(), 0u);
  auto find = [&](uint32_t v) {
    while (root[v] != v) v = root[v] = root[root[v]];
    return v;
  };
  for (size_t t = 0; t < m.triangle_count(); ++t)
    for (int k = 1; k < 3; ++k) root[find(m.indices[3 * t + k])] = find(m.indices[3 * t]);
  const size_t copies_in = [&] {
    size_t k = 0;
    for (const auto& e : copies_of(m.positions)) k += size_t(e.second);
    return k;
  }();
  ASSERT_GT(copies_in, m.vertex_count() / 10) << "spot's seams are a large share of its vertices";
  QemOptions o;
  o.attributes = m.uvs.data();
  o.attribute_count = 2;
  o.attribute_weight = 0.2f;
  const size_t target = m.triangle_count() * 6 / 100;
  ChainLevelOut level;
  qem_simplify_chain(&level, m.positions.data(), m.vertex_count(), m.indices.data(), m.indices.size(), &target, 1, o);
  EXPECT_LE(double(level.triangle_count()), 1.02 * double(target));
  for (size_t t = 0; t < level.triangle_count(); ++t) {
    const uint32_t c = find(level.source_vertex[level.indices[3 * t]]);
    for (int k = 1; k < 3; ++k) ASSERT_EQ(find(level.source_vertex[level.indices[3 * t + k]]), c) << "face across a seam";
  }
  // A level position held by a seam vertex holds all of that position's copies.
  const std::map<Key, int> in = copies_of(m.positions);
  std::map<Key, int> out;
  for (size_t v = 0; v < level.positions.size() / 3; ++v) out[key_of(&level.positions[3 * v])]++;
  size_t copies_out = 0;
  for (const auto& [p, count] : out) {
    const auto it = in.find(p);
    EXPECT_EQ(count, it == in.end() ? 1 : it->second);
    if (it != in.end()) copies_out += size_t(count);
  }
  std::printf("spot: %zu of %zu vertices on seams; at %zu triangles %zu of %zu\n", copies_in, m.vertex_count(),
              level.triangle_count(), copies_out, level.positions.size() / 3);
  EXPECT_LT(copies_out, copies_in / 2) << "the seams were simplified along their length";
}

}  // namespace
}  // namespace lod
