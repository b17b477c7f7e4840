// Front updates on hierarchies built from generated meshes: long random camera walks keep a
// valid triangulation, and the view criteria put detail where the camera looks.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "preprocess/mesh_clean.h"
#include "preprocess/mesh_io.h"
#include "preprocess/vertex_hierarchy.h"
#include "runtime/geomorph.h"
#include "runtime/vertex_front.h"
#include "test_support.h"
#include "vd_meshes.h"

namespace lod {
namespace {

VertexTree build(const MeshData& m) {
  VertexTree t;
  const Status s = build_vertex_hierarchy(t, m);
  EXPECT_TRUE(s.ok) << s.message;
  return t;
}

FrontView view_at(glm::vec3 eye, glm::vec3 target, int width = 640, int height = 480) {
  View v;
  v.eye = eye;
  v.target = target;
  v.width = width;
  v.height = height;
  v.near_plane = 0.01f;
  v.far_plane = 100.f;
  const float origin[3] = {0, 0, 0};
  return front_view_of(v, origin, 1.f, 0.f);
}

// Walks a camera around `mesh` for `frames` frames: smooth steps, turns and sometimes a
// teleport; checks the whole front after every frame.
void walk(const MeshData& mesh, bool closed, int frames, const FrontParams& base, uint32_t seed) {
  const VertexTree t = build(mesh);
  VertexFront f;
  front_init(f, t, 2.f);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1, 1);
  glm::vec3 eye(0, 0.5f, 3), look(0, 0, 0);
  FrontParams p = base;
  for (int i = 0; i < frames; ++i) {
    if (i % 37 == 36) {
      eye = glm::vec3(u(rng), u(rng), u(rng)) * 3.f;  // teleport
    } else {
      eye += glm::vec3(u(rng), u(rng), u(rng)) * 0.05f;
      look += glm::vec3(u(rng), u(rng), u(rng)) * 0.05f;
    }
    if (glm::length(eye - look) < 0.05f) eye += glm::vec3(0.1f, 0, 0);
    p.time = i / 60.0;
    const FrontStats s = front_update(f, t, view_at(eye, look), p);
    std::string msg;
    ASSERT_TRUE(check_front(f, t, closed ? EdgeCheck::closed : EdgeCheck::oriented, &msg))
        << "frame " << i << ": " << msg;
    if (p.max_triangles) {
      ASSERT_LE(s.active_tris, p.max_triangles) << "frame " << i;
    }
    ASSERT_EQ(s.active_tris, f.tri_count);
  }
}

TEST(VertexFrontWalk, ClosedSphereStaysCrackFreeOnARandomWalk) {
  walk(test::vd_sphere(30, 40), true, 300, FrontParams{}, 1);
}

TEST(VertexFrontWalk, OpenGridStaysValidOnARandomWalk) {
  walk(test::vd_grid(30, 30, 2, -1, -1), false, 300, FrontParams{}, 2);
}

TEST(VertexFrontWalk, SeveralComponentsStayValidUnderABudgetAndFeedback) {
  const MeshData m = test::vd_concat(
      test::vd_concat(test::vd_sphere(20, 24, 0.5f, -0.8f), test::vd_sphere(12, 16, 0.3f, 0.8f)),
      test::vd_grid(16, 16, 1, -0.5f, 0.8f));
  FrontParams p;
  p.max_triangles = 1200;
  p.target_triangles = 1000;
  walk(m, false, 300, p, 3);
}

TEST(VertexFrontWalk, DeferredCollapsesAndOperationLimitsKeepItValid) {
  FrontParams p;
  p.collapse_delay = 0.1f;
  p.max_operations = 40;
  walk(test::vd_sphere(24, 30), true, 300, p, 4);
}

TEST(VertexFrontWalk, DetailFollowsTheCamera) {
  const MeshData m = test::vd_sphere(40, 60);
  const VertexTree t = build(m);
  VertexFront f;
  front_init(f, t, 1.f);
  // Close to the north pole, looking at it.
  for (int i = 0; i < 4; ++i) front_update(f, t, view_at({0, 1.6f, 0.01f}, {0, 0, 0}), FrontParams{});
  size_t near = 0, far = 0;
  for (uint32_t k = 0; k < f.active_count; ++k) {
    const float y = t.positions[3 * size_t(f.active[k]) + 1];
    near += y > 0.7f;
    far += y < -0.7f;
  }
  // The far cap is back-facing and tiny on screen: far less detail than the near cap.
  EXPECT_GT(near, 5 * std::max<size_t>(far, 1));
  EXPECT_LT(f.tri_count, m.triangle_count());
}

TEST(VertexFrontWalk, LookingAwayFallsBackNearTheBaseMesh) {
  const MeshData m = test::vd_sphere(30, 40);
  const VertexTree t = build(m);
  VertexFront f;
  front_init(f, t, 1.f);
  const uint32_t base = f.tri_count;
  front_update(f, t, view_at({0, 0, 3}, {0, 0, 0}), FrontParams{});
  const uint32_t seen = f.tri_count;
  EXPECT_GT(seen, 20 * base);
  // Looking away: only the few coarse nodes whose (conservative) spheres still reach into
  // the frustum stay split.
  front_update(f, t, view_at({0, 0, 3}, {0, 0, 6}), FrontParams{});
  EXPECT_LT(f.tri_count, seen / 20);
  EXPECT_LE(f.tri_count, 4 * base);
}

TEST(VertexFrontWalk, AStillCameraVisitsNothing) {
  const MeshData m = test::vd_sphere(30, 40);
  const VertexTree t = build(m);
  VertexFront f;
  front_init(f, t, 1.f);
  const FrontView v = view_at({0.3f, 0.2f, 2.5f}, {0, 0, 0});
  FrontStats s = front_update(f, t, v, FrontParams{});
  EXPECT_TRUE(s.full_pass);
  EXPECT_GT(s.splits, 0u);
  // One more frame retries what the first deferred (collapses wanted while splitting); then
  // nothing changes and nothing is visited.
  front_update(f, t, v, FrontParams{});
  for (int i = 0; i < 3; ++i) {
    s = front_update(f, t, v, FrontParams{});
    EXPECT_EQ(s.visited, 0u);
  }
  EXPECT_EQ(s.splits + s.collapses, 0u);
}

TEST(VertexFrontWalk, SmallMovesVisitFewNodesAndMatchAFullPass) {
  const MeshData m = test::vd_sphere(60, 80);
  const VertexTree t = build(m);
  VertexFront inc;
  front_init(inc, t, 1.f);
  glm::vec3 eye(0, 0.3f, 2.5f);
  front_update(inc, t, view_at(eye, {0, 0, 0}), FrontParams{});
  uint64_t visited = 0;
  for (int i = 0; i < 20; ++i) {
    eye.x += 0.005f;
    visited += front_update(inc, t, view_at(eye, {0, 0, 0}), FrontParams{}).visited;
  }
  EXPECT_LT(visited / 20, inc.active_count / 4) << "incremental frames should visit a fraction of the front";
  // A fresh front evaluated once from the final view makes the same decisions.
  VertexFront full;
  front_init(full, t, 1.f);
  for (int i = 0; i < 3; ++i) front_update(full, t, view_at(eye, {0, 0, 0}), FrontParams{});
  const double ratio = double(inc.tri_count) / full.tri_count;
  EXPECT_GT(ratio, 0.97);
  EXPECT_LT(ratio, 1.03);
}

// Temporal coherence must never leave a decision stale: after every frame of smooth motion
// (orbiting, turning, moving in and out) the front agrees with judging every node afresh.
TEST(VertexFrontWalk, CoherentFramesAgreeWithAFullReevaluation) {
  const MeshData m = test::vd_sphere(60, 80);
  const VertexTree t = build(m);
  for (float hysteresis : {1.f, 1.5f}) {
    VertexFront f;
    front_init(f, t, 1.f);
    FrontParams p;
    p.hysteresis = hysteresis;
    uint64_t visited = 0, changes = 0;
    for (int i = 0; i < 240; ++i) {
      const float a = 0.01f * i, r = 1.6f + 0.6f * std::sin(0.02f * i);
      const glm::vec3 eye(r * std::sin(a), 0.3f, r * std::cos(a));
      const glm::vec3 look(0.4f * std::sin(0.03f * i), 0.2f * std::cos(0.05f * i), 0);  // the view turns too
      const FrontView v = view_at(eye, look);
      const FrontStats s = front_update(f, t, v, p);
      if (i > 0) visited += s.visited, changes += s.splits + s.collapses;
      std::string msg;
      ASSERT_EQ(front_stale_decisions(f, t, v, p, &msg), 0u) << "hysteresis " << hysteresis << " frame " << i
                                                             << ": " << msg;
    }
    EXPECT_GT(changes, 0u) << "the walk should change the front";
    EXPECT_LT(visited / 239, f.active_count) << "coherent frames should not re-judge everything";
  }
}

// Turning on the spot never moves the eye calendar on, so its far buckets collect the dead
// entries of every re-filed node and must be compacted; check_front audits the books.
TEST(VertexFrontWalk, TurningInPlaceKeepsTheCalendarBooks) {
  const MeshData m = test::vd_sphere(60, 80);
  const VertexTree t = build(m);
  VertexFront f;
  front_init(f, t, 0.5f);
  const glm::vec3 eye(0, 0.2f, 1.6f);
  std::string msg;
  for (int i = 0; i < 1500; ++i) {
    const float a = 0.02f * i;
    const glm::vec3 look = eye + glm::vec3(std::sin(a), 0.3f * std::sin(0.7f * a), -std::cos(a));
    front_update(f, t, view_at(eye, look), FrontParams{});
    if (i % 50 == 49) {
      ASSERT_TRUE(check_front(f, t, EdgeCheck::closed, &msg)) << "frame " << i << ": " << msg;
    }
  }
}

TEST(VertexFrontWalk, FeedbackBringsTrianglesToTheTarget) {
  const MeshData m = test::vd_sphere(80, 100);
  const VertexTree t = build(m);
  VertexFront f;
  front_init(f, t, 0.1f);
  FrontParams p;
  p.target_triangles = 3000;
  p.max_triangles = 3300;
  FrontStats s;
  for (int i = 0; i < 40; ++i) s = front_update(f, t, view_at({0, 0.3f, 2.2f}, {0, 0, 0}), p);
  EXPECT_LE(s.active_tris, 3300u);
  EXPECT_GT(s.active_tris, 3000u * 0.7);
  EXPECT_GT(s.threshold, 0.1f);
}

TEST(VertexFrontWalk, TeleportSettlesWithinThreeFramesUnderTheCap) {
  const MeshData m = test::vd_sphere(80, 100);
  const VertexTree t = build(m);
  VertexFront f;
  front_init(f, t, 1.f);
  FrontParams p;
  p.target_triangles = 4000;
  p.max_triangles = 4400;
  for (int i = 0; i < 30; ++i) front_update(f, t, view_at({0, 0.3f, 2.2f}, {0, 0, 0}), p);
  int frames = 0;
  for (; frames < 10; ++frames) {
    const FrontStats s = front_update(f, t, view_at({0.2f, -2.0f, -0.8f}, {0, 0, 0}), p);
    ASSERT_LE(s.active_tris, 4400u);
    if (frames > 0 && s.splits + s.collapses < 0.02 * s.active_tris) break;
  }
  EXPECT_LE(frames, 3);
}

TEST(VertexFrontWalk, GeomorphMovesEachVertexAtMostItsShareOfTheDistancePerFrame) {
  const MeshData m = test::vd_sphere(30, 40);
  const VertexTree t = build(m);
  VertexFront f;
  front_init(f, t, 1.f);
  VertexMorph morph;
  const float duration = 0.2f;
  vertex_morph_init(morph, t, duration);
  FrontParams p;
  p.collapse_delay = duration;
  std::vector<float> shown(t.positions), before(t.positions);
  std::vector<uint8_t> was_active(t.node_count(), 0);
  const double dt = 1 / 60.0;
  glm::vec3 eye(0, 0, 2.5f);
  size_t checked = 0;
  for (int i = 0; i < 240; ++i) {
    p.time = i * dt;
    eye = glm::vec3(2.5f * std::sin(i * 0.02f), 0.4f, 2.5f * std::cos(i * 0.02f)) *
          (1.f + 0.5f * std::sin(i * 0.05f));
    front_update(f, t, view_at(eye, {0, 0, 0}), p);
    vertex_morph_apply(morph, t, f.frame_events(), p.time);
    std::string msg;
    ASSERT_TRUE(check_front(f, t, EdgeCheck::closed, &msg)) << msg;
    before = shown;
    vertex_morph_positions(shown, morph, f.vertices(), p.time);
    for (const FrontEvent& e : f.frame_events()) {
      if (e.kind != FrontEventKind::collapse) continue;
      // The children had arrived on the parent: it appears exactly where they were shown.
      const uint32_t i_e = e.node - t.leaf_count;
      for (int c = 0; c < 2; ++c)
        for (int k = 0; k < 3; ++k)
          ASSERT_EQ(before[3 * t.children[2 * i_e + c] + k], t.positions[3 * e.node + k])
              << "node " << e.node;
    }
    for (uint32_t v : f.vertices()) {
      if (!was_active[v] || morph.start[v] >= p.time - 1e-9) continue;  // new, or (re)started now
      // A vertex shown last frame moves at most |to - from| * dt / duration.
      float bound = 0, step = 0;
      for (int k = 0; k < 3; ++k) {
        const float d = morph.to[3 * v + k] - morph.from[3 * v + k];
        bound += d * d;
        const float s = shown[3 * v + k] - before[3 * v + k];
        step += s * s;
      }
      ASSERT_LE(std::sqrt(step), std::sqrt(bound) * float(dt / duration) * 1.01f + 1e-6f) << "node " << v;
      ++checked;
    }
    std::fill(was_active.begin(), was_active.end(), 0);
    for (uint32_t v : f.vertices()) was_active[v] = 1;
  }
  EXPECT_GT(checked, 1000u);
  // Settled (t = 1): every shown vertex is exactly at its target, and that is its own position
  // unless it is on its way onto its parent.
  vertex_morph_positions(shown, morph, f.vertices(), 1e9);
  for (uint32_t v : f.vertices()) {
    const uint32_t par = t.parent[v];
    const bool merging = par != kNoNode && f.pending_until[par - t.leaf_count] >= 0;
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(shown[3 * v + k], morph.to[3 * v + k]);
      if (!merging) {
        ASSERT_EQ(shown[3 * v + k], t.positions[3 * v + k]) << "node " << v;
      }
    }
  }
}

}  // namespace
}  // namespace lod

namespace lod {
namespace {

// Real scans: open borders, several components, orientation flips (the res3 reconstructions):
// every front passes whatever check the full mesh itself passes.
void walk_scan(const std::filesystem::path& file) {
  MeshData m;
  ASSERT_TRUE(load_mesh(file, m).ok);
  clean_mesh(m);
  const VertexTree t = build(m);
  const EdgeCheck edges = edge_check_of(m.indices);
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    const glm::vec3 p(m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]);
    lo = glm::min(lo, p), hi = glm::max(hi, p);
  }
  const glm::vec3 c = 0.5f * (lo + hi);
  const float size = glm::length(hi - lo);
  VertexFront f;
  front_init(f, t, 1.f);
  const uint32_t base = f.tri_count;  // the cap cannot go below the base mesh
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1, 1);
  glm::vec3 eye = c + glm::vec3(0, 0, size);
  FrontParams p;
  p.target_triangles = static_cast<uint32_t>(m.triangle_count() / 4);
  p.max_triangles = p.target_triangles + p.target_triangles / 10;
  p.collapse_delay = 0.05f;
  for (int i = 0; i < 60; ++i) {
    if (i % 20 == 19)
      eye = c + glm::vec3(u(rng), u(rng), u(rng)) * size;
    else
      eye += glm::vec3(u(rng), u(rng), u(rng)) * 0.02f * size;
    View v;
    v.eye = eye;
    v.target = c + glm::vec3(u(rng), u(rng), u(rng)) * 0.1f * size;
    v.near_plane = 1e-4f * size;
    v.far_plane = 100 * size;
    const float origin[3] = {0, 0, 0};
    p.time = i / 60.0;
    const FrontStats s = front_update(f, t, front_view_of(v, origin, 1.f, 0.f), p);
    std::string msg;
    ASSERT_TRUE(check_front(f, t, edges, &msg)) << file << " frame " << i << ": " << msg;
    ASSERT_LE(s.active_tris, std::max(p.max_triangles, base));
  }
}

TEST(VertexFrontWalk, OpenScanStaysValid) {
  LOD_REQUIRE_SHARED_MESH(file, "stanford-bunny.obj");
  walk_scan(file);
}

TEST(VertexFrontWalk, ScanWithOrientationFlipsKeepsValidCorners) {
  LOD_REQUIRE_SHARED_MESH(file, "happy-buddha-res3.ply");
  walk_scan(file);
}

}  // namespace
}  // namespace lod
