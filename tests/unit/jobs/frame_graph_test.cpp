// FrameGraph: the wired per-frame graph against the stages run by hand.
#include "jobs/frame_graph.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <stdexcept>

#include "runtime/visibility.h"
#include "unit/jobs/synthetic_scene.h"

namespace lod {
namespace {

FrameGraphOptions options_with(uint32_t threads, uint64_t budget, uint32_t grain = 256) {
  FrameGraphOptions o;
  o.threads = threads;
  o.selection.budget = budget;
  o.grain = grain;
  return o;
}

// Triangles at the initial (screen-space) levels, before any budget: the scale budgets bind on.
uint64_t unbudgeted_triangles(const Scene& scene, const View& view) {
  FrameGraph g(scene, options_with(1, UINT64_MAX));
  Frame f;
  g.run(view, f);
  return f.tris_selected;
}

void expect_same_frame(const Frame& a, const Frame& b, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(a.index, b.index);
  EXPECT_EQ(a.objects, b.objects);
  EXPECT_EQ(a.levels, b.levels);
  EXPECT_EQ(a.morph, b.morph);
  EXPECT_EQ(a.visible, b.visible);
  EXPECT_EQ(a.tris_in_view, b.tris_in_view);
  EXPECT_EQ(a.tris_selected, b.tris_selected);
  EXPECT_EQ(a.level_cost, b.level_cost);
  EXPECT_EQ(a.coarsest_cost, b.coarsest_cost);
  EXPECT_EQ(a.over_budget, b.over_budget);
  EXPECT_EQ(a.lowered_steps, b.lowered_steps);
  EXPECT_EQ(a.level_histogram, b.level_histogram);
}

TEST(FrameGraph, SameFramesAtOneTwoAndFourThreads) {
  const Scene scene = test::synthetic_scene(6000, 300);
  const CameraPath path = test::synthetic_config(6000, 300).camera;
  const uint64_t budget = unbudgeted_triangles(scene, view_at(path, 0)) / 3;
  std::vector<std::vector<Frame>> runs;
  for (uint32_t threads : {1u, 2u, 4u}) {
    FrameGraph g(scene, options_with(threads, budget, 128));
    std::vector<Frame> frames(12);
    for (uint32_t n = 0; n < frames.size(); ++n) g.run(view_at(path, n * 7), frames[n]);
    runs.push_back(std::move(frames));
  }
  ASSERT_GT(runs[0][0].lowered_steps, 0u) << "the budget must bind for this test to mean anything";
  for (size_t r = 1; r < runs.size(); ++r)
    for (size_t n = 0; n < runs[0].size(); ++n)
      expect_same_frame(runs[0][n], runs[r][n], "run " + std::to_string(r) + " frame " + std::to_string(n));
}

TEST(FrameGraph, BudgetMetOrFlaggedAtEveryBudget) {
  const Scene scene = test::synthetic_scene(3000, 250);
  const View view = view_at(test::synthetic_config(3000, 250).camera, 30);
  const uint64_t unbudgeted = unbudgeted_triangles(scene, view);
  for (uint64_t budget :
       {uint64_t{0}, uint64_t{1000}, unbudgeted / 50, unbudgeted / 4, unbudgeted, unbudgeted * 2}) {
    FrameGraph g(scene, options_with(2, budget));
    Frame f;
    g.run(view, f);
    ASSERT_GT(f.visible, 0u);
    EXPECT_EQ(f.budget, budget);
    if (f.over_budget) {
      EXPECT_GT(f.coarsest_cost, budget);
      // Flagged frames use the coarsest level of every visible object.
      for (size_t k = 0; k < f.objects.size(); ++k) {
        const uint32_t m = scene.objects.model[f.objects[k]];
        EXPECT_EQ(f.levels[k], scene.models.level_count[m] - 1u);
      }
      EXPECT_EQ(f.tris_selected, f.coarsest_cost);
    } else {
      EXPECT_LE(f.tris_selected, budget) << "budget " << budget;
      EXPECT_LE(f.coarsest_cost, budget);
    }
  }
}

TEST(FrameGraph, LevelBudgetCountsPowersOfTwo) {
  const Scene scene = test::synthetic_scene(2000, 200);
  const View view = view_at(test::synthetic_config(2000, 200).camera, 0);
  FrameGraphOptions o = options_with(2, 0);
  o.selection.count = BudgetCount::levels;
  o.selection.budget = 4000000;
  FrameGraph g(scene, o);
  Frame f;
  g.run(view, f);
  ASSERT_FALSE(f.over_budget);
  EXPECT_LE(f.level_cost, o.selection.budget);
  EXPECT_GT(f.lowered_steps, 0u);
}

TEST(FrameGraph, VisibleObjectsAreExactlyThoseCullSpheresKeeps) {
  const Scene scene = test::synthetic_scene(5000, 300);
  const CameraPath path = test::synthetic_config(5000, 300).camera;
  FrameGraph g(scene, options_with(2, 500000, 100));
  const ObjectSet& o = scene.objects;
  for (uint32_t n : {0u, 50u, 120u}) {
    const View view = view_at(path, n);
    Frame f;
    g.run(view, f);
    std::vector<uint8_t> visible(o.size());
    cull_spheres(visible, o.cx, o.cy, o.cz, o.radius, frustum_of(view));
    std::vector<uint32_t> expected;
    for (uint32_t i = 0; i < visible.size(); ++i)
      if (visible[i]) expected.push_back(i);
    ASSERT_FALSE(expected.empty());
    ASSERT_LT(expected.size(), o.size()) << "the view must cull something";
    EXPECT_EQ(f.objects, expected);
    EXPECT_EQ(f.visible, expected.size());
    EXPECT_EQ(f.levels.size(), expected.size());
    EXPECT_EQ(f.object_count, o.size());
  }
}

TEST(FrameGraph, TotalsMatchThePublishedLevels) {
  const Scene scene = test::synthetic_scene(4000, 250);
  const View view = view_at(test::synthetic_config(4000, 250).camera, 10);
  FrameGraph g(scene, options_with(2, 300000, 64));
  Frame f;
  g.run(view, f);
  uint64_t in_view = 0, selected = 0, cost = 0;
  std::array<uint32_t, kHistogramLevels> histogram{};
  for (size_t k = 0; k < f.objects.size(); ++k) {
    const uint32_t first = scene.models.first_level[scene.objects.model[f.objects[k]]];
    const uint32_t at = first + f.levels[k];
    in_view += scene.models.triangles[first];
    selected += scene.models.triangles[at];
    cost += uint64_t{1} << scene.models.level_l[at];
    ++histogram[scene.models.level_l[at]];
    EXPECT_EQ(f.morph[k], 1.0f);
  }
  EXPECT_EQ(f.tris_in_view, in_view);
  EXPECT_EQ(f.tris_selected, selected);
  EXPECT_EQ(f.level_cost, cost);
  EXPECT_EQ(f.level_histogram, histogram);
  EXPECT_GT(f.tris_in_view, f.tris_selected);
}

TEST(FrameGraph, NothingInViewGivesAnEmptyFrame) {
  const Scene scene = test::synthetic_scene(1000, 100);
  View away;
  away.eye = {0, 5000, 0};
  away.target = {0, 10000, 0};
  away.up = {0, 0, 1};
  away.far_plane = 100;
  FrameGraph g(scene, options_with(2, 10));
  Frame f;
  f.objects.assign(7, 7);  // stale contents must not survive
  g.run(away, f);
  EXPECT_EQ(f.visible, 0u);
  EXPECT_TRUE(f.objects.empty());
  EXPECT_EQ(f.tris_in_view, 0u);
  EXPECT_EQ(f.tris_selected, 0u);
  EXPECT_FALSE(f.over_budget);
  EXPECT_EQ(f.object_count, 1000u);
}

TEST(FrameGraph, EmptySceneRuns) {
  const Scene scene;
  FrameGraph g(scene, options_with(2, 100));
  Frame f;
  g.run(View{}, f);
  EXPECT_EQ(f.object_count, 0u);
  EXPECT_EQ(f.visible, 0u);
  EXPECT_EQ(f.index, 1u);
}

TEST(FrameGraph, FrameIndicesIncreaseByOne) {
  const Scene scene = test::synthetic_scene(500, 100);
  FrameGraph g(scene, options_with(2, 100000));
  Frame f;
  for (uint64_t n = 1; n <= 5; ++n) {
    g.run(View{}, f);
    EXPECT_EQ(f.index, n);
  }
}

TEST(FrameGraph, SetBudgetAppliesToTheNextFrame) {
  const Scene scene = test::synthetic_scene(3000, 250);
  const View view = view_at(test::synthetic_config(3000, 250).camera, 0);
  FrameGraph g(scene, options_with(2, UINT64_MAX));
  Frame f;
  g.run(view, f);
  const uint64_t free_tris = f.tris_selected;
  g.set_budget(free_tris / 2);
  EXPECT_EQ(g.options().selection.budget, free_tris / 2);
  g.run(view, f);
  EXPECT_EQ(f.budget, free_tris / 2);
  EXPECT_LE(f.tris_selected, free_tris / 2);
}

TEST(FrameGraph, StageTimesAreFilledAndBoundedByTheTotal) {
  const Scene scene = test::synthetic_scene(2000, 200);
  FrameGraph g(scene, options_with(2, 100000));
  Frame f;
  g.run(view_at(test::synthetic_config(2000, 200).camera, 0), f);
  // Independent nodes run at the same time, so the stages' sum may pass the frame's wall
  // time; no single stage can.
  for (double ms : f.stage_ms) {
    EXPECT_GE(ms, 0.0);
    EXPECT_LE(ms, f.total_ms);
  }
  EXPECT_GT(f.stage_ms[static_cast<size_t>(Stage::visibility)], 0.0);
}

// The data dependencies of the node table: each node starts after the nodes it reads from.
constexpr std::pair<Stage, Stage> kDataEdges[] = {
    {Stage::commit, Stage::bounds},       {Stage::bounds, Stage::visibility},  {Stage::view, Stage::visibility},
    {Stage::visibility, Stage::scene_hlod}, {Stage::scene_hlod, Stage::importance}, {Stage::importance, Stage::selection}, {Stage::selection, Stage::geomorph},
    {Stage::selection, Stage::vdlod},     {Stage::vdlod, Stage::vd_mesh},      {Stage::geomorph, Stage::publish},
    {Stage::importance, Stage::entries},  {Stage::entries, Stage::vdlod},      {Stage::selection, Stage::hlod},
    {Stage::hlod, Stage::publish},
};

TEST(FrameGraph, StageHookSeesEveryStageOnceAfterItsInputs) {
  const Scene scene = test::synthetic_scene(500, 100);
  std::mutex mutex;  // independent stages may run at once, on whichever worker is free
  std::vector<Stage> seen;
  FrameGraphOptions o = options_with(2, 100000);
  o.stage_hook = [&](Stage s) {
    std::lock_guard lock(mutex);
    seen.push_back(s);
  };
  FrameGraph g(scene, o);
  Frame f;
  for (int frame = 0; frame < 3; ++frame) {
    seen.clear();
    g.run(View{}, f);
    std::lock_guard lock(mutex);
    ASSERT_EQ(seen.size(), kStageCount);
    auto at = [&](Stage s) { return std::find(seen.begin(), seen.end(), s) - seen.begin(); };
    for (size_t i = 0; i < kStageCount; ++i) EXPECT_LT(at(static_cast<Stage>(i)), ptrdiff_t(kStageCount));
    for (auto [from, to] : kDataEdges)
      EXPECT_LT(at(from), at(to)) << kStageNames[size_t(from)] << " -> " << kStageNames[size_t(to)];
  }
}

// geomorph and vdlod share no column, so with two threads they run at the same time: each
// waits (boundedly) for the other to have started.
TEST(FrameGraph, IndependentNodesRunTogether) {
  const Scene scene = test::synthetic_scene(500, 100);
  std::atomic<int> started{0};
  std::atomic<bool> overlapped{false};
  FrameGraphOptions o = options_with(2, 100000);
  o.stage_hook = [&](Stage s) {
    if (s != Stage::geomorph && s != Stage::vdlod) return;
    // The first to start waits for the other; only it can tell that they overlapped.
    if (started.fetch_add(1) != 0) return;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (started.load() < 2 && std::chrono::steady_clock::now() < deadline) std::this_thread::yield();
    overlapped.store(started.load() >= 2);
  };
  FrameGraph g(scene, o);
  Frame f;
  g.run(View{}, f);
  EXPECT_TRUE(overlapped.load()) << "geomorph and vdlod never ran at the same time";
}

TEST(FrameGraph, ThrowingStagePropagatesAndTheNextFrameStartsFresh) {
  const Scene scene = test::synthetic_scene(3000, 250);
  const CameraPath path = test::synthetic_config(3000, 250).camera;
  for (Stage failing : {Stage::visibility, Stage::selection, Stage::publish}) {
    SCOPED_TRACE(kStageNames[static_cast<size_t>(failing)]);
    std::atomic<bool> fail_now{false};
    FrameGraphOptions o = options_with(2, 200000);
    o.stage_hook = [&](Stage s) {
      if (fail_now && s == failing) throw std::runtime_error("injected");
    };
    FrameGraph g(scene, o);
    Frame f;
    g.run(view_at(path, 0), f);
    g.run(view_at(path, 5), f);
    fail_now = true;
    EXPECT_THROW(g.run(view_at(path, 10), f), std::runtime_error);
    fail_now = false;
    g.run(view_at(path, 20), f);

    // After a failure the temporal state is forgotten: the frame equals a fresh graph's.
    FrameGraph fresh(scene, options_with(2, 200000));
    Frame expected;
    fresh.run(view_at(path, 20), expected);
    expected.index = f.index;
    expect_same_frame(f, expected, "after failure");
    EXPECT_EQ(f.index, 4u);
  }
}

TEST(FrameGraph, ChunkSizeDoesNotChangeTheFrame) {
  const Scene scene = test::synthetic_scene(3000, 250);
  const CameraPath path = test::synthetic_config(3000, 250).camera;
  const uint64_t budget = unbudgeted_triangles(scene, view_at(path, 0)) * 2 / 3;
  std::vector<std::vector<Frame>> runs;
  for (uint32_t grain : {1u, 7u, 2048u, 1000000u}) {
    FrameGraph g(scene, options_with(2, budget, grain));
    std::vector<Frame> frames(4);
    for (uint32_t n = 0; n < frames.size(); ++n) g.run(view_at(path, n * 11), frames[n]);
    runs.push_back(std::move(frames));
  }
  ASSERT_GT(runs[0][0].lowered_steps, 0u) << "the budget must bind for this test to mean anything";
  for (size_t r = 1; r < runs.size(); ++r)
    for (size_t n = 0; n < runs[0].size(); ++n)
      expect_same_frame(runs[0][n], runs[r][n],
                        "grain run " + std::to_string(r) + " frame " + std::to_string(n));
}

TEST(FrameGraph, SingleLevelModelsCannotBeLoweredAndAreFlagged) {
  SceneConfig c = test::synthetic_config(300, 50);
  std::vector<LodChain> chains = test::synthetic_chains();
  for (LodChain& chain : chains) chain.levels.resize(1);  // full detail only
  const Scene scene = make_scene(c, chains);
  FrameGraph g(scene, options_with(2, 1000));
  Frame f;
  g.run(view_at(c.camera, 0), f);
  ASSERT_GT(f.visible, 0u);
  EXPECT_TRUE(f.over_budget);
  EXPECT_EQ(f.tris_selected, f.tris_in_view);
  EXPECT_EQ(f.lowered_steps, 0u);
  for (uint8_t l : f.levels) EXPECT_EQ(l, 0);
}

TEST(FrameGraph, CameraInsideAnObjectGivesFiniteResults) {
  const Scene scene = test::synthetic_scene(1000, 100);
  View inside;
  inside.eye = {scene.objects.cx[5], scene.objects.cy[5], scene.objects.cz[5]};
  inside.target = inside.eye + glm::vec3(1, 0, 0);
  FrameGraph g(scene, options_with(2, 50000));
  Frame f;
  g.run(inside, f);
  ASSERT_GT(f.visible, 0u);
  EXPECT_NE(std::find(f.objects.begin(), f.objects.end(), 5u), f.objects.end());
  EXPECT_TRUE(f.over_budget || f.tris_selected <= f.budget);
  for (size_t k = 0; k < f.objects.size(); ++k)
    EXPECT_LT(f.levels[k], scene.models.level_count[scene.objects.model[f.objects[k]]]);
}

TEST(FrameGraph, DotIsTheNodeTable) {
  const std::string dot = FrameGraph::dot();
  EXPECT_EQ(dot.rfind("digraph", 0), 0u);
  for (size_t i = 0; i < kStageCount; ++i)
    EXPECT_NE(dot.find(std::string("  ") + kStageNames[i] + " [label="), std::string::npos) << kStageNames[i];
  for (auto [from, to] : kDataEdges) {
    const std::string edge = std::string(kStageNames[size_t(from)]) + " -> " + kStageNames[size_t(to)] + ";";
    EXPECT_NE(dot.find(edge), std::string::npos) << edge;
  }
  // Independent nodes get no edge, and implied edges are left out.
  EXPECT_EQ(dot.find("geomorph -> vdlod;"), std::string::npos);
  EXPECT_EQ(dot.find("selection -> entries;"), std::string::npos) << "entries runs beside selection";
  EXPECT_EQ(dot.find("commit -> visibility;"), std::string::npos);
  EXPECT_NE(dot.find("reads: "), std::string::npos);
  EXPECT_EQ(dot.back(), '\n');
}

}  // namespace
}  // namespace lod
