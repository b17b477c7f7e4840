// The viewer sees only whole frames: a reader loop doing what the viewer's frame loop does
// (stage the movers and commit, set the view, hold acquire_frame(), build the draw list) while
// the service publishes on its own thread as fast as it can. Every frame read must be self-consistent, and
// what would be submitted must equal its tris_selected plus what its morphing objects add.
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <set>

#include "jobs/scene_motion.h"
#include "jobs/service.h"
#include "runtime/camera_path.h"
#include "viewer/draw_list.h"
#include "viewer/frame_check.h"
#include "viewer/mesh_layout.h"
#include "viewer/scene_loader.h"
#include "viewer/viewer_harness.h"

namespace {

using namespace lod;

const char* kRun = "[run]\nframes = 50\nthreads = 2\nrate_hz = 5000\n[budget]\ntriangles = 60000\n";
const char* kOrbit = R"([camera]
path = "orbit"
radius = 45.0
height_above = 12.0
period_frames = 50
)";
const char* kField = R"([[instances]]
model = "sphere"
count = 200
box_min = [-40.0, 0.0, -40.0]
box_max = [40.0, 0.0, 40.0]
seed = 5
motion = "wander"
speed = 30.0
[[instances]]
model = "box"
count = 200
box_min = [-40.0, 0.0, -40.0]
box_max = [40.0, 0.0, 40.0]
seed = 6
)";

TEST(ViewerFrames, ReaderNeverSeesATornFrameWhileTheServicePublishes) {
  const auto files = lod::test::write_viewer_scene("tearing", kRun, kOrbit, kField);
  viewer::LoadedScene loaded;
  const Status st = viewer::load_scene(files.config, {}, files.dir / "cache", loaded, [](const std::string&) {});
  ASSERT_TRUE(st) << st.message;
  const Scene& scene = loaded.scene;
  const viewer::MeshLayout layout = viewer::layout_meshes(scene.chains);

  FrameGraphOptions options;
  options.threads = 2;
  options.selection = loaded.config.selection;
  std::vector<ObjectHandle> handles;
  const std::unique_ptr<Service> owned = make_service(scene, options, loaded.config.rate_hz, &handles);
  Service& service = *owned;
  SceneMotion motion(loaded.config, scene.objects, handles);
  ASSERT_EQ(motion.moving(), 200u);
  set_view(service, 0, view_at(loaded.config.camera, 0));
  service.start();

  viewer::DrawList list;
  std::set<uint64_t> seen;
  uint64_t last_index = 0;
  size_t reads = 0, torn = 0;
  std::string first_problem;
  // Bounded by distinct frames seen or wall time, whichever comes first; nothing is timed.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  for (uint32_t i = 0; seen.size() < 300 && std::chrono::steady_clock::now() < deadline; ++i) {
    set_view(service, 0, view_at(loaded.config.camera, i / 16));  // the camera moves: levels change
    if (i % 64 == 0) service.set_budget(i % 128 == 0 ? 20000 : 60000);
    motion.stage(service, 0.001 * i);  // and so do half the objects
    service.commit(i + 1);
    const FrameRef held = service.acquire_frame();
    if (!held) continue;  // nothing published yet
    const Frame& f = *held;
    ++reads;
    std::string why;
    const bool whole = viewer::frame_is_whole(f, scene, &why);
    viewer::build_draw_list(f, layout, list);
    // Objects blending two levels are drawn at the finer one: the frame says what that adds.
    if (!whole || list.rejected != 0 || list.triangles != f.tris_selected + f.tris_morph_extra ||
        list.morphing != f.morphing || f.index < last_index) {
      if (torn++ == 0)
        first_problem = "frame " + std::to_string(f.index) + ": " + (whole ? "draw list disagrees" : why);
    }
    last_index = f.index;
    if (f.index > 0) seen.insert(f.index);
  }
  service.stop();
  EXPECT_EQ(torn, 0u) << torn << " of " << reads << " reads were not whole; first: " << first_problem;
  EXPECT_GE(seen.size(), 2u) << "the service published fewer than two frames during " << reads << " reads";
  EXPECT_EQ(service.stats().errors, 0u);
}

}  // namespace
