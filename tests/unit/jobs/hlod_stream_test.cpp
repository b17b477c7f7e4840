// HlodStream: select + page as one node, on a synthetic in-memory model.
#include "jobs/hlod_stream.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>

#include "unit/runtime/hlod_fixtures.h"

namespace lod {
namespace {

Status fill(uint32_t node, HlodPayload& out) {
  out.indices.assign(6, node);
  out.positions.assign(9, float(node));
  out.normals.assign(9, 0.f);
  return Status::success();
}

HlodView view_at(int frame) {
  const float a = float(frame) * 0.03f;
  View v;
  v.eye = glm::vec3(120 * std::cos(a), 20, 120 * std::sin(a));
  v.far_plane = 1e4f;
  return hlod_view_of(v);
}

TEST(HlodStream, FiguresFollowTheCutAndThePagerOnAFlight) {
  HlodTree t = test::full_octree({.depth = 3, .half = 64, .root_error = 16, .triangles = 400});
  uint64_t total = 0;
  for (const HlodNode& n : t.nodes) total += n.resident_bytes;
  const uint64_t budget = total / 3;
  HlodStream stream(std::move(t), {.loader_threads = 2, .budget_bytes = budget, .max_in_flight = 4}, fill);
  Transform tr;
  tr.scale = 2;
  tr.position[1] = -10;
  uint64_t opened = 0;
  for (int f = 0; f < 300 || ((stream.figures().stream_loads <= 20 || opened == 0) && f < 40000); ++f) {
    const bool root_resident = stream.pager().residency()[0] != 0;  // what the cut will see
    const HlodCut& cut = stream.frame(uint64_t(f + 1), tr, view_at(f), {1.0f, 200000});
    const HlodStreamFigures fig = stream.figures();
    EXPECT_EQ(fig.hlod_nodes_drawn, cut.drawn.size());
    EXPECT_EQ(fig.hlod_triangles, cut.triangles);
    EXPECT_LE(fig.hlod_triangles, 200000u);
    EXPECT_LE(fig.resident_bytes, budget);
    EXPECT_EQ(fig.stream_failures, 0u);
    if (root_resident) {
      ASSERT_EQ(fig.holes, 0u) << "frame " << f;
    } else {
      EXPECT_EQ(fig.holes, 1u);  // the root itself, requested
    }
    for (const HlodDraw& d : cut.drawn) {
      ASSERT_TRUE(stream.payload(0, d.node)) << "frame " << f << " node " << d.node;
      EXPECT_EQ(stream.payload(0, d.node)->indices.front(), d.node);
    }
    opened += cut.opened.size();
    std::this_thread::sleep_for(std::chrono::microseconds(300));
  }
  const HlodStreamFigures fig = stream.figures();
  EXPECT_GT(fig.stream_loads, 20u);
  EXPECT_GE(fig.stream_requests, fig.stream_loads);
  EXPECT_GT(opened, 0u);
}

TEST(HlodStream, ModelsShareOneBudgetAndOnePriorityOrder) {
  std::vector<HlodTree> trees;
  trees.push_back(test::full_octree({.depth = 2, .half = 32, .root_error = 8, .triangles = 300}));
  trees.push_back(test::random_octree(5, 400, 4));
  trees.push_back(test::full_octree({.depth = 3, .half = 64, .root_error = 16, .triangles = 200}));
  std::vector<size_t> sizes;
  uint64_t total = 0;
  for (const HlodTree& t : trees) {
    sizes.push_back(t.nodes.size());
    for (const HlodNode& n : t.nodes) total += n.resident_bytes;
  }
  const uint64_t budget = total / 4;
  std::atomic<int> out_of_range{0};
  HlodStream stream(std::move(trees), {.loader_threads = 2, .budget_bytes = budget, .max_in_flight = 6},
                    [&](uint32_t model, uint32_t node, HlodPayload& out) {
                      if (model >= sizes.size() || node >= sizes[model]) ++out_of_range;
                      out.indices.assign(3, model * 100000 + node);
                      return Status::success();
                    });
  ASSERT_EQ(stream.model_count(), 3u);
  std::vector<HlodModelInput> inputs(3);
  for (uint32_t m = 0; m < 3; ++m) {
    inputs[m].transform.position[0] = float(m) * 150 - 150;  // side by side along x
    inputs[m].params = {1.0f, 150000};
  }
  std::vector<uint8_t> seen_root(3, 0);
  auto enough = [&] {
    return seen_root == std::vector<uint8_t>(3, 1) && stream.figures().stream_evictions > 0;
  };
  for (int f = 0; f < 300 || (!enough() && f < 40000); ++f) {
    std::vector<uint8_t> root_resident(3);
    for (uint32_t m = 0; m < 3; ++m) root_resident[m] = stream.residency(m)[0];
    const float x = -200 + float(f % 300) * 400.f / 300.f;  // flying along the row, again and again
    View v;
    v.eye = {x, 40, 90};
    v.target = {x, 0, 0};
    v.far_plane = 1e4f;
    stream.frame(uint64_t(f + 1), hlod_view_of(v), inputs);
    ASSERT_LE(stream.pager().reserved_bytes(), budget);
    for (uint32_t m = 0; m < 3; ++m) {
      const HlodCut& cut = stream.cut(m);
      EXPECT_LE(cut.triangles, 150000u);
      if (root_resident[m]) {
        ASSERT_EQ(cut.holes, 0u) << "model " << m << " frame " << f;
        seen_root[m] = 1;
      }
      for (const HlodDraw& d : cut.drawn) {
        const auto& p = stream.payload(m, d.node);
        ASSERT_TRUE(p);
        ASSERT_EQ(p->indices.front(), m * 100000 + d.node) << "model " << m;
      }
    }
    std::this_thread::sleep_for(std::chrono::microseconds(300));
  }
  EXPECT_EQ(out_of_range, 0);
  EXPECT_EQ(seen_root, std::vector<uint8_t>(3, 1));
  const HlodStreamFigures fig = stream.figures();
  EXPECT_GT(fig.stream_evictions, 0u);  // one budget for the three
  EXPECT_EQ(fig.stream_failures, 0u);
}

}  // namespace
}  // namespace lod
