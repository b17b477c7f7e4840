// Morph targets stored at bake time: each level's vertices into the next coarser level, from
// the simplifier's vertex mapping, so that a level change can blend instead of pop.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <set>

#include "preprocess/lod_bake.h"
#include "runtime/geomorph.h"
#include "test_support.h"

namespace lod {
namespace {

namespace fs = std::filesystem;

// A bumpy sphere (so QEM has real choices to make), written as OFF.
std::string bumpy_sphere_off(int rings, int segments) {
  std::string s = "OFF\n";
  const int verts = 2 + (rings - 1) * segments, faces = 2 * segments * (rings - 1);
  s += std::to_string(verts) + " " + std::to_string(faces) + " 0\n";
  auto put = [&](double x, double y, double z) {
    s += std::to_string(x) + " " + std::to_string(y) + " " + std::to_string(z) + "\n";
  };
  put(0, 1, 0);
  for (int r = 1; r < rings; ++r)
    for (int g = 0; g < segments; ++g) {
      const double th = M_PI * r / rings, ph = 2 * M_PI * g / segments;
      const double k = 1 + 0.08 * std::sin(5 * ph) * std::sin(3 * th);
      put(k * std::sin(th) * std::cos(ph), k * std::cos(th), k * std::sin(th) * std::sin(ph));
    }
  put(0, -1, 0);
  auto ring = [&](int r, int g) { return 1 + (r - 1) * segments + (g % segments); };
  for (int g = 0; g < segments; ++g) s += "3 0 " + std::to_string(ring(1, g + 1)) + " " + std::to_string(ring(1, g)) + "\n";
  for (int r = 1; r + 1 < rings; ++r)
    for (int g = 0; g < segments; ++g) {
      const int a = ring(r, g), b = ring(r, g + 1), c = ring(r + 1, g), d = ring(r + 1, g + 1);
      s += "3 " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(d) + "\n";
      s += "3 " + std::to_string(a) + " " + std::to_string(d) + " " + std::to_string(c) + "\n";
    }
  for (int g = 0; g < segments; ++g)
    s += "3 " + std::to_string(verts - 1) + " " + std::to_string(ring(rings - 1, g)) + " " +
         std::to_string(ring(rings - 1, g + 1)) + "\n";
  return s;
}

LodChain bake(const std::string& tag, const std::string& off, BakeSettings settings, BakeReport* report) {
  const fs::path p = test::temp_dir(tag) / "mesh.off";
  test::write_text(p, off);
  LodChain chain;
  const Status st = bake_model(p, tag, settings, chain, report, nullptr);
  EXPECT_TRUE(st) << st.message;
  return chain;
}

std::span<const float> level_positions(const LodChain& c, uint32_t k) {
  return std::span(c.positions).subspan(3 * size_t(c.levels[k].first_vertex), 3 * size_t(c.levels[k].vertex_count));
}
std::span<const uint32_t> level_indices(const LodChain& c, uint32_t k) {
  return std::span(c.indices).subspan(c.levels[k].first_index, c.levels[k].index_count);
}

using Tri = std::array<uint32_t, 3>;
Tri as_set(uint32_t a, uint32_t b, uint32_t c) {
  Tri t{a, b, c};
  std::sort(t.begin(), t.end());
  return t;
}

// What a renderer draws at w = 1 when blending level `fine` into `coarse`: every fine vertex at
// its composed target. Checks it is the coarse mesh: each drawn vertex sits exactly on a coarse
// vertex, and the non-degenerate drawn triangles are exactly the coarse triangles, as sets.
void expect_collapses_onto(const LodChain& c, uint32_t fine, uint32_t coarse) {
  SCOPED_TRACE("level " + std::to_string(fine) + " -> " + std::to_string(coarse));
  std::vector<uint32_t> target(c.levels[fine].vertex_count);
  compose_morph_targets(target, c, fine, coarse);
  for (uint32_t t : target) ASSERT_LT(t, c.levels[coarse].vertex_count);
  const auto fp = level_positions(c, fine), cp = level_positions(c, coarse);
  std::vector<float> drawn(fp.size());
  level_morph_positions(drawn, fp, cp, target, 0.f);
  EXPECT_TRUE(std::equal(drawn.begin(), drawn.end(), fp.begin())) << "w = 0 must draw the finer level";
  level_morph_positions(drawn, fp, cp, target, 1.f);
  for (size_t v = 0; v < target.size(); ++v)
    for (int k = 0; k < 3; ++k) ASSERT_EQ(drawn[3 * v + k], cp[3 * size_t(target[v]) + k]) << "vertex " << v;
  std::set<Tri> coarse_tris, drawn_tris;
  const auto ci = level_indices(c, coarse), fi = level_indices(c, fine);
  for (size_t i = 0; i < ci.size(); i += 3) coarse_tris.insert(as_set(ci[i], ci[i + 1], ci[i + 2]));
  for (size_t i = 0; i < fi.size(); i += 3) {
    const Tri t = as_set(target[fi[i]], target[fi[i + 1]], target[fi[i + 2]]);
    if (t[0] != t[1] && t[1] != t[2]) drawn_tris.insert(t);
  }
  EXPECT_EQ(drawn_tris.size(), coarse_tris.size());
  EXPECT_TRUE(drawn_tris == coarse_tris) << "drawn triangles are not the coarse triangles";
}

TEST(MorphTargets, QemChainCollapsesOntoEveryCoarserLevel) {
  BakeSettings settings;
  settings.method = SimplifyMethod::qem;
  BakeReport report;
  const LodChain c = bake("morph-qem", bumpy_sphere_off(24, 32), settings, &report);
  ASSERT_GE(c.levels.size(), 4u);
  ASSERT_EQ(c.morph_targets.size(), morph_target_count(c));
  EXPECT_EQ(c.morph_targets.size(), c.positions.size() / 3 - c.levels.back().vertex_count);
  std::string problem;
  EXPECT_TRUE(validate_chain(c, &problem)) << problem;
  for (const std::string& n : report.notes) EXPECT_EQ(n.find("morph targets"), std::string::npos) << n;
  for (uint32_t fine = 0; fine + 1 < c.levels.size(); ++fine)
    for (uint32_t coarse = fine + 1; coarse < c.levels.size(); ++coarse) expect_collapses_onto(c, fine, coarse);
}

TEST(MorphTargets, EveryCoarseVertexIsReachedFromTheFinerLevel) {
  // Each coarse vertex of an edge-collapse chain survived from a fine vertex (same source), so
  // at w = 1 no part of the coarser mesh is missing.
  BakeSettings settings;
  settings.method = SimplifyMethod::qem;
  const LodChain c = bake("morph-onto", bumpy_sphere_off(12, 16), settings, nullptr);
  ASSERT_GE(c.levels.size(), 2u);
  for (uint32_t k = 0; k + 1 < c.levels.size(); ++k) {
    std::vector<uint8_t> reached(c.levels[k + 1].vertex_count, 0);
    for (uint32_t v = 0; v < c.levels[k].vertex_count; ++v) reached[c.morph_targets[c.levels[k].first_vertex + v]] = 1;
    EXPECT_EQ(std::count(reached.begin(), reached.end(), 0), 0) << "level " << k + 1 << " has unreached vertices";
  }
}

TEST(MorphTargets, ClusteringChainHasTargetsInRange) {
  BakeSettings settings;
  settings.method = SimplifyMethod::extreme;
  settings.ratios = {1.0f, 0.3f, 0.1f};
  BakeReport report;
  const LodChain c = bake("morph-cluster", bumpy_sphere_off(16, 20), settings, &report);
  ASSERT_EQ(c.levels.size(), 3u);
  ASSERT_EQ(c.morph_targets.size(), morph_target_count(c));
  std::string problem;
  EXPECT_TRUE(validate_chain(c, &problem)) << problem;
  std::vector<uint32_t> target(c.levels[0].vertex_count);
  compose_morph_targets(target, c, 0, 2);
  for (uint32_t t : target) EXPECT_LT(t, c.levels[2].vertex_count);
  // Figures for the report: how close clustering's mapping comes to collapsing.
  for (uint32_t k = 0; k + 1 < c.levels.size(); ++k) {
    std::vector<uint32_t> one(c.morph_targets.begin() + c.levels[k].first_vertex,
                              c.morph_targets.begin() + c.levels[k].first_vertex + c.levels[k].vertex_count);
    std::cout << "  clustering level " << k << ": "
              << level_morph_misses(one, level_indices(c, k), level_indices(c, k + 1)) << " of "
              << c.levels[k].triangles() << " triangles land on no level " << k + 1 << " triangle\n";
  }
}

TEST(MorphTargets, SingleLevelChainHasNone) {
  BakeSettings settings;
  settings.ratios = {1.0f};
  const LodChain c = bake("morph-single", bumpy_sphere_off(6, 8), settings, nullptr);
  ASSERT_EQ(c.levels.size(), 1u);
  EXPECT_TRUE(c.morph_targets.empty());
}

}  // namespace
}  // namespace lod

namespace lod {
namespace {

// Figures for the report (no timing assertion): what morph targets cost in a real bake and
// whether a scan's QEM chain collapses exactly.
TEST(MorphTargets, DragonChainFigures) {
  LOD_REQUIRE_SHARED_MESH(p, "stanford-dragon.ply");
  LodChain chain;
  BakeReport report;
  ASSERT_TRUE(bake_model(p, "dragon", BakeSettings{}, chain, &report, nullptr));
  ASSERT_EQ(chain.morph_targets.size(), morph_target_count(chain));
  std::string problem;
  EXPECT_TRUE(validate_chain(chain, &problem)) << problem;
  std::cout << "  dragon: bake " << report.seconds << " s, morph targets " << report.morph_seconds << " s for "
            << chain.morph_targets.size() << " vertices (" << report.method << ")\n";
  for (const std::string& n : report.notes) std::cout << "  note: " << n << "\n";
}

}  // namespace
}  // namespace lod
