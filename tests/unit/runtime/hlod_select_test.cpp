#include "runtime/hlod_select.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/gtc/quaternion.hpp>
#include <map>
#include <random>
#include <set>

#include "unit/runtime/hlod_fixtures.h"

namespace lod {
namespace {

// ---- the brute-force reference: the recursive definition of hlod_select.h, with its own
// world bounds (glm quaternions) and its own error test (Cesium's sse) ---------------------

struct RefCut {
  std::map<uint32_t, uint32_t> drawn;  // node -> layer
  std::set<uint32_t> opened, requested, culled;
  // A test within float rounding of its threshold (float and double may decide differently).
  bool borderline = false;
};

struct RefInputs {
  const HlodTree& tree;
  const std::vector<uint8_t>& resident;
  Transform transform;
  View view;
  float pixel_error;
  bool cull;
  HlodCulledNodes culled = HlodCulledNodes::skip;
};

glm::vec3 ref_world_center(const RefInputs& in, const HlodNode& n) {
  const Transform& t = in.transform;
  glm::quat q(t.rotation[3], t.rotation[0], t.rotation[1], t.rotation[2]);
  q = glm::normalize(q);
  const glm::vec3 c(n.bounds.center[0], n.bounds.center[1], n.bounds.center[2]);
  return glm::vec3(t.position[0], t.position[1], t.position[2]) + t.scale * (q * c);
}

bool ref_visible(const RefInputs& in, const HlodNode& n, bool* borderline) {
  if (!in.cull) return true;
  const Frustum f = frustum_of(in.view);
  const glm::vec3 c = ref_world_center(in, n);
  const float r = n.bounds.radius * in.transform.scale;
  bool inside = true;
  for (const glm::vec4& p : f.planes) {
    const float margin = glm::dot(glm::vec3(p), c) + p.w + r;
    if (std::abs(margin) < 1e-3f * (r + 1)) *borderline = true;
    if (margin < 0) inside = false;
  }
  return inside;
}

double ref_distance(const RefInputs& in, const HlodNode& n) {
  const double d =
      glm::length(ref_world_center(in, n) - in.view.eye) - double(n.bounds.radius) * in.transform.scale;
  return d > 0 ? d : 0;
}

// Cesium: sse = e * H / (d * 2 tan(fovy / 2)); a layer is fine enough when sse <= P.
double cesium_sse(double e, double height, double d, double fovy_rad) {
  return e * height / (d * 2 * std::tan(fovy_rad / 2));
}

int ref_wanted_layer(const RefInputs& in, const HlodNode& n, bool* borderline) {
  const double d = ref_distance(in, n);
  for (int l = n.layer_count - 1; l >= 0; --l) {
    const double e = double(n.layers[l].error) * in.transform.scale;
    if (e == 0) return l;
    if (d <= 0) continue;
    const double sse = cesium_sse(e, in.view.height, d, glm::radians(double(in.view.fov_y_deg)));
    if (std::abs(sse - in.pixel_error) < 1e-4 * in.pixel_error) *borderline = true;
    if (sse <= in.pixel_error) return l;
  }
  return -1;
}

void ref_visit(const RefInputs& in, uint32_t id, bool in_cut, RefCut& out) {
  const HlodNode& n = in.tree.nodes[id];
  if (!ref_visible(in, n, &out.borderline)) {
    if (id == 0 || in.culled == HlodCulledNodes::skip) {
      out.culled.insert(id);
    } else if (!in.resident[id]) {
      out.requested.insert(id);
    } else if (in_cut) {
      out.drawn[id] = n.layer_count - 1u;  // covered at its coarsest
    }
    return;
  }
  if (!in.resident[id]) {
    out.requested.insert(id);
    return;
  }
  const int l = ref_wanted_layer(in, n, &out.borderline);
  if (l >= 0 || n.leaf()) {
    if (in_cut) out.drawn[id] = uint32_t(std::max(l, 0));
    return;
  }
  bool can_open = true;
  for (uint32_t k = 0; k < n.child_count; ++k) {
    const uint32_t c = n.first_child + k;
    const bool counts =
        in.culled == HlodCulledNodes::cover || ref_visible(in, in.tree.nodes[c], &out.borderline);
    if (counts && !in.resident[c]) can_open = false;
  }
  for (uint32_t k = 0; k < n.child_count; ++k) ref_visit(in, n.first_child + k, in_cut && can_open, out);
  if (in_cut && can_open) out.opened.insert(id);
  if (in_cut && !can_open) out.drawn[id] = 0;
}

RefCut reference_cut(const RefInputs& in) {
  RefCut out;
  ref_visit(in, 0, true, out);
  return out;
}

// ---- helpers -------------------------------------------------------------------------------

struct Selector {
  HlodCut cut;
  HlodCutScratch scratch;
  explicit Selector(const HlodTree& t) { prepare_hlod_cut(cut, scratch, t); }
  const HlodCut& run(const HlodTree& t, const std::vector<uint8_t>& resident, const Transform& tr,
                     const View& v, float pixel_error, bool cull = true, uint64_t budget = UINT64_MAX,
                     HlodBudgetPass pass = HlodBudgetPass::automatic,
                     HlodCulledNodes culled = HlodCulledNodes::skip) {
    HlodView hv = hlod_view_of(v);
    hv.cull = cull;
    select_hlod_cut(cut, scratch, t, resident, tr, hv, {pixel_error, budget, pass, culled});
    return cut;
  }
};

View looking_at(glm::vec3 eye, glm::vec3 target) {
  View v;
  v.eye = eye;
  v.target = target;
  v.far_plane = 1e5f;
  return v;
}

View random_view(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1, 1);
  const glm::vec3 dir = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + glm::vec3(0, 0, 1e-3f));
  const float dist = 20 + 400 * (u(rng) + 1) / 2;
  View v = looking_at(dir * dist, glm::vec3(u(rng), u(rng), u(rng)) * 40.0f);
  v.fov_y_deg = 30 + 60 * (u(rng) + 1) / 2;
  v.height = 400 + int(rng() % 800);
  v.width = v.height * 16 / 9;
  return v;
}

Transform random_transform(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1, 1);
  Transform t;
  for (int k = 0; k < 3; ++k) t.position[k] = 20 * u(rng);
  for (int k = 0; k < 4; ++k) t.rotation[k] = u(rng);
  t.scale = 0.5f + (u(rng) + 1);
  return t;
}

std::vector<uint8_t> random_residency(size_t n, std::mt19937& rng, uint32_t percent) {
  std::vector<uint8_t> r(n);
  for (auto& x : r) x = rng() % 100 < percent;
  return r;
}

uint64_t triangles_of(const HlodTree& t, const HlodCut& cut) {
  uint64_t sum = 0;
  for (const HlodDraw& d : cut.drawn) sum += t.nodes[d.node].layers[d.layer].triangles;
  for (uint32_t o : cut.opened) sum += t.nodes[o].boundary_triangles;
  return sum;
}

// Every root-to-leaf path passes opened nodes and then stops at exactly one drawn or culled
// node, drawn and opened nodes are resident: a cut without holes or overlaps.
void expect_closed_cut(const HlodTree& t, const HlodCut& cut, const std::vector<uint8_t>& resident) {
  std::vector<uint8_t> role(t.nodes.size(), 0);  // 1 drawn, 2 opened, 3 culled
  for (const HlodDraw& d : cut.drawn) {
    ASSERT_EQ(role[d.node], 0);
    role[d.node] = 1;
    EXPECT_TRUE(resident[d.node]) << d.node;
    EXPECT_LT(d.layer, t.nodes[d.node].layer_count);
  }
  for (uint32_t o : cut.opened) {
    ASSERT_EQ(role[o], 0);
    role[o] = 2;
    EXPECT_TRUE(resident[o]) << o;
  }
  for (uint32_t c : cut.culled)
    if (role[c] == 0) role[c] = 3;
  for (uint32_t id = 0; id < t.nodes.size(); ++id) {
    if (!t.nodes[id].leaf()) continue;
    uint32_t stops = 0;
    for (int32_t a = int32_t(id); a >= 0; a = t.nodes[a].parent) {
      const int32_t p = t.nodes[a].parent;
      const bool reached = p < 0 || role[p] == 2;
      if (role[a] == 1 || role[a] == 3) stops += reached;
      if (role[a] == 1 || role[a] == 2) {
        EXPECT_TRUE(reached) << "node " << a << " drawn or opened below a node not opened";
      }
    }
    EXPECT_EQ(stops, 1u) << "leaf " << id;
  }
}

// ---- tests ---------------------------------------------------------------------------------

TEST(HlodSelect, ThresholdEqualsCesiumScreenSpaceError) {
  // Zhou and Tian's E = d * (P / N) * tan(theta) with N = H / 2 and theta = fovy / 2, Cesium's
  // sse = e * H / (d * 2 tan(fovy / 2)) <= P: the same test for the same inputs.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  int compared = 0;
  for (int i = 0; i < 20000; ++i) {
    View v;
    v.fov_y_deg = float(10 + 150 * u(rng));
    v.height = 100 + int(rng() % 4000);
    const float d = float(0.1 + 1000 * u(rng));
    const float p = float(0.25 + 8 * u(rng));
    const float e = float(2 * u(rng) * d * p / focal_pixels(v));  // around the threshold
    const double theta = glm::radians(double(v.fov_y_deg)) / 2;
    const double r1 = double(d) * (double(p) / (v.height / 2.0)) * std::tan(theta);
    EXPECT_NEAR(hlod_error_threshold(d, p, focal_pixels(v)), r1, 1e-5 * r1);
    const double sse = cesium_sse(e, v.height, d, 2 * theta);
    if (std::abs(sse - p) < 1e-4 * p) continue;  // float rounding decides exact ties
    EXPECT_EQ(e <= hlod_error_threshold(d, p, focal_pixels(v)), sse <= p) << "e " << e << " d " << d;
    ++compared;
  }
  EXPECT_GT(compared, 19000);
}

TEST(HlodSelect, EqualsRecursiveReferenceOnRandomTreesAndViews) {
  std::mt19937 rng(5);
  int compared = 0;
  size_t opened = 0, requested_total = 0, culled_total = 0;
  for (uint32_t seed = 1; seed <= 40; ++seed) {
    const HlodTree t = test::random_octree(seed);
    Selector sel(t);
    for (int k = 0; k < 25; ++k) {
      const View v = random_view(rng);
      const Transform tr = k % 5 == 0 ? Transform{} : random_transform(rng);
      const auto resident = random_residency(t.nodes.size(), rng, k % 3 == 0 ? 100 : 85);
      const float p = 0.5f + float(rng() % 8);
      const bool cull = k % 4 != 0;
      const HlodCulledNodes culled = k % 2 ? HlodCulledNodes::cover : HlodCulledNodes::skip;
      const HlodCut& cut =
          sel.run(t, resident, tr, v, p, cull, UINT64_MAX, HlodBudgetPass::automatic, culled);
      const RefCut ref = reference_cut({t, resident, tr, v, p, cull, culled});
      if (ref.borderline) continue;
      ++compared;
      opened += ref.opened.size();
      requested_total += ref.requested.size();
      culled_total += ref.culled.size();
      std::map<uint32_t, uint32_t> drawn;
      for (const HlodDraw& d : cut.drawn) drawn[d.node] = d.layer;
      ASSERT_EQ(drawn, ref.drawn) << "seed " << seed << " view " << k;
      ASSERT_EQ(std::set<uint32_t>(cut.opened.begin(), cut.opened.end()), ref.opened);
      std::set<uint32_t> requested;
      for (const HlodRequest& r : cut.requests) requested.insert(r.node);
      ASSERT_EQ(requested, ref.requested);
      ASSERT_EQ(std::set<uint32_t>(cut.culled.begin(), cut.culled.end()), ref.culled);
      EXPECT_EQ(cut.triangles, triangles_of(t, cut));
    }
  }
  EXPECT_GT(compared, 900);
  // The views open, request and cull a fair share (the comparison is not between empty cuts).
  EXPECT_GT(opened, size_t(compared) * 3);
  EXPECT_GT(requested_total, size_t(compared));
  EXPECT_GT(culled_total, size_t(compared) / 4);  // skip-mode views only
  std::printf("compared %d cuts: %zu opened, %zu requested, %zu culled\n", compared, opened, requested_total,
              culled_total);
}

TEST(HlodSelect, NeverAHoleWithRandomResidency) {
  std::mt19937 rng(7);
  for (uint32_t seed = 1; seed <= 30; ++seed) {
    const HlodTree t = test::random_octree(seed + 100);
    Selector sel(t);
    for (int k = 0; k < 20; ++k) {
      auto resident = random_residency(t.nodes.size(), rng, 20 + 10 * uint32_t(k % 8));
      resident[0] = 1;
      const HlodCut& cut = sel.run(t, resident, random_transform(rng), random_view(rng), 1.0f, k % 2 == 0);
      EXPECT_EQ(cut.holes, 0u);
      expect_closed_cut(t, cut, resident);
    }
  }
}

TEST(HlodSelect, CoverModeKeepsTheWholeCutClosed) {
  // Every root-to-leaf path ends at a drawn node (none at a culled one) once the root is in
  // view, whatever is resident: the cut a crack checker can test edge by edge.
  std::mt19937 rng(17);
  int with_outside = 0;
  for (uint32_t seed = 1; seed <= 30; ++seed) {
    const HlodTree t = test::random_octree(seed + 500);
    Selector sel(t);
    for (int k = 0; k < 20; ++k) {
      auto resident = random_residency(t.nodes.size(), rng, 30 + 10 * uint32_t(k % 7));
      resident[0] = 1;
      const HlodCut& cut = sel.run(t, resident, random_transform(rng), random_view(rng), 1.0f, true,
                                   UINT64_MAX, HlodBudgetPass::automatic, HlodCulledNodes::cover);
      if (!cut.culled.empty()) {
        EXPECT_EQ(cut.culled, std::vector<uint32_t>{0});  // only a root out of view is culled
        continue;
      }
      EXPECT_EQ(cut.holes, 0u);
      expect_closed_cut(t, cut, resident);
      for (size_t i = 1; i < cut.requests.size(); ++i)
        EXPECT_TRUE(request_before(cut.requests[i - 1], cut.requests[i]));
      with_outside +=
          std::any_of(cut.requests.begin(), cut.requests.end(), [](auto& r) { return r.deficit < -1e30f; });
    }
  }
  EXPECT_GT(with_outside, 20);  // covered nodes outside the view were requested, last
}

TEST(HlodSelect, CoverModeWaitsForChildrenOutsideTheView) {
  const HlodTree t = test::full_octree({.depth = 1});
  Selector sel(t);
  std::vector<uint8_t> resident(t.nodes.size(), 1);
  View v = looking_at({40, 0, 0}, {200, 0, 0});  // the -x children (ids 1, 3, 5, 7) are behind
  v.fov_y_deg = 20;
  v.near_plane = 1;
  resident[3] = 0;
  const HlodCut& waiting =
      sel.run(t, resident, {}, v, 0.01f, true, UINT64_MAX, HlodBudgetPass::automatic, HlodCulledNodes::cover);
  ASSERT_EQ(waiting.drawn.size(), 1u);  // the root, until node 3 is in
  EXPECT_EQ(waiting.drawn[0].node, 0u);
  ASSERT_EQ(waiting.requests.size(), 1u);
  EXPECT_EQ(waiting.requests[0].node, 3u);
  resident[3] = 1;
  const HlodCut& cut =
      sel.run(t, resident, {}, v, 0.01f, true, UINT64_MAX, HlodBudgetPass::automatic, HlodCulledNodes::cover);
  EXPECT_EQ(cut.opened.size(), 1u);
  EXPECT_EQ(cut.drawn.size(), 8u);
  EXPECT_TRUE(cut.culled.empty());
  for (const HlodDraw& d : cut.drawn) {
    if ((d.node - 1) % 2 == 0) {
      EXPECT_EQ(d.layer, 2u) << "behind, drawn coarsest: " << d.node;
    }
  }
}

TEST(HlodSelect, MissingRootDrawsNothingAndIsRequestedAsTheOneHole) {
  const HlodTree t = test::full_octree({.depth = 2});
  Selector sel(t);
  std::vector<uint8_t> resident(t.nodes.size(), 1);
  resident[0] = 0;
  const HlodCut& cut = sel.run(t, resident, {}, looking_at({0, 0, 300}, {0, 0, 0}), 1.0f);
  EXPECT_TRUE(cut.drawn.empty());
  EXPECT_TRUE(cut.opened.empty());
  ASSERT_EQ(cut.requests.size(), 1u);
  EXPECT_EQ(cut.requests[0].node, 0u);
  EXPECT_EQ(cut.holes, 1u);
}

TEST(HlodSelect, ParentStaysDrawnUntilAllItsChildrenAreResident) {
  const HlodTree t = test::full_octree({.depth = 1});
  Selector sel(t);
  std::vector<uint8_t> resident(t.nodes.size(), 1);
  resident[3] = 0;
  const View v = looking_at({0, 0, 70}, {0, 0, 0});  // near: the root wants to open
  const HlodCut& cut = sel.run(t, resident, {}, v, 1.0f, false);
  ASSERT_EQ(cut.drawn.size(), 1u);
  EXPECT_EQ(cut.drawn[0].node, 0u);
  EXPECT_EQ(cut.drawn[0].layer, 0u);  // its finest: the closest it can get
  ASSERT_EQ(cut.requests.size(), 1u);
  EXPECT_EQ(cut.requests[0].node, 3u);
  EXPECT_GT(cut.requests[0].deficit, 0.f);
  EXPECT_EQ(cut.kept.size(), 8u);  // the root and the seven resident children it waits with
  resident[3] = 1;
  const HlodCut& full = sel.run(t, resident, {}, v, 1.0f, false);
  EXPECT_EQ(full.drawn.size(), 8u);
  ASSERT_EQ(full.opened.size(), 1u);
  EXPECT_TRUE(full.requests.empty());
}

TEST(HlodSelect, CulledChildrenNeitherDrawnRequestedNorBlockingTheOpening) {
  const HlodTree t = test::full_octree({.depth = 1});
  Selector sel(t);
  std::vector<uint8_t> resident(t.nodes.size(), 1);
  // Looking down +x from just outside the cube: the -x octants (even ids 1, 3, 5, 7) are
  // behind a narrow frustum aimed at the +x half.
  View v = looking_at({40, 0, 0}, {200, 0, 0});
  v.fov_y_deg = 20;
  v.near_plane = 1;
  for (uint32_t c = 1; c <= 8; ++c)
    if (((c - 1) & 1) == 0) resident[c] = 0;  // the -x children, culled, are not loaded
  const HlodCut& cut = sel.run(t, resident, {}, v, 0.01f);
  EXPECT_EQ(cut.opened.size(), 1u) << "the root opens although its culled children are missing";
  EXPECT_TRUE(cut.requests.empty());
  for (uint32_t c : cut.culled) EXPECT_EQ((c - 1) & 1, 0u) << c;
  EXPECT_EQ(cut.culled.size() + cut.drawn.size(), 8u);
  EXPECT_EQ(cut.holes, 0u);
}

TEST(HlodSelect, CoarserAndShallowerWithDistanceAndPixelError) {
  const HlodTree t = test::full_octree({.depth = 3});
  Selector sel(t);
  const std::vector<uint8_t> resident(t.nodes.size(), 1);
  const HlodCut& far = sel.run(t, resident, {}, looking_at({0, 0, 1e4f}, {0, 0, 0}), 1.0f);
  ASSERT_EQ(far.drawn.size(), 1u);
  EXPECT_EQ(far.drawn[0].layer, 2u);
  const uint64_t near_triangles =
      sel.run(t, resident, {}, looking_at({0, 0, 200}, {0, 0, 0}), 1.0f).triangles;
  const uint64_t loose_triangles =
      sel.run(t, resident, {}, looking_at({0, 0, 200}, {0, 0, 0}), 8.0f).triangles;
  EXPECT_GT(near_triangles, far.triangles);
  EXPECT_LT(loose_triangles, near_triangles);
}

// The finer the covering node of a leaf, the higher: depth first, then the layer.
int refinement_rank(const HlodTree& t, const HlodCut& cut, uint32_t leaf, const std::vector<int>& layer_of) {
  for (int32_t a = int32_t(leaf); a >= 0; a = t.nodes[a].parent)
    if (layer_of[a] >= 0)
      return int(t.nodes[a].depth) * int(kHlodMaxLayers) + int(kHlodMaxLayers) - 1 - layer_of[a];
  (void)cut;
  return -1;
}

TEST(HlodSelect, RefinesMonotonicallyAsTheCameraApproaches) {
  for (uint32_t seed = 1; seed <= 10; ++seed) {
    const HlodTree t = test::random_octree(seed + 300);
    Selector sel(t);
    const std::vector<uint8_t> resident(t.nodes.size(), 1);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1, 1);
    const glm::vec3 dir = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)));
    // Beyond every node's bounds centre, distances to them all shrink as the eye moves in.
    float root_r = t.nodes[0].bounds.radius;
    for (const HlodNode& n : t.nodes)
      root_r = std::max(root_r,
                        glm::length(glm::vec3(n.bounds.center[0], n.bounds.center[1], n.bounds.center[2])));
    std::vector<int> last(t.nodes.size(), -1);
    for (float dist = 40 * root_r; dist > 1.05f * root_r; dist *= 0.97f) {
      const HlodCut& cut = sel.run(t, resident, {}, looking_at(dir * dist, {0, 0, 0}), 1.0f, false);
      std::vector<int> layer_of(t.nodes.size(), -1);
      for (const HlodDraw& d : cut.drawn) layer_of[d.node] = d.layer;
      for (uint32_t id = 0; id < t.nodes.size(); ++id) {
        if (!t.nodes[id].leaf()) continue;
        const int rank = refinement_rank(t, cut, id, layer_of);
        ASSERT_GE(rank, last[id]) << "seed " << seed << " leaf " << id << " at " << dist;
        last[id] = rank;
      }
    }
  }
}

TEST(HlodSelect, TransformActsAsTheInverseOnTheEye) {
  // A scaled, rotated, moved tree seen from `eye` gives the cut of the bare tree seen from
  // the eye taken back to object space (errors and distances both scale by s).
  for (uint32_t seed = 1; seed <= 10; ++seed) {
    const HlodTree t = test::random_octree(seed + 400);
    Selector a(t), b(t);
    std::mt19937 rng(seed);
    const std::vector<uint8_t> resident(t.nodes.size(), 1);
    Transform tr = random_transform(rng);
    const glm::quat q =
        glm::normalize(glm::quat(tr.rotation[3], tr.rotation[0], tr.rotation[1], tr.rotation[2]));
    const glm::vec3 eye(150, 40, -90);
    const glm::vec3 local =
        glm::inverse(q) * (eye - glm::vec3(tr.position[0], tr.position[1], tr.position[2])) / tr.scale;
    const HlodCut& world = a.run(t, resident, tr, looking_at(eye, {0, 0, 0}), 1.0f, false);
    const HlodCut& object = b.run(t, resident, {}, looking_at(local, {0, 0, 0}), 1.0f, false);
    ASSERT_EQ(world.drawn.size(), object.drawn.size()) << seed;
    for (size_t i = 0; i < world.drawn.size(); ++i) {
      EXPECT_EQ(world.drawn[i].node, object.drawn[i].node);
      EXPECT_EQ(world.drawn[i].layer, object.drawn[i].layer);
    }
  }
}

void budget_never_exceeded(HlodBudgetPass pass) {
  std::mt19937 rng(3);
  uint64_t undone = 0;
  for (uint32_t seed = 1; seed <= 30; ++seed) {
    const HlodTree t = test::random_octree(seed + 200);
    Selector sel(t);
    const HlodNode& root = t.nodes[0];
    for (int k = 0; k < 20; ++k) {
      auto resident = random_residency(t.nodes.size(), rng, 90);
      resident[0] = 1;
      const View v = random_view(rng);
      const Transform tr = random_transform(rng);
      const HlodCulledNodes culled = k % 2 ? HlodCulledNodes::cover : HlodCulledNodes::skip;
      const uint64_t wanted =
          sel.run(t, resident, tr, v, 0.5f, true, UINT64_MAX, HlodBudgetPass::automatic, culled)
              .wanted_triangles;
      const uint64_t smallest = root.layers[root.layer_count - 1].triangles;
      const uint64_t budget = smallest + uint64_t(rng() % (wanted + 1));
      const HlodCut& cut = sel.run(t, resident, tr, v, 0.5f, true, budget, pass, culled);
      EXPECT_EQ(cut.wanted_triangles, wanted);
      EXPECT_LE(cut.triangles, budget) << "seed " << seed << " view " << k;
      EXPECT_FALSE(cut.over_budget);
      EXPECT_EQ(cut.triangles, triangles_of(t, cut));
      EXPECT_EQ(cut.holes, 0u);
      expect_closed_cut(t, cut, resident);
      if (wanted <= budget) {
        EXPECT_EQ(cut.undone, 0u);
      }
      undone += cut.undone;
    }
  }
  EXPECT_GT(undone, 1000u);  // the budgets really bite
  std::printf("%llu refinements undone\n", (unsigned long long)undone);
}

TEST(HlodSelect, BudgetNeverExceededWhenTheSmallestCutFits) {
  budget_never_exceeded(HlodBudgetPass::automatic);
}
TEST(HlodSelect, BudgetNeverExceededByTheUndoingPass) { budget_never_exceeded(HlodBudgetPass::undo); }
TEST(HlodSelect, BudgetNeverExceededByTheRefiningPass) { budget_never_exceeded(HlodBudgetPass::refine); }

TEST(HlodSelect, RefiningAndUndoingPassesAgreeOnMonotonicTrees) {
  // Full octrees: errors and triangle counts monotonic up the tree, bounds nested, so both
  // passes take the same steps in opposite orders and stop at the same cut. Without culling:
  // closing a node most of whose children are culled adds triangles (then they may differ).
  std::mt19937 rng(8);
  int compared = 0, undone = 0;
  for (uint32_t depth = 2; depth <= 4; ++depth) {
    const HlodTree t = test::full_octree({.depth = depth});
    Selector a(t), b(t);
    for (int k = 0; k < 60; ++k) {
      const auto resident = random_residency(t.nodes.size(), rng, k % 2 ? 100 : 90);
      const View v = random_view(rng);
      const uint64_t wanted = a.run(t, resident, {}, v, 0.25f, false).wanted_triangles;
      const uint64_t budget = 250 + uint64_t(rng() % (wanted + 1));
      const HlodCut& u = a.run(t, resident, {}, v, 0.25f, false, budget, HlodBudgetPass::undo);
      const HlodCut& r = b.run(t, resident, {}, v, 0.25f, false, budget, HlodBudgetPass::refine);
      ASSERT_EQ(u.drawn.size(), r.drawn.size()) << "depth " << depth << " view " << k;
      for (size_t i = 0; i < u.drawn.size(); ++i) {
        ASSERT_EQ(u.drawn[i].node, r.drawn[i].node);
        ASSERT_EQ(u.drawn[i].layer, r.drawn[i].layer);
      }
      EXPECT_EQ(u.opened, r.opened);
      EXPECT_EQ(u.triangles, r.triangles);
      EXPECT_EQ(u.undone, r.undone);
      ++compared;
      undone += int(u.undone);
    }
  }
  EXPECT_EQ(compared, 180);
  EXPECT_GT(undone, 500);
}

TEST(HlodSelect, BudgetUndoesTheFarRefinementFirst) {
  // Root opened into 8 children at layer 0; the children farther away give way first.
  const HlodTree t = test::full_octree({.depth = 1, .triangles = 800});
  Selector sel(t);
  const std::vector<uint8_t> resident(t.nodes.size(), 1);
  const View v = looking_at({0, 0, 66}, {0, 0, 0});
  const HlodCut& free_cut = sel.run(t, resident, {}, v, 0.25f, false);
  ASSERT_EQ(free_cut.opened.size(), 1u);
  const uint64_t wanted = free_cut.triangles;
  const HlodCut& cut = sel.run(t, resident, {}, v, 0.25f, false, wanted - 1);
  EXPECT_EQ(cut.undone, 1u);
  EXPECT_LE(cut.triangles, wanted - 1);
  // The one coarsened child is one of the four far (z < 0) ones.
  for (const HlodDraw& d : cut.drawn) {
    if (d.layer == 0) continue;
    EXPECT_LT(t.nodes[d.node].box_center[2], 0.f) << d.node;
  }
}

TEST(HlodSelect, BudgetBelowTheSmallestCutDrawsTheRootCoarsest) {
  const HlodTree t = test::full_octree({.depth = 2});
  Selector sel(t);
  const std::vector<uint8_t> resident(t.nodes.size(), 1);
  const HlodCut& cut = sel.run(t, resident, {}, looking_at({0, 0, 150}, {0, 0, 0}), 0.5f, true, 10);
  ASSERT_EQ(cut.drawn.size(), 1u);
  EXPECT_EQ(cut.drawn[0].node, 0u);
  EXPECT_EQ(cut.drawn[0].layer, 2u);
  EXPECT_TRUE(cut.opened.empty());
  EXPECT_TRUE(cut.over_budget);
}

TEST(HlodSelect, RequestsLargestDeficitFirstThenNearest) {
  const HlodTree t = test::full_octree({.depth = 2});
  Selector sel(t);
  std::vector<uint8_t> resident(t.nodes.size(), 0);
  for (uint32_t i = 0; i <= 8; ++i) resident[i] = 1;  // root and children; no grandchild
  const HlodCut& cut = sel.run(t, resident, {}, looking_at({10, 20, 90}, {0, 0, 0}), 0.25f, false);
  ASSERT_GT(cut.requests.size(), 8u);
  for (size_t i = 1; i < cut.requests.size(); ++i)
    EXPECT_TRUE(request_before(cut.requests[i - 1], cut.requests[i]));
  for (const HlodRequest& r : cut.requests) EXPECT_GE(t.nodes[r.node].depth, 2u);
}

TEST(HlodSelect, SteadyStateKeepsItsBuffers) {
  // After prepare_hlod_cut nothing grows: the outputs and scratch keep their storage.
  const HlodTree t = test::random_octree(9, 2000, 6);
  Selector sel(t);
  std::mt19937 rng(1);
  auto storage = [&] {
    return std::vector<const void*>{sel.cut.drawn.data(),    sel.cut.opened.data(), sel.cut.culled.data(),
                                    sel.cut.requests.data(), sel.cut.kept.data(),   sel.scratch.queue.data(),
                                    sel.scratch.heap.data()};
  };
  const auto before = storage();
  for (int k = 0; k < 200; ++k) {
    const auto resident = random_residency(t.nodes.size(), rng, 100 - uint32_t(k % 50));
    sel.run(t, resident, random_transform(rng), random_view(rng), 0.25f, k % 2 == 0, 500 + rng() % 50000);
    ASSERT_EQ(storage(), before) << "frame " << k;
  }
}

}  // namespace
}  // namespace lod
