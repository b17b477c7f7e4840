#include "preprocess/lod_bake.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <iostream>
#include <thread>

#include "test_support.h"

namespace lod {
namespace {

namespace fs = std::filesystem;

fs::path write_sphere(const std::string& tag, int rings, int segments) {
  const fs::path p = test::temp_dir(tag) / "sphere.off";
  test::write_text(p, test::sphere_off(rings, segments));
  return p;
}

void expect_chain_invariants(const LodChain& c) {
  std::string problem;
  EXPECT_TRUE(validate_chain(c, &problem)) << problem;
  ASSERT_FALSE(c.levels.empty());
  EXPECT_EQ(c.levels[0].error, 0.0f);
  EXPECT_EQ(c.levels[0].error_rms, 0.0f);
  EXPECT_EQ(c.normals.size(), c.positions.size());
  for (size_t i = 0; i < c.levels.size(); ++i) {
    const LodLevel& l = c.levels[i];
    EXPECT_EQ(l.level, level_of_triangles(l.triangles()));
    if (i > 0) {
      EXPECT_LT(l.triangles(), c.levels[i - 1].triangles());
      EXPECT_GE(l.error, c.levels[i - 1].error);
      EXPECT_GE(l.error_rms, c.levels[i - 1].error_rms);
    }
    // Every vertex of the level lies inside its bounding sphere.
    for (uint32_t v = l.first_vertex; v < l.first_vertex + l.vertex_count; ++v) {
      const float* p = &c.positions[3 * v];
      const float dx = p[0] - l.bounds.center[0], dy = p[1] - l.bounds.center[1], dz = p[2] - l.bounds.center[2];
      ASSERT_LE(std::sqrt(dx * dx + dy * dy + dz * dz), l.bounds.radius);
    }
    for (uint32_t k = l.first_index; k < l.first_index + l.index_count; ++k) ASSERT_LT(c.indices[k], l.vertex_count);
  }
}

TEST(DefaultRatios, FollowTheReferenceBySize) {
  EXPECT_EQ(default_ratios(5804), (std::vector<float>{1.0f, 0.5f, 0.25f, 0.12f, 0.06f}));
  EXPECT_EQ(default_ratios(69451), (std::vector<float>{1.0f, 0.5f, 0.25f, 0.12f, 0.06f, 0.03f}));
  EXPECT_EQ(default_ratios(345944),
            (std::vector<float>{1.0f, 0.25f, 0.12f, 0.06f, 0.03f, 0.015f, 0.0075f, 0.0037f, 0.0018f}));
  EXPECT_EQ(default_ratios(1087716).size(), 9u);
}

TEST(BakeKey, ChangesWithContentAndSettingsOnly) {
  const fs::path dir = test::temp_dir("bake-key");
  test::write_text(dir / "a.off", test::sphere_off(6, 8));
  test::write_text(dir / "b.off", test::sphere_off(6, 8));
  test::write_text(dir / "c.off", test::sphere_off(6, 9));
  BakeSettings s;
  Status st;
  const uint64_t ka = bake_key(dir / "a.off", s, &st);
  ASSERT_TRUE(st.ok);
  EXPECT_EQ(bake_key(dir / "b.off", s, nullptr), ka);  // same bytes, other name
  EXPECT_NE(bake_key(dir / "c.off", s, nullptr), ka);
  BakeSettings r = s;
  r.ratios = {1.0f, 0.5f};
  EXPECT_NE(bake_key(dir / "a.off", r, nullptr), ka);
  BakeSettings m = s;
  m.method = SimplifyMethod::extreme;
  EXPECT_NE(bake_key(dir / "a.off", m, nullptr), ka);
  bake_key(dir / "missing.off", s, &st);
  EXPECT_FALSE(st.ok);
  EXPECT_NE(st.message.find("missing.off"), std::string::npos);
}

TEST(BakeModel, BakesASphereChainWithMonotonicErrors) {
  const fs::path p = write_sphere("bake-sphere", 30, 40);  // 2,320 triangles
  BakeSettings settings;
  LodChain chain;
  BakeReport report;
  std::vector<std::pair<float, std::string>> progress;
  const Status s = bake_model(p, "sphere", settings, chain, &report,
                              [&](float f, const char* what) { progress.emplace_back(f, what); });
  ASSERT_TRUE(s.ok) << s.message;
  EXPECT_EQ(chain.name, "sphere");
  EXPECT_EQ(chain.source_hash, bake_key(p, settings, nullptr));
  ASSERT_EQ(chain.levels.size(), 5u);
  const std::vector<float> ratios = default_ratios(2320);
  for (size_t i = 0; i < chain.levels.size(); ++i) {
    const double target = ratios[i] * 2320.0;
    EXPECT_NEAR(double(chain.levels[i].triangles()), target, 0.02 * target) << "level " << i;
  }
  expect_chain_invariants(chain);
  EXPECT_GT(chain.levels.back().error, 0.0f);
  EXPECT_LT(chain.levels.back().error, 0.5f);  // a unit sphere at 6 % is still round-ish
  EXPECT_EQ(report.input_triangles, 2320u);
  EXPECT_FALSE(report.cleaned.changed());
  EXPECT_NE(report.method.find("qem"), std::string::npos);
  ASSERT_FALSE(progress.empty());
  EXPECT_EQ(progress.front().second, "load");
  EXPECT_EQ(progress.back().first, 1.0f);
  for (size_t i = 1; i < progress.size(); ++i) EXPECT_GE(progress[i].first, progress[i - 1].first);
  bool saw_simplify = false, saw_measure = false;
  for (const auto& [f, what] : progress) saw_simplify |= what == "simplify", saw_measure |= what == "measure";
  EXPECT_TRUE(saw_simplify);
  EXPECT_TRUE(saw_measure);
}

TEST(BakeModel, ExtremeMethodSaysWhatRanInstead) {
  const fs::path p = write_sphere("bake-extreme", 10, 12);
  BakeSettings settings;
  settings.method = SimplifyMethod::extreme;
  settings.ratios = {1.0f, 0.5f};
  LodChain chain;
  BakeReport report;
  ASSERT_TRUE(bake_model(p, "s", settings, chain, &report, nullptr).ok);
  EXPECT_NE(report.method.find("extreme"), std::string::npos);
  bool noted = false;
  for (const std::string& n : report.notes) noted |= n.find("extreme") != std::string::npos;
  EXPECT_TRUE(noted);
  EXPECT_EQ(chain.levels.size(), 2u);
}

TEST(BakeModel, AutomaticPicksExtremeAboveTheThreshold) {
  const fs::path p = write_sphere("bake-auto", 10, 12);  // 216 triangles
  BakeSettings settings;
  settings.extreme_threshold = 100;
  settings.ratios = {1.0f, 0.5f};
  LodChain chain;
  BakeReport report;
  ASSERT_TRUE(bake_model(p, "s", settings, chain, &report, nullptr).ok);
  EXPECT_NE(report.method.find("extreme"), std::string::npos);
}

TEST(BakeModel, SortsRatiosAndAddsFullDetail) {
  const fs::path p = write_sphere("bake-ratios", 20, 24);
  BakeSettings settings;
  settings.ratios = {0.25f, 0.5f};
  LodChain chain;
  ASSERT_TRUE(bake_model(p, "s", settings, chain, nullptr, nullptr).ok);
  ASSERT_EQ(chain.levels.size(), 3u);
  EXPECT_EQ(chain.levels[0].triangles(), 2u * 24 * 19);
  expect_chain_invariants(chain);
}

TEST(BakeModel, RefusesBadRatiosAndBadFiles) {
  const fs::path p = write_sphere("bake-bad", 6, 8);
  LodChain chain;
  BakeSettings settings;
  settings.ratios = {1.0f, -0.5f};
  Status s = bake_model(p, "s", settings, chain, nullptr, nullptr);
  EXPECT_FALSE(s.ok);
  EXPECT_TRUE(chain.levels.empty());
  s = bake_model(p.parent_path() / "nope.obj", "s", BakeSettings{}, chain, nullptr, nullptr);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("nope.obj"), std::string::npos);
}

TEST(BakeModel, CleansTheInputAndReportsIt) {
  const fs::path dir = test::temp_dir("bake-clean");
  // A closed octahedron plus one duplicate face, one zero-area face (on vertex 8, the
  // octahedron's centre, which nothing else uses) and one stray vertex.
  test::write_text(dir / "o.obj",
                   "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\nv 9 9 9\nv 0 0 0\n"
                   "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n"
                   "f 1 3 5\nf 1 2 8\n");
  BakeSettings settings;
  settings.ratios = {1.0f, 0.5f};
  LodChain chain;
  BakeReport report;
  ASSERT_TRUE(bake_model(dir / "o.obj", "octa", settings, chain, &report, nullptr).ok);
  EXPECT_EQ(report.input_triangles, 10u);
  EXPECT_EQ(report.cleaned.duplicate_faces, 1u);
  EXPECT_EQ(report.cleaned.degenerate_faces, 1u);
  EXPECT_EQ(report.cleaned.unreferenced_vertices, 2u);
  EXPECT_EQ(chain.levels[0].triangles(), 8u);
  EXPECT_EQ(chain.levels[0].vertex_count, 6u);
}

TEST(BakeModel, GivesTheSameChainWhenBakedConcurrently) {
  const fs::path a = write_sphere("bake-par-a", 16, 20);
  const fs::path b = write_sphere("bake-par-b", 12, 30);
  BakeSettings settings;
  settings.ratios = {1.0f, 0.5f, 0.25f};
  LodChain ref_a, ref_b;
  ASSERT_TRUE(bake_model(a, "a", settings, ref_a, nullptr, nullptr).ok);
  ASSERT_TRUE(bake_model(b, "b", settings, ref_b, nullptr, nullptr).ok);
  LodChain par[4];
  Status st[4];
  std::vector<std::thread> threads;
  for (int i = 0; i < 4; ++i)
    threads.emplace_back([&, i] { st[i] = bake_model(i % 2 ? b : a, i % 2 ? "b" : "a", settings, par[i], nullptr, nullptr); });
  for (std::thread& t : threads) t.join();
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(st[i].ok) << st[i].message;
    const LodChain& ref = i % 2 ? ref_b : ref_a;
    EXPECT_EQ(par[i].indices, ref.indices);
    EXPECT_EQ(par[i].positions, ref.positions);
    ASSERT_EQ(par[i].levels.size(), ref.levels.size());
    for (size_t l = 0; l < ref.levels.size(); ++l) EXPECT_EQ(par[i].levels[l].error, ref.levels[l].error);
  }
}

TEST(BakeModel, ParallelForInsideOneModelGivesTheSameBytes) {
  const fs::path p = write_sphere("bake-inner-par", 40, 60);
  BakeSettings serial;
  serial.ratios = {1.0f, 0.5f, 0.25f, 0.12f, 0.06f};
  BakeSettings parallel = serial;
  size_t calls = 0;
  parallel.parallel_for = [&calls](size_t count, const std::function<void(size_t)>& body) {
    ++calls;
    std::vector<std::thread> threads;
    for (size_t i = 0; i < count; ++i) threads.emplace_back(body, i);
    for (std::thread& t : threads) t.join();
  };
  LodChain a, b;
  BakeReport ra, rb;
  ASSERT_TRUE(bake_model(p, "s", serial, a, &ra, nullptr).ok);
  ASSERT_TRUE(bake_model(p, "s", parallel, b, &rb, nullptr).ok);
  EXPECT_GE(calls, 1u) << "the level measurements go through parallel_for (small meshes are not split)";
  EXPECT_EQ(a.indices, b.indices);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.normals, b.normals);
  ASSERT_EQ(a.levels.size(), b.levels.size());
  for (size_t l = 0; l < a.levels.size(); ++l) {
    EXPECT_EQ(a.levels[l].error, b.levels[l].error) << "level " << l;
    EXPECT_EQ(a.levels[l].error_rms, b.levels[l].error_rms) << "level " << l;
  }
  EXPECT_EQ(a.source_hash, b.source_hash) << "the hook is not part of the cache key";
}

TEST(BakeModel, KeepsEveryFaceOfANonManifoldScan) {
  LOD_REQUIRE_SHARED_MESH(p, "stanford-dragon-res4.ply");
  LodChain chain;
  BakeReport report;
  ASSERT_TRUE(bake_model(p, "dragon4", BakeSettings{}, chain, &report, nullptr).ok);
  // 11,102 faces of which 502 repeat an earlier face: level 0 keeps all the rest.
  EXPECT_EQ(report.input_triangles, 11102u);
  EXPECT_EQ(chain.levels[0].triangles(),
            11102u - report.cleaned.duplicate_faces - report.cleaned.degenerate_faces);
  expect_chain_invariants(chain);
  for (const std::string& n : report.notes) std::cout << "  note: " << n << "\n";
}

TEST(BakeModel, CowChainFollowsTheReference) {
  fs::path cow;
  if (!test::shared_meshes().empty() && fs::exists(test::shared_meshes() / "cow.obj"))
    cow = test::shared_meshes() / "cow.obj";
  else if (!test::data_dir().empty())
    cow = test::data_dir() / "cow.off";
  else
    GTEST_SKIP() << "needs ../shared/data/meshes/cow.obj or the CGAL cow.off (absent on this machine)";
  LodChain chain;
  BakeReport report;
  ASSERT_TRUE(bake_model(cow, "cow", BakeSettings{}, chain, &report, nullptr).ok);
  EXPECT_EQ(report.input_triangles, 5804u);
  ASSERT_EQ(chain.levels.size(), 5u);  // Yu, Liang and Chen: 100/50/25/12/6 %
  const std::vector<float> ratios = default_ratios(5804);
  for (size_t i = 0; i < chain.levels.size(); ++i) {
    const double target = ratios[i] * double(chain.levels[0].triangles());
    EXPECT_NEAR(double(chain.levels[i].triangles()), target, 0.02 * target) << "level " << i;
  }
  EXPECT_EQ(chain.levels[0].level, 13);  // round(log2 5804) = 13
  expect_chain_invariants(chain);
  EXPECT_GT(chain.levels.back().error, chain.levels[1].error);
}

TEST(BakeModel, BunnyChainMeetsItsTargets) {
  LOD_REQUIRE_SHARED_MESH(p, "stanford-bunny.obj");
  LodChain chain;
  BakeReport report;
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(bake_model(p, "bunny", BakeSettings{}, chain, &report, nullptr).ok);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(report.input_triangles, 69451u);
  ASSERT_EQ(chain.levels.size(), 6u);
  const std::vector<float> ratios = default_ratios(69451);
  for (size_t i = 0; i < chain.levels.size(); ++i) {
    const double target = ratios[i] * double(chain.levels[0].triangles());
    EXPECT_NEAR(double(chain.levels[i].triangles()), target, 0.02 * target) << "level " << i;
  }
  expect_chain_invariants(chain);
  // Figures for the report, not assertions.
  std::cout << "  bunny bake " << s << " s;";
  for (const LodLevel& l : chain.levels) std::cout << " " << l.triangles() << "/" << l.error;
  std::cout << "\n";
  for (const std::string& n : report.notes) std::cout << "  note: " << n << "\n";
}

}  // namespace
}  // namespace lod
