// HlodStream: select + page as one node, on a synthetic in-memory model.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "jobs/hlod_stream.h"
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
  for (int f = 0; f < 300; ++f) {
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
      ASSERT_TRUE(stream.payload(d.node)) << "frame " << f << " node " << d.node;
      EXPECT_EQ(stream.payload(d.node)->indices.front(), d.node);
    }
    opened += cut.opened.size();
    std::this_thread::sleep_for(std::chrono::microseconds(300));
  }
  const HlodStreamFigures fig = stream.figures();
  EXPECT_GT(fig.stream_loads, 20u);
  EXPECT_GE(fig.stream_requests, fig.stream_loads);
  EXPECT_GT(opened, 300u);
}

}  // namespace
}  // namespace lod
