// A probe of the frame graph's ThreadSanitizer annotations (jobs/frame_graph.cpp): they mark
// only the hand-overs of the node table's edges, so data two nodes without an edge both write
// must still be reported. The commit and view nodes are roots with no edge between them; their
// stage hooks write one counter with no lock. In the TSan build, ctest runs this with
// LOD_TSAN_PROBE=1 and passes only when TSan reports that race (tests/CMakeLists.txt); an
// annotation that ordered every node after every other would hide it. Elsewhere it skips.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <thread>

#include "jobs/frame_graph.h"
#include "unit/jobs/synthetic_scene.h"

namespace lod {
namespace {

TEST(TsanProbe, NodesWithoutAnEdgeRaceOnWhatTheyShare) {
  if (!std::getenv("LOD_TSAN_PROBE")) GTEST_SKIP() << "runs only as the TSan build's probe (LOD_TSAN_PROBE=1)";
  const Scene scene = test::synthetic_scene(200, 50);
  FrameGraphOptions o;
  o.threads = 4;
  long unguarded = 0;
  o.stage_hook = [&](Stage s) {
    if (s != Stage::commit && s != Stage::view) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));  // both roots in flight at once
    ++unguarded;
  };
  FrameGraph g(scene, o);
  Frame f;
  for (int frame = 0; frame < 50; ++frame) g.run(View{}, f);
  EXPECT_EQ(unguarded, 100);
}

}  // namespace
}  // namespace lod
