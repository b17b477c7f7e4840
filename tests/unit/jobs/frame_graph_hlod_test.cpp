// The hlod node of the frame graph: HLOD models drawn from a real .hlod file beside discrete
// objects, within what the discrete selection leaves of M, never with a hole.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <thread>

#include "jobs/frame_graph.h"
#include "jobs/hlod_bake.h"
#include "jobs/hlod_read_failures.h"
#include "runtime/hlod_asset.h"
#include "synthetic_scene.h"
#include "test_support.h"

namespace lod {
namespace {

// A sphere of ~25k triangles baked to a .hlod, placed at the origin, scale 20.
std::shared_ptr<HlodModels> sphere_hlod(const std::string& tag, uint64_t budget_bytes) {
  const auto dir = test::temp_dir(tag);
  test::write_text(dir / "big.off", test::sphere_off(80, 160));
  HlodBakeResult baked;
  HlodBakeSettings settings;
  settings.min_verts = 500;
  EXPECT_TRUE(bake_hlod_file(dir / "big.off", "big", dir, settings, nullptr, &baked).ok);
  auto h = std::make_shared<HlodModels>();
  HlodTree tree;
  EXPECT_TRUE(read_hlod_tree(baked.file, tree).ok);
  h->names.push_back("big");
  h->trees.push_back(std::move(tree));
  h->files.push_back(baked.file);
  Transform t;
  t.scale = 20;
  h->transforms.push_back(t);
  h->stream.budget_bytes = budget_bytes;
  return h;
}

View near_origin(uint32_t n) {
  View v;
  v.eye = glm::vec3(0, 5, 300.f - 2.5f * float(n));  // flies toward the model
  v.target = glm::vec3(0, 0, 0);
  return v;
}

uint64_t discrete_triangles(const Frame& f, const Scene& scene) {
  uint64_t tris = 0;
  for (size_t k = 0; k < f.levels.size(); ++k)
    tris += scene.models.triangles[scene.models.first_level[f.models[k]] + f.levels[k]];
  return tris;
}

void run_flight(uint64_t budget, bool expect_fit) {
  const Scene scene = test::synthetic_scene(300, 150);
  FrameGraphOptions o;
  o.threads = 2;
  o.selection.budget = budget;
  o.hlod = sphere_hlod("fg-hlod", 64ull << 20);
  FrameGraph g(scene, o);
  Frame f;
  uint64_t most_nodes = 0;
  for (uint32_t n = 0; n < 100; ++n) {
    g.run(near_origin(n), f);
    const uint64_t discrete = discrete_triangles(f, scene);
    ASSERT_EQ(f.holes, 0u) << "frame " << n << ": the roots are loaded before frame 1";
    ASSERT_GT(f.hlod_nodes_drawn, 0u);
    ASSERT_EQ(f.hlod_drawn.size(), f.hlod_nodes_drawn);
    EXPECT_EQ(f.tris_selected, discrete + f.hlod_tris) << "frame " << n;
    EXPECT_LE(f.resident_bytes, f.stream_budget);
    EXPECT_EQ(f.stream_budget, 64ull << 20);
    const uint64_t left = budget > discrete ? budget - discrete : 0;
    if (!f.over_budget) {
      EXPECT_LE(f.hlod_tris, left) << "frame " << n << ": the HLOD cut gets what M leaves";
    }
    if (expect_fit) {
      EXPECT_FALSE(f.over_budget) << "frame " << n;
    }
    for (const HlodDrawFrame& d : f.hlod_drawn) {
      EXPECT_EQ(d.model, 0u);
      EXPECT_LT(d.layer, o.hlod->trees[0].nodes[d.node].layer_count);
    }
    most_nodes = std::max<uint64_t>(most_nodes, f.hlod_nodes_drawn);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));  // a frame's time: the loaders read
  }
  EXPECT_GT(f.stream_loads, 1u);
  if (expect_fit) {
    EXPECT_GT(most_nodes, 1u) << "the cut refined as the camera came close";
  }
}

TEST(FrameGraphHlod, DrawsTheCutWithinWhatTheDiscreteSelectionLeaves) { run_flight(20000000, true); }
// M binds the discrete objects: the HLOD cut gets the rest, or its smallest cut (over_budget).
TEST(FrameGraphHlod, ABindingBudgetLeavesTheHlodCutTheRest) { run_flight(400000, false); }

// M far below the discrete objects' coarsest levels: the HLOD share is 0, the cut is its
// smallest (the root at its coarsest), the frame says over_budget, and still no hole.
TEST(FrameGraphHlod, NoShareLeftDrawsTheSmallestCut) {
  const Scene scene = test::synthetic_scene(300, 150);
  FrameGraphOptions o;
  o.threads = 2;
  o.selection.budget = 10;
  o.hlod = sphere_hlod("fg-hlod-tight", 64ull << 20);
  FrameGraph g(scene, o);
  Frame f;
  const HlodNode& root = o.hlod->trees[0].nodes[0];
  for (uint32_t n = 0; n < 20; ++n) {
    g.run(near_origin(n * 5), f);
    EXPECT_TRUE(f.over_budget);
    ASSERT_EQ(f.hlod_drawn.size(), 1u);
    EXPECT_EQ(f.hlod_drawn[0].node, 0u);
    EXPECT_EQ(f.hlod_drawn[0].layer, root.layer_count - 1);
    EXPECT_EQ(f.hlod_tris, root.layers[root.layer_count - 1].triangles);
    EXPECT_EQ(f.holes, 0u);
  }
}

// Storage that takes 20 ms per node: the hlod node never waits for it (loads finish on the
// loader threads while frames go on), so its time stays far below one read.
TEST(FrameGraphHlod, SlowReadsNeverStallTheNode) {
  const Scene scene = test::synthetic_scene(300, 150);
  FrameGraphOptions o;
  o.threads = 2;
  o.selection.budget = 20000000;
  auto h = sphere_hlod("fg-hlod-slow", 64ull << 20);
  h->load = [files = h->files, trees = h->trees](uint32_t m, uint32_t node, HlodPayload& out) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    return read_hlod_node(files[m], trees[m].nodes[node], out);
  };
  o.hlod = h;
  FrameGraph g(scene, o);
  Frame f;
  std::vector<double> ms;
  uint64_t loads_at_start = 0;
  for (uint32_t n = 0; n < 100; ++n) {
    g.run(near_origin(n), f);
    if (n == 0) loads_at_start = f.stream_loads;
    ASSERT_EQ(f.holes, 0u);
    ms.push_back(f.stage_ms[size_t(Stage::hlod)]);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  EXPECT_GT(f.stream_loads, loads_at_start + 2) << "loads completed while frames ran";
  std::sort(ms.begin(), ms.end());
  EXPECT_LT(ms[ms.size() / 2], 2.0) << "median hlod node ms";
  EXPECT_LT(ms[ms.size() * 9 / 10], 10.0) << "p90 hlod node ms: a wait would take 20";
}

// The root's children's payloads overwritten with 0xff behind an intact head: as the camera
// comes close, each one read fails once, and the frame names it with the file and the checksum
// (their parent stays drawn); the cache entry is marked bad.
TEST(FrameGraphHlod, ADamagedPayloadIsNamedInTheFrameAndItsEntryMarkedBad) {
  const Scene scene = test::synthetic_scene(300, 150);
  FrameGraphOptions o;
  o.threads = 2;
  o.selection.budget = 20000000;
  auto h = sphere_hlod("fg-hlod-damaged", 64ull << 20);
  h->cache_entry = {1};
  const HlodTree& tree = h->trees[0];
  const HlodNode& root = tree.nodes[0];
  ASSERT_GT(root.child_count, 0u);
  std::vector<uint8_t> bytes = test::read_bytes(h->files[0]);
  std::vector<uint32_t> damaged;
  for (uint32_t c = 0; c < root.child_count; ++c) damaged.push_back(root.first_child + c);
  for (const uint32_t n : damaged)
    std::fill_n(bytes.begin() + std::ptrdiff_t(tree.nodes[n].payload_offset), 64, uint8_t(0xff));
  test::write_bytes(h->files[0], bytes);
  o.hlod = h;
  FrameGraph g(scene, o);
  Frame f;
  for (uint32_t n = 0; n < 100; ++n) {
    g.run(near_origin(n), f);
    ASSERT_EQ(f.holes, 0u) << "the root is sound";
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_EQ(f.stream_failed.size(), f.stream_failures);
  ASSERT_GE(f.stream_failed.size(), 1u) << "the cut wanted a child as the camera came close";
  const std::string file = h->files[0].string();
  for (const HlodFailedFrame& failed : f.stream_failed) {
    EXPECT_EQ(failed.model, 0u);
    EXPECT_NE(std::find(damaged.begin(), damaged.end(), failed.node), damaged.end()) << failed.message;
    EXPECT_EQ(failed.message.rfind(file + ": node " + std::to_string(failed.node) + ": payload checksum mismatch", 0),
              0u)
        << failed.message;
    EXPECT_NE(failed.message.find("marked bad"), std::string::npos) << failed.message;
  }
  std::string why;
  ASSERT_TRUE(entry_marked_bad(h->files[0], &why));
  EXPECT_NE(why.find("payload checksum mismatch"), std::string::npos) << why;
}

TEST(FrameGraphHlod, WithoutHlodModelsTheNodeDrawsNothing) {
  const Scene scene = test::synthetic_scene(300, 150);
  FrameGraph g(scene, FrameGraphOptions{});
  Frame f;
  g.run(near_origin(0), f);
  EXPECT_TRUE(f.hlod_drawn.empty());
  EXPECT_EQ(f.hlod_nodes_drawn, 0u);
  EXPECT_EQ(f.hlod_tris, 0u);
  EXPECT_EQ(f.stream_budget, 0u);
  EXPECT_EQ(f.tris_selected, discrete_triangles(f, scene));
}

}  // namespace
}  // namespace lod
