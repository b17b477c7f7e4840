#include "preprocess/surface_error.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <functional>
#include <random>

#include "preprocess/mesh_io.h"
#include "test_support.h"

namespace lod {
namespace {

TriangleMeshView view(const std::vector<float>& p, const std::vector<uint32_t>& i) {
  return {p.data(), p.size() / 3, i.data(), i.size()};
}

const std::vector<float> kSquare = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
const std::vector<uint32_t> kSquareTris = {0, 1, 2, 0, 2, 3};

TEST(SurfaceError, OfAMeshAgainstItselfIsZero) {
  SurfaceError e;
  ASSERT_TRUE(measure_surface_error(view(kSquare, kSquareTris), view(kSquare, kSquareTris), {}, e).ok);
  EXPECT_LT(e.max, 1e-6f);
  EXPECT_LT(e.rms, 1e-6f);
  EXPECT_GT(e.samples, 2 * SurfaceErrorSettings{}.surface_samples);
}

TEST(SurfaceError, OfAShiftedCopyIsTheShift) {
  std::vector<float> shifted = kSquare;
  for (size_t v = 0; v < 4; ++v) shifted[3 * v + 2] += 0.25f;
  SurfaceError e;
  ASSERT_TRUE(measure_surface_error(view(kSquare, kSquareTris), view(shifted, kSquareTris), {}, e).ok);
  EXPECT_NEAR(e.max, 0.25f, 1e-6f);
  EXPECT_NEAR(e.rms, 0.25f, 1e-6f);
}

// Vertices no triangle uses are not on the surface: they must not be sampled (a simplifier's
// output that indexes the whole input would otherwise look closer than it is).
TEST(SurfaceError, IgnoresVerticesNoTriangleUses) {
  std::vector<float> shifted = kSquare;
  for (size_t v = 0; v < 4; ++v) shifted[3 * v + 2] += 0.25f;
  std::vector<float> padded = shifted;
  for (int k = 0; k < 1000; ++k) padded.insert(padded.end(), {0.5f, 0.5f, 0.f});  // on the reference, unused
  SurfaceError plain, with_unused;
  SurfaceErrorSettings few;
  few.surface_samples = 200;
  ASSERT_TRUE(measure_surface_error(view(kSquare, kSquareTris), view(shifted, kSquareTris), few, plain).ok);
  ASSERT_TRUE(measure_surface_error(view(kSquare, kSquareTris), view(padded, kSquareTris), few, with_unused).ok);
  EXPECT_NEAR(with_unused.rms, 0.25f, 1e-6f);
  EXPECT_EQ(with_unused.samples, plain.samples);
}

TEST(SurfaceError, IsSymmetricAndSeesWhatOnlyOneSideHas) {
  // b = a plus a far triangle: h(a,b) = 0 but h(b,a) is large; both orders report it.
  std::vector<float> b = kSquare;
  b.insert(b.end(), {0, 0, 3, 1, 0, 3, 0, 1, 3});
  std::vector<uint32_t> bt = kSquareTris;
  bt.insert(bt.end(), {4, 5, 6});
  SurfaceError ab, ba;
  ASSERT_TRUE(measure_surface_error(view(kSquare, kSquareTris), view(b, bt), {}, ab).ok);
  ASSERT_TRUE(measure_surface_error(view(b, bt), view(kSquare, kSquareTris), {}, ba).ok);
  EXPECT_NEAR(ab.max, 3.0f, 1e-5f);
  EXPECT_NEAR(ba.max, 3.0f, 1e-5f);
}

TEST(SurfaceError, MeasuresTheGapToAnEdgeNotJustToPlanes) {
  // A point beside a triangle's edge: its closest point lies on the edge.
  const std::vector<float> tri = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::vector<uint32_t> t = {0, 1, 2};
  const std::vector<float> far = {2, 0, 0, 3, 0, 0, 2, 1, 0};
  SurfaceError e;
  ASSERT_TRUE(measure_surface_error(view(tri, t), view(far, t), {}, e).ok);
  // Farthest point of `far` from `tri` is (3,0,0): 2 from the corner (1,0,0).
  EXPECT_NEAR(e.max, 2.0f, 1e-5f);
}

TEST(SurfaceError, IsReproducibleForOneSeed) {
  const auto dir = test::temp_dir("surface-seed");
  test::write_text(dir / "s.off", test::sphere_off(12, 16));
  test::write_text(dir / "t.off", test::sphere_off(6, 8));
  MeshData a, b;
  ASSERT_TRUE(load_mesh(dir / "s.off", a).ok);
  ASSERT_TRUE(load_mesh(dir / "t.off", b).ok);
  const TriangleMeshView va{a.positions.data(), a.vertex_count(), a.indices.data(), a.indices.size()};
  const TriangleMeshView vb{b.positions.data(), b.vertex_count(), b.indices.data(), b.indices.size()};
  SurfaceError e1, e2;
  ASSERT_TRUE(measure_surface_error(va, vb, {5000, 7}, e1).ok);
  ASSERT_TRUE(measure_surface_error(va, vb, {5000, 7}, e2).ok);
  EXPECT_EQ(e1.max, e2.max);
  EXPECT_EQ(e1.rms, e2.rms);
  EXPECT_GT(e1.max, 0.0f);
  EXPECT_LT(e1.max, 0.3f);  // both inscribed in the unit sphere
  EXPECT_LE(e1.rms, e1.max);
}

TEST(SurfaceError, MeterReusesItsReference) {
  std::vector<float> up = kSquare;
  for (size_t v = 0; v < 4; ++v) up[3 * v + 2] += 0.5f;
  SurfaceErrorMeter meter;
  ASSERT_TRUE(meter.set_reference(view(kSquare, kSquareTris), {}, "square").ok);
  SurfaceError same, shifted;
  ASSERT_TRUE(meter.measure(view(kSquare, kSquareTris), same).ok);
  ASSERT_TRUE(meter.measure(view(up, kSquareTris), shifted).ok);
  EXPECT_LT(same.max, 1e-6f);
  EXPECT_NEAR(shifted.max, 0.5f, 1e-6f);
}

// The wavy 60 x 60 sheet over [0, 1]^2 the part tests query.
void wavy_sheet(std::vector<float>& p, std::vector<uint32_t>& t) {
  const uint32_t n = 60;
  for (uint32_t y = 0; y <= n; ++y)
    for (uint32_t x = 0; x <= n; ++x) {
      const float u = float(x) / n, v = float(y) / n;
      p.insert(p.end(), {u, v, 0.05f * std::sin(9 * u) * std::cos(7 * v) + 0.5f});
    }
  for (uint32_t y = 0; y < n; ++y)
    for (uint32_t x = 0; x < n; ++x) {
      const uint32_t a = y * (n + 1) + x;
      t.insert(t.end(), {a, a + 1, a + n + 2, a, a + n + 2, a + n + 1});
    }
}

// A surface part answers a point only when it is provably the whole surface's answer, to the
// bit; the others go to the whole (or are left unanswered); cells outside reach none of it.
TEST(SurfaceDistance, PartAnswersExactlyAsTheWhole) {
  std::vector<float> p;
  std::vector<uint32_t> t;
  wavy_sheet(p, t);
  SurfaceDistance whole, part;
  ASSERT_TRUE(whole.set_surface(view(p, t), "sheet"));
  SurfaceGrid grid;
  grid.n = 16;
  std::vector<uint8_t> wanted(grid.cells(), 0);
  for (uint32_t z = 0; z < grid.n; ++z)
    for (uint32_t y = 0; y < grid.n; ++y)
      for (uint32_t x = 0; x < grid.n / 2; ++x) wanted[(size_t(z) * grid.n + y) * grid.n + x] = 1;  // x < 0.5
  ASSERT_TRUE(part.set_surface_part(view(p, t), grid, wanted, "half sheet"));
  EXPECT_GT(part.triangles(), t.size() / 3 / 3);
  EXPECT_LT(part.triangles(), t.size() / 3 * 2 / 3);
  auto on_sheet = [](float u, float v) { return 0.05f * std::sin(9 * u) * std::cos(7 * v) + 0.5f; };
  const float inside[3] = {0.2f, 0.5f, on_sheet(0.2f, 0.5f)}, outside[3] = {0.8f, 0.5f, on_sheet(0.8f, 0.5f)};
  EXPECT_TRUE(part.holds(inside));
  EXPECT_FALSE(part.holds(outside));
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0, 1), h(0.3f, 0.7f);
  size_t mine = 0, theirs = 0;
  const std::function<const SurfaceDistance*()> ask_whole = [&] { return &whole; };
  for (int k = 0; k < 2000; ++k) {
    const float q[3] = {u(rng), u(rng), h(rng)};
    SurfaceError w, a, b;
    std::vector<uint8_t> answered;
    ASSERT_TRUE(whole.from_points(q, 1, nullptr, w));
    ASSERT_TRUE(part.from_points_part(q, 1, nullptr, ask_whole, a, nullptr));
    EXPECT_EQ(std::bit_cast<uint32_t>(a.max), std::bit_cast<uint32_t>(w.max)) << q[0] << " " << q[1] << " " << q[2];
    ASSERT_TRUE(part.from_points_part(q, 1, nullptr, {}, b, &answered));
    ASSERT_EQ(answered.size(), 1u);
    if (answered[0]) {
      ++mine;
      EXPECT_EQ(std::bit_cast<uint32_t>(b.max), std::bit_cast<uint32_t>(w.max));
      EXPECT_LT(q[0], 0.5f + 1e-6f + w.max) << "answered from a half that cannot hold the nearest point";
    } else {
      ++theirs;
      EXPECT_EQ(b.samples, 0u);
    }
  }
  EXPECT_GT(mine, 300u);
  EXPECT_GT(theirs, 300u);
}

SurfaceBox box(float x0, float y0, float x1, float y1) {
  SurfaceBox b;
  b.lo[0] = x0, b.lo[1] = y0, b.lo[2] = 0, b.hi[0] = x1, b.hi[1] = y1, b.hi[2] = 1;
  return b;
}

// Each planned part lists exactly the triangles whose box reaches into its box's cells (as a
// brute force over every triangle and box finds them), and answers a query only as the whole
// surface would, to the bit; one SurfaceDistance and one scratch serve every part in turn.
TEST(SurfaceDistance, PlannedPartsListWhatReachesTheirBoxesAndAnswerExactlyAsTheWhole) {
  std::vector<float> p;
  std::vector<uint32_t> t;
  wavy_sheet(p, t);
  SurfaceGrid grid;
  grid.n = 64;
  const std::vector<SurfaceBox> boxes = {box(0, 0, 0.53f, 0.53f), box(0.47f, 0, 1, 0.53f), box(0, 0.47f, 0.53f, 1),
                                         box(0.47f, 0.47f, 1, 1), box(0.3f, 0.3f, 0.31f, 0.7f)};
  SurfacePartPlan plan;
  ASSERT_TRUE(plan_surface_parts(view(p, t), grid, boxes, plan, "sheet"));
  ASSERT_EQ(plan.triangles.size(), boxes.size());
  for (size_t b = 0; b < boxes.size(); ++b) {
    std::vector<uint32_t> expected;
    for (uint32_t f = 0; f < t.size() / 3; ++f) {
      bool meets = true;
      for (int k = 0; k < 3; ++k) {
        uint32_t lo = grid.n, hi = 0;
        for (int c = 0; c < 3; ++c) {
          const uint32_t cell = grid.cell(p[3 * size_t(t[3 * f + c]) + k], k);
          lo = std::min(lo, cell), hi = std::max(hi, cell);
        }
        meets = meets && hi >= grid.cell(boxes[b].lo[k], k) && lo <= grid.cell(boxes[b].hi[k], k);
      }
      if (meets) expected.push_back(f);
    }
    EXPECT_EQ(plan.triangles[b], expected) << "box " << b;
  }
  SurfaceDistance whole, part;
  ASSERT_TRUE(whole.set_surface(view(p, t), "sheet"));
  std::vector<uint32_t> remap;
  const std::function<const SurfaceDistance*()> ask_whole = [&] { return &whole; };
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0, 1), h(0.3f, 0.7f);
  for (size_t b = 0; b < boxes.size(); ++b) {
    ASSERT_TRUE(part.set_surface_planned(view(p, t), plan, b, remap, "sheet part"));
    EXPECT_EQ(part.triangles(), plan.triangles[b].size());
    ASSERT_EQ(remap.size(), p.size() / 3);
    EXPECT_EQ(std::count(remap.begin(), remap.end(), UINT32_MAX), ptrdiff_t(remap.size())) << "scratch left dirty";
    const float centre[3] = {(boxes[b].lo[0] + boxes[b].hi[0]) / 2, (boxes[b].lo[1] + boxes[b].hi[1]) / 2, 0.5f};
    const float far[3] = {boxes[b].hi[0] + 0.2f > 1 ? boxes[b].lo[0] - 0.2f : boxes[b].hi[0] + 0.2f, centre[1], 0.5f};
    EXPECT_TRUE(part.holds(centre));
    EXPECT_FALSE(part.holds(far));
    size_t mine = 0;
    for (int k = 0; k < 500; ++k) {
      const float q[3] = {u(rng), u(rng), h(rng)};
      SurfaceError w, a, c;
      std::vector<uint8_t> answered;
      ASSERT_TRUE(whole.from_points(q, 1, nullptr, w));
      ASSERT_TRUE(part.from_points_part(q, 1, nullptr, ask_whole, a, nullptr));
      EXPECT_EQ(std::bit_cast<uint32_t>(a.max), std::bit_cast<uint32_t>(w.max)) << "box " << b;
      ASSERT_TRUE(part.from_points_part(q, 1, nullptr, {}, c, &answered));
      if (!answered[0]) continue;
      ++mine;
      EXPECT_EQ(std::bit_cast<uint32_t>(c.max), std::bit_cast<uint32_t>(w.max)) << "box " << b;
    }
    if (b < 4) {
      EXPECT_GT(mine, 30u) << "box " << b << " answers nothing itself";
    }
  }
}

TEST(SurfaceDistance, PlannedPartsRefuseWhatDoesNotFit) {
  std::vector<float> p;
  std::vector<uint32_t> t;
  wavy_sheet(p, t);
  SurfaceGrid grid;
  grid.n = 16;
  SurfacePartPlan plan;
  std::vector<uint32_t> broken = t;
  broken[3 * 7 + 1] = uint32_t(p.size());  // triangle 7 names a vertex the sheet lacks
  Status s = plan_surface_parts(view(p, broken), grid, {box(0, 0, 1, 1)}, plan, "broken sheet");
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("broken sheet: triangle 7"), std::string::npos) << s.message;
  SurfaceGrid huge = grid;
  huge.n = 70000;
  EXPECT_FALSE(plan_surface_parts(view(p, t), huge, {box(0, 0, 1, 1)}, plan, "sheet").ok);
  ASSERT_TRUE(plan_surface_parts(view(p, t), grid, {box(0, 0, 1, 1)}, plan, "sheet"));
  SurfaceDistance part;
  std::vector<uint32_t> remap;
  s = part.set_surface_planned(view(p, t), plan, 1, remap, "sheet part");
  EXPECT_FALSE(s.ok) << "a box the plan lacks";
  EXPECT_NE(s.message.find("sheet part"), std::string::npos);
  EXPECT_FALSE(part.ready());
  const std::vector<float> fewer(p.begin(), p.end() - 3);
  EXPECT_FALSE(part.set_surface_planned(view(fewer, {0, 1, 2}), plan, 0, remap, "another").ok) << "another surface";
  remap.assign(5, UINT32_MAX);
  EXPECT_FALSE(part.set_surface_planned(view(p, t), plan, 0, remap, "sheet part").ok) << "scratch of another size";
  remap.clear();
  EXPECT_TRUE(part.set_surface_planned(view(p, t), plan, 0, remap, "sheet part"));
  EXPECT_TRUE(part.ready());
  EXPECT_EQ(part.triangles(), t.size() / 3);
}

TEST(SurfaceError, RefusesBadInput) {
  SurfaceErrorMeter meter;
  SurfaceError e;
  EXPECT_FALSE(meter.measure(view(kSquare, kSquareTris), e).ok);  // no reference yet
  const std::vector<uint32_t> bad = {0, 1, 7};
  const Status s = meter.set_reference(view(kSquare, bad), {}, "square");
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("square"), std::string::npos);
  EXPECT_FALSE(meter.set_reference(view(kSquare, {}), {}, "empty").ok);
}

}  // namespace
}  // namespace lod
