#include "runtime/roam.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "runtime/terrain_mesh_check.h"

namespace lod {
namespace {

enum class Relief { sines, random };

HeightField make_field(uint32_t levels, Relief relief, uint32_t seed = 1) {
  HeightField f;
  f.width = f.height = (1u << levels) + 1;
  f.heights.resize(f.sample_count());
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-3.f, 3.f);
  for (uint32_t y = 0; y < f.height; ++y)
    for (uint32_t x = 0; x < f.width; ++x)
      f.heights[size_t(y) * f.width + x] =
          relief == Relief::sines ? 6.f * std::sin(0.11f * float(x)) * std::cos(0.07f * float(y)) +
                                        2.f * std::sin(0.5f * float(x + y))
                                  : u(rng);
  return f;
}

// A camera flying diagonally over the terrain at a steady pace, looking ahead and down.
View flying_view(const RoamTerrain& t, int frame) {
  const float side = float(t.size - 1);
  View v;
  const float s = 0.1f * side + 0.006f * side * float(frame);
  v.eye = {s, 12.f, 0.3f * side + 0.5f * s};
  v.target = v.eye + glm::vec3(0.7f, -0.35f, 0.6f);
  v.width = 640;
  v.height = 360;
  v.near_plane = 0.5f;
  v.far_plane = 4 * side;
  return v;
}

std::vector<uint32_t> mesh_of(const RoamState& s, const RoamTerrain& t) {
  std::vector<uint32_t> idx;
  roam_triangles(idx, s, t);
  return idx;
}

// Every visible leaf's diamond projects to at most tau (finest leaves cannot split: error 0).
size_t leaves_over_tau(const RoamState& s, const RoamTerrain& t, const std::vector<uint32_t>& idx,
                       float tau) {
  size_t over = 0;
  for (size_t i = 0; i < idx.size(); i += 3) {
    const int32_t d = roam_diamond_of(t, idx[i + 1], idx[i + 2]);
    if (d >= 0 && roam_projected_error(s, t, d) > tau) ++over;
  }
  return over;
}

TEST(Roam, SizeMustBeASquareOfTwoToTheNPlusOne) {
  EXPECT_TRUE(roam_size_valid(3, 3));
  EXPECT_TRUE(roam_size_valid(1025, 1025));
  EXPECT_FALSE(roam_size_valid(1024, 1024));
  EXPECT_FALSE(roam_size_valid(129, 65));
  EXPECT_FALSE(roam_size_valid(2, 2));
}

TEST(Roam, ResetGivesTheTwoBaseTriangles) {
  const RoamTerrain t = build_roam_terrain(make_field(5, Relief::sines));
  RoamState s;
  roam_reset(s, t);
  const auto idx = mesh_of(s, t);
  EXPECT_EQ(idx.size(), 6u);
  EXPECT_EQ(s.triangle_count, 2u);
  EXPECT_TRUE(check_terrain_mesh(idx, t.size).ok());
}

TEST(Roam, WedgiesAreNestedAndBoundTheTrueError) {
  const RoamTerrain t = build_roam_terrain(make_field(5, Relief::random, 3));
  for (size_t d = 0; d < t.error.size(); ++d)
    for (int32_t c : t.children[d])
      if (c >= 0) {
        EXPECT_GE(t.error[d], t.error[c]);
        EXPECT_GE(t.radius[d] + 1e-4f, glm::length(t.positions[c] - t.positions[d]) + t.radius[c]);
      }
  // Split everything down to a random front, then compare each leaf with the samples it covers.
  RoamState s;
  roam_reset(s, t);
  std::mt19937 rng(5);
  for (int i = 0; i < 200; ++i)
    roam_split(s, t, int32_t(rng() % (t.positions.size() - 1)) | 1);  // odd: never a corner
  const auto idx = mesh_of(s, t);
  for (size_t i = 0; i < idx.size(); i += 3) {
    const glm::vec3 a = t.positions[idx[i]], b = t.positions[idx[i + 1]], c = t.positions[idx[i + 2]];
    const int32_t d = roam_diamond_of(t, idx[i + 1], idx[i + 2]);
    const float bound = d >= 0 ? t.error[d] : 0.f;
    for (const glm::vec3& p : t.positions) {
      // barycentric in the (x, z) plane
      const float det = (b.x - a.x) * (c.z - a.z) - (c.x - a.x) * (b.z - a.z);
      const float u = ((p.x - a.x) * (c.z - a.z) - (c.x - a.x) * (p.z - a.z)) / det;
      const float v = ((b.x - a.x) * (p.z - a.z) - (p.x - a.x) * (b.z - a.z)) / det;
      if (u < -1e-5f || v < -1e-5f || u + v > 1 + 1e-5f) continue;
      const float h = a.y + u * (b.y - a.y) + v * (c.y - a.y);
      EXPECT_LE(std::abs(p.y - h), bound + 1e-4f) << "triangle " << i / 3;
    }
  }
}

TEST(Roam, ForcedSplitsKeepTheMeshCrackFree) {
  const RoamTerrain t = build_roam_terrain(make_field(6, Relief::random));
  RoamState s;
  roam_reset(s, t);
  std::mt19937 rng(9);
  for (int i = 0; i < 50; ++i) {
    const int32_t d = int32_t(rng() % t.positions.size());
    if (t.triangles[d] == 0) continue;  // a grid corner is no diamond
    roam_split(s, t, d);
    const auto idx = mesh_of(s, t);
    const TerrainMeshCheck c = check_terrain_mesh(idx, t.size);
    ASSERT_TRUE(c.ok()) << c.first_problem;
    ASSERT_EQ(c.triangles, s.triangle_count);
  }
}

TEST(Roam, SplittingEveryDiamondGivesTheFullGrid) {
  for (uint32_t levels : {1u, 2u, 4u}) {
    const RoamTerrain t = build_roam_terrain(make_field(levels, Relief::random));
    RoamState s;
    roam_reset(s, t);
    for (size_t d = 0; d < t.positions.size(); ++d)
      if (t.triangles[d] > 0) roam_split(s, t, int32_t(d));
    const auto idx = mesh_of(s, t);
    const uint32_t cells = (t.size - 1) * (t.size - 1);
    EXPECT_EQ(idx.size() / 3, 2u * cells);
    EXPECT_EQ(s.triangle_count, 2u * cells);
    EXPECT_TRUE(check_terrain_mesh(idx, t.size).ok());
    EXPECT_TRUE(s.split_queue.heap.empty());  // nothing left to split
  }
}

TEST(Roam, UpdatesNeverReallocateTheirState) {
  const RoamTerrain t = build_roam_terrain(make_field(7, Relief::random));
  RoamState s;
  roam_reset(s, t);
  const void* heaps[2] = {s.split_queue.heap.data(), s.merge_queue.heap.data()};
  const void* columns[2] = {s.split.data(), s.priority.data()};
  RoamParams p;
  p.pixel_error = 0.5f;
  for (int frame = 0; frame < 30; ++frame) roam_update(s, t, flying_view(t, 4 * frame), p);
  EXPECT_EQ(heaps[0], s.split_queue.heap.data());
  EXPECT_EQ(heaps[1], s.merge_queue.heap.data());
  EXPECT_EQ(columns[0], s.split.data());
  EXPECT_EQ(columns[1], s.priority.data());
}

// A fresh state after one update (unbounded unless p says otherwise).
RoamState updated_once(const RoamTerrain& t, const View& v, const RoamParams& p) {
  RoamState s;
  roam_reset(s, t);
  roam_update(s, t, v, p);
  return s;
}

// Frames after a bound one, at the same view: crack-free each, unbound within a few, and then
// the mesh one unbounded update made (`full`), spread over several frames.
void expect_catches_up(RoamState& s, const RoamTerrain& t, const View& v, const RoamParams& p, const RoamState& full) {
  RoamFrameStats st;
  int frames = 1;
  do {
    st = roam_update(s, t, v, p);
    ASSERT_TRUE(check_terrain_mesh(mesh_of(s, t), t.size).ok());
  } while (st.budget_bound && ++frames < 1000);
  EXPECT_EQ(st.budget_bound, 0);
  EXPECT_EQ(st.time_bound, 0);
  EXPECT_GE(frames, 2);
  EXPECT_EQ(s.split, full.split);
}

TEST(Roam, OperationBudgetBoundsAFrameAndLaterFramesCatchUp) {
  const RoamTerrain t = build_roam_terrain(make_field(7, Relief::sines));
  const View v = flying_view(t, 5);
  RoamParams p;
  p.pixel_error = 1.f;
  const RoamState full = updated_once(t, v, p);
  p.max_operations = 40;
  RoamState s;
  roam_reset(s, t);
  const RoamFrameStats st = roam_update(s, t, v, p);
  EXPECT_EQ(st.budget_bound, 1);
  EXPECT_LT(st.triangles, full.triangle_count);
  expect_catches_up(s, t, v, p, full);
}

// A clock that moves `step` ms at every read, so a time limit stops at a known operation.
struct SteppingClock {
  double now = 0, step = 0;
  uint32_t reads = 0;
  static double read(const void* c) {
    auto* self = const_cast<SteppingClock*>(static_cast<const SteppingClock*>(c));
    ++self->reads;
    return self->now += self->step;
  }
  RoamClock clock() const { return {&SteppingClock::read, this}; }
};

TEST(Roam, TimeLimitStopsAtTheClockAndLaterFramesCatchUp) {
  const RoamTerrain t = build_roam_terrain(make_field(7, Relief::sines));
  const View v = flying_view(t, 5);
  RoamParams p;
  p.pixel_error = 1.f;
  const RoamState full = updated_once(t, v, p);
  SteppingClock c{0, 1.0};  // 1 ms a read: the first read after the start passes 0.5 ms
  p.max_ms = 0.5f;
  p.clock = c.clock();
  RoamState s;
  roam_reset(s, t);
  const RoamFrameStats st = roam_update(s, t, v, p);
  EXPECT_EQ(st.time_bound, 1);
  EXPECT_EQ(st.budget_bound, 1);
  EXPECT_EQ(c.reads, 2u);  // the start, then one read a stride: the second one expired
  EXPECT_GE(st.splits, kRoamClockStride - 1);  // forced splits come with some of the operations
  EXPECT_LT(st.triangles, full.triangle_count);
  expect_catches_up(s, t, v, p, full);
}

TEST(Roam, AClockThatDoesNotRunOutChangesNothing) {
  const RoamTerrain t = build_roam_terrain(make_field(7, Relief::random, 4));
  RoamParams p;
  p.pixel_error = 1.5f;
  RoamParams timed = p;
  SteppingClock c{0, 0.0};
  timed.max_ms = 1.f;
  timed.clock = c.clock();
  RoamState a, b;
  roam_reset(a, t);
  roam_reset(b, t);
  for (int frame = 0; frame < 30; ++frame) {
    roam_update(a, t, flying_view(t, 4 * frame), p);
    const RoamFrameStats st = roam_update(b, t, flying_view(t, 4 * frame), timed);
    ASSERT_EQ(st.time_bound, 0);
    ASSERT_EQ(a.split, b.split) << "frame " << frame;
  }
  EXPECT_GT(c.reads, 30u);  // it was read, every frame
}

TEST(Roam, ACutShortPixelFrameBothSplitsAndMerges) {
  const RoamTerrain t = build_roam_terrain(make_field(7, Relief::sines));
  RoamParams p;
  p.pixel_error = 1.f;
  RoamState s;
  roam_reset(s, t);
  roam_update(s, t, flying_view(t, 0), p);
  SteppingClock c{0, 1.0};
  p.max_ms = 0.5f;
  p.clock = c.clock();
  // Far ahead: much to merge behind, much to split in front; a frame cut short does some of both.
  const RoamFrameStats st = roam_update(s, t, flying_view(t, 90), p);
  EXPECT_EQ(st.time_bound, 1);
  EXPECT_GT(st.splits, 0u);
  EXPECT_GT(st.merges, 0u);
  EXPECT_TRUE(check_terrain_mesh(mesh_of(s, t), t.size).ok());
}

TEST(Roam, TimeTargetRefinesTowardsItsCountAsTheClockAllows) {
  const RoamTerrain t = build_roam_terrain(make_field(7, Relief::random, 2));
  RoamParams p;
  p.target = RoamTarget::time_limit;
  p.triangle_count = 4001;
  SteppingClock c{0, 1.0};
  p.max_ms = 2.5f;  // two strides a frame
  p.clock = c.clock();
  RoamState s;
  roam_reset(s, t);
  const View v = flying_view(t, 10);
  uint32_t last = 0;
  RoamFrameStats st;
  int frames = 0;
  for (; frames < 400; ++frames) {
    st = roam_update(s, t, v, p);
    ASSERT_TRUE(check_terrain_mesh(mesh_of(s, t), t.size).ok());
    ASSERT_LE(st.triangles, p.triangle_count);
    if (!st.time_bound) break;
    if (last + 2 < p.triangle_count) EXPECT_GE(st.triangles, last);  // a still camera: each frame goes on from the last
    last = st.triangles;
  }
  EXPECT_GT(frames, 5);
  EXPECT_EQ(st.time_bound, 0);
  EXPECT_GE(st.triangles + 2, p.triangle_count);
}

class RoamFlight : public ::testing::TestWithParam<Relief> {};

TEST_P(RoamFlight, EveryFrameIsCrackFreeAndMeetsThePixelError) {
  const RoamTerrain t = build_roam_terrain(make_field(7, GetParam()));
  RoamState s;
  roam_reset(s, t);
  RoamParams p;
  p.pixel_error = 2.f;
  std::vector<uint32_t> idx;
  uint32_t changes = 0;
  for (int frame = 0; frame < 60; ++frame) {
    const RoamFrameStats st = roam_update(s, t, flying_view(t, frame), p);
    roam_triangles(idx, s, t);
    const TerrainMeshCheck c = check_terrain_mesh(idx, t.size);
    ASSERT_TRUE(c.ok()) << "frame " << frame << ": " << c.first_problem;
    ASSERT_EQ(c.triangles, st.triangles);
    ASSERT_EQ(st.budget_bound, 0);
    EXPECT_EQ(leaves_over_tau(s, t, idx, p.pixel_error), 0u) << "frame " << frame;
    if (frame > 0) changes += st.splits + st.merges;
  }
  EXPECT_GT(changes, 0u);  // the camera moved: the mesh followed
}

TEST_P(RoamFlight, TriangleTargetIsMetWithinOneDiamond) {
  const RoamTerrain t = build_roam_terrain(make_field(7, GetParam()));
  RoamState s;
  roam_reset(s, t);
  RoamParams p;
  p.target = RoamTarget::triangle_count;
  p.triangle_count = 3001;
  std::vector<uint32_t> idx;
  for (int frame = 0; frame < 60; ++frame) {
    const RoamFrameStats st = roam_update(s, t, flying_view(t, frame), p);
    roam_triangles(idx, s, t);
    const TerrainMeshCheck c = check_terrain_mesh(idx, t.size);
    ASSERT_TRUE(c.ok()) << "frame " << frame << ": " << c.first_problem;
    EXPECT_LE(c.triangles, p.triangle_count) << "frame " << frame;
    EXPECT_GE(c.triangles + 2, p.triangle_count) << "frame " << frame;
    EXPECT_EQ(st.budget_bound, 0);
  }
}

TEST_P(RoamFlight, IncrementalEqualsFromScratchAtAPixelError) {
  const RoamTerrain t = build_roam_terrain(make_field(7, GetParam()));
  RoamState s, fresh;
  roam_reset(s, t);
  RoamParams p;
  p.pixel_error = 1.5f;
  for (int frame = 0; frame < 40; ++frame) {
    const View v = flying_view(t, 3 * frame);
    roam_update(s, t, v, p);
    roam_reset(fresh, t);
    roam_update(fresh, t, v, p);
    ASSERT_EQ(s.split, fresh.split) << "frame " << frame;
    ASSERT_EQ(s.triangle_count, fresh.triangle_count);
  }
}

// At a triangle count the result depends on the path (forced splits are kept or traded), so
// incremental and from-scratch meshes differ; the tolerance: the worst visible leaf of the
// incremental mesh is within 25 % of the from-scratch one's, plus 0.05 pixel.
float worst_leaf(const RoamState& s, const RoamTerrain& t) {
  float worst = 0;
  for (int32_t d : s.split_queue.heap) worst = std::max(worst, roam_projected_error(s, t, d));
  return worst;
}

TEST_P(RoamFlight, IncrementalIsWithinToleranceOfFromScratchAtATriangleCount) {
  const RoamTerrain t = build_roam_terrain(make_field(7, GetParam()));
  RoamState s, fresh;
  roam_reset(s, t);
  RoamParams p;
  p.target = RoamTarget::triangle_count;
  p.triangle_count = 2000;
  float worst_ratio = 0;
  for (int frame = 0; frame < 40; ++frame) {
    const View v = flying_view(t, 3 * frame);
    roam_update(s, t, v, p);
    roam_reset(fresh, t);
    roam_update(fresh, t, v, p);
    const float inc = worst_leaf(s, t), scratch = worst_leaf(fresh, t);
    EXPECT_LE(inc, 1.25f * scratch + 0.05f) << "frame " << frame;
    worst_ratio = std::max(worst_ratio, inc / std::max(scratch, 1e-6f));
  }
  RecordProperty("worst_ratio", std::to_string(worst_ratio));
  std::printf("incremental / from-scratch worst leaf error, worst frame: %.3f\n", worst_ratio);
}

TEST_P(RoamFlight, ASteadyFlightReKeysOnlyPartOfTheFront) {
  const RoamTerrain t = build_roam_terrain(make_field(7, GetParam()));
  RoamState s;
  roam_reset(s, t);
  RoamParams p;
  p.pixel_error = 1.f;
  size_t rekeyed = 0, front = 0;
  for (int frame = 0; frame < 40; ++frame) {
    const RoamFrameStats st = roam_update(s, t, flying_view(t, frame), p);
    if (frame == 0) continue;
    rekeyed += st.rekeyed;
    front += s.split_queue.heap.size() + s.merge_queue.heap.size();
  }
  EXPECT_LT(rekeyed, front / 2);  // deadlines spare most of the front
  View turned = flying_view(t, 40);
  turned.target = turned.eye + glm::vec3(-0.6f, -0.35f, 0.7f);
  const size_t before = s.split_queue.heap.size() + s.merge_queue.heap.size();
  EXPECT_EQ(roam_update(s, t, turned, p).rekeyed, before);  // a turn re-keys everything
}

INSTANTIATE_TEST_SUITE_P(Reliefs, RoamFlight, ::testing::Values(Relief::sines, Relief::random));

std::vector<int32_t> members(const RoamQueue& q) {
  std::vector<int32_t> m(q.heap);
  std::sort(m.begin(), m.end());
  return m;
}

TEST(Roam, MergesUndoSplitsExactly) {
  const RoamTerrain t = build_roam_terrain(make_field(6, Relief::sines));
  RoamState s;
  roam_reset(s, t);
  RoamParams p;
  p.pixel_error = 4.f;
  roam_update(s, t, flying_view(t, 10), p);
  const RoamState before = s;
  // A finest diamond near a corner: its split forces a chain of splits up the bintree.
  roam_split(s, t, int32_t(2 * t.size + 1) + 1);
  ASSERT_GT(s.triangle_count, before.triangle_count);
  for (bool merged = true; merged;) {
    merged = false;
    for (int32_t d : std::vector<int32_t>(s.merge_queue.heap))
      if (!before.split[d]) roam_merge(s, t, d), merged = true;
  }
  EXPECT_EQ(s.split, before.split);
  EXPECT_EQ(s.triangle_count, before.triangle_count);
  EXPECT_EQ(members(s.split_queue), members(before.split_queue));
  EXPECT_EQ(members(s.merge_queue), members(before.merge_queue));
  EXPECT_EQ(mesh_of(s, t), mesh_of(before, t));
}

TEST(Roam, CulledSubtreesStayCoarse) {
  const RoamTerrain t = build_roam_terrain(make_field(6, Relief::random));
  RoamState s;
  roam_reset(s, t);
  View up = flying_view(t, 0);
  up.eye.y = 200;  // high enough that even the root's bounding sphere is below the frustum
  up.target = up.eye + glm::vec3(0, 1, 0);  // the sky: no terrain in the frustum
  up.up = {0, 0, 1};
  RoamParams p;
  p.pixel_error = 0.5f;
  EXPECT_EQ(roam_update(s, t, up, p).triangles, 2u);
  EXPECT_GT(roam_update(s, t, flying_view(t, 0), p).triangles, 100u);
  EXPECT_EQ(roam_update(s, t, up, p).triangles, 2u);  // and merges back
}

// Triangles left out of the draw list lie wholly outside one frustum plane; the rest are the mesh's.
TEST(Roam, VisibleTrianglesDropOnlyWhatIsOutsideTheFrustum) {
  const RoamTerrain t = build_roam_terrain(make_field(7, Relief::sines));
  RoamState s;
  roam_reset(s, t);
  RoamParams p;
  p.pixel_error = 1.f;
  const View v = flying_view(t, 20);
  roam_update(s, t, v, p);
  std::vector<uint32_t> all, visible;
  roam_triangles(all, s, t);
  roam_visible_triangles(visible, s, t);
  ASSERT_LT(visible.size(), all.size());
  ASSERT_GT(visible.size(), 0u);
  auto key = [](const uint32_t* v3) { return std::array<uint32_t, 3>{v3[0], v3[1], v3[2]}; };
  std::vector<std::array<uint32_t, 3>> shown;
  for (size_t i = 0; i < visible.size(); i += 3) shown.push_back(key(&visible[i]));
  std::sort(shown.begin(), shown.end());
  const Frustum f = frustum_of(v);
  size_t dropped = 0;
  for (size_t i = 0; i < all.size(); i += 3) {
    if (std::binary_search(shown.begin(), shown.end(), key(&all[i]))) continue;
    ++dropped;
    bool outside_one = false;
    for (const glm::vec4& pl : f.planes) {
      bool all_out = true;
      for (int k = 0; k < 3; ++k) all_out &= glm::dot(glm::vec3(pl), t.positions[all[i + k]]) + pl.w < 0;
      outside_one |= all_out;
    }
    EXPECT_TRUE(outside_one) << "triangle " << i / 3 << " dropped but not outside the frustum";
  }
  EXPECT_EQ(dropped * 3, all.size() - visible.size());
}

TEST(TerrainMeshCheck, FindsTJunctionsHolesAndOverlaps) {
  const RoamTerrain t = build_roam_terrain(make_field(4, Relief::sines));
  RoamState s;
  roam_reset(s, t);
  roam_split(s, t, t.root);
  auto idx = mesh_of(s, t);  // 4 triangles around the centre
  ASSERT_TRUE(check_terrain_mesh(idx, t.size).ok());
  roam_split(s, t, roam_diamond_of(t, idx[1], idx[2]));
  idx = mesh_of(s, t);
  // Replace an interior-based triangle by its halves while its neighbour stays whole.
  for (size_t i = 0; i < idx.size(); i += 3) {
    const int32_t d = roam_diamond_of(t, idx[i + 1], idx[i + 2]);
    if (d < 0 || t.triangles[d] != 2) continue;
    auto bad = idx;
    const uint32_t ap = bad[i], bl = bad[i + 1], br = bad[i + 2];
    bad.erase(bad.begin() + long(i), bad.begin() + long(i) + 3);
    bad.insert(bad.end(), {uint32_t(d), ap, bl, uint32_t(d), br, ap});
    const TerrainMeshCheck c = check_terrain_mesh(bad, t.size);
    EXPECT_FALSE(c.ok());
    EXPECT_EQ(c.open_edges, 3u) << c.first_problem;  // the long edge and the two half edges
    break;
  }
  auto hole = idx;
  hole.resize(hole.size() - 3);
  EXPECT_FALSE(check_terrain_mesh(hole, t.size).covers_grid);
  auto twice = idx;
  twice.insert(twice.end(), idx.begin(), idx.begin() + 3);
  EXPECT_GT(check_terrain_mesh(twice, t.size).overshared_edges, 0u);
  auto flipped = idx;
  std::swap(flipped[1], flipped[2]);
  EXPECT_GT(check_terrain_mesh(flipped, t.size).flipped, 0u);
}

}  // namespace
}  // namespace lod
