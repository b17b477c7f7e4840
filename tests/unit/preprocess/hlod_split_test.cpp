// The HLOD build split into plan / subtree bakes / assembly: the output never
// depends on where the frontier is, which builder baked which subtree, or in which order.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "preprocess/hlod_build.h"
#include "runtime/hlod_asset.h"
#include "vd_meshes.h"

namespace lod {
namespace {

MeshData mesh() { return test::vd_concat(test::vd_sphere(40, 50, 0.4f, 0.5f, 0.3f, 0.5f), test::vd_grid(40, 40)); }

HlodBuildOptions options_with(uint32_t subtrees) {
  HlodBuildOptions o;
  o.min_verts = 150;
  o.subtrees = subtrees;
  return o;
}

std::vector<uint8_t> bytes_of(const HlodModel& m) { return encode_hlod_asset(m.tree, m.payloads); }

std::vector<uint8_t> local_build(const MeshData& m, uint32_t subtrees) {
  HlodModel model;
  const Status st = build_hlod(model, m, options_with(subtrees));
  EXPECT_TRUE(st) << st.message;
  return bytes_of(model);
}

// Every subtree of a planned builder, baked in order into `baked`.
Status bake_all(HlodBuilder& b, std::vector<HlodSubtree>& baked) {
  baked.assign(b.subtrees().size(), {});
  std::vector<size_t> all(baked.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  return b.bake_subtrees(all, [&](size_t i, HlodSubtree&& s) {
    baked[i] = std::move(s);
    return Status::success();
  });
}

TEST(HlodSplit, SameBytesWhereverTheFrontierIs) {
  const MeshData m = mesh();
  const std::vector<uint8_t> one = local_build(m, 1);
  for (uint32_t subtrees : {2u, 5u, 16u, 64u, 100000u}) EXPECT_EQ(local_build(m, subtrees), one) << subtrees << " subtrees";
}

TEST(HlodSplit, SameBytesWithTheFrontierRefinedAtRankCuts) {
  const MeshData m = mesh();
  const std::vector<uint8_t> one = local_build(m, 1);
  for (uint32_t parts : {2u, 3u, 7u, 64u}) {
    HlodBuildOptions o = options_with(4);
    o.balance_parts = parts;
    HlodModel model;
    ASSERT_TRUE(build_hlod(model, m, o));
    EXPECT_EQ(bytes_of(model), one) << parts << " parts";
  }
}

TEST(HlodSplit, FrontierHoldsNoSplittableSubtreeAboveTheLimit) {
  const MeshData m = mesh();
  const HlodBuildOptions o = options_with(16);
  HlodBuilder b(m, o);
  ASSERT_TRUE(b.plan());
  const auto& specs = b.subtrees();
  ASSERT_GE(specs.size(), 16u);
  std::vector<HlodSubtree> baked;
  ASSERT_TRUE(bake_all(b, baked));
  const uint64_t limit = m.triangle_count() / 16;
  for (size_t i = 0; i < specs.size(); ++i) {
    EXPECT_EQ(baked[i].nodes[0].depth, specs[i].depth);
    if (specs[i].triangles > limit) {
      EXPECT_EQ(baked[i].nodes.size(), 1u) << "subtree " << i << " could have split";
    }
  }
  for (size_t i = 1; i < specs.size(); ++i) EXPECT_NE(specs[i].fingerprint, specs[0].fingerprint);
}

// Every layer is measured against a BVH of the part of the original near its subtree's cell (the
// top's samples against their subtree's part again), never against a BVH of the whole: the
// parts hold each triangle about once (a margin's more), and the bytes are the local build's.
TEST(HlodSplit, ABuildMeasuresAgainstPartsOfTheOriginalNeverItsWholeBvh) {
  const MeshData m = mesh();
  HlodBuilder b(m, options_with(16));
  ASSERT_TRUE(b.plan());
  std::vector<HlodSubtree> baked;
  ASSERT_TRUE(bake_all(b, baked));
  EXPECT_GE(b.part_triangles(), m.triangle_count());
  EXPECT_LT(b.part_triangles(), m.triangle_count() * 3 / 2);
  HlodModel model;
  ASSERT_TRUE(b.assemble(baked, model));
  EXPECT_FALSE(b.whole_surface_built()) << "a query no part could answer built the whole original's BVH";
  EXPECT_GT(b.surface_cpu_seconds(), 0.0);
  EXPECT_EQ(bytes_of(model), local_build(m, 1)) << "the bytes of one subtree, whose part is the whole mesh";
}

// Three builders as three processes: two bake half the subtrees each, the third only assembles.
TEST(HlodSplit, SubtreesBakedByOtherBuildersSpliceIntoTheSameFile) {
  const MeshData m = mesh();
  const HlodBuildOptions o = options_with(16);
  HlodBuilder a(m, o), b(m, o), root(m, o);
  for (HlodBuilder* builder : {&a, &b, &root}) ASSERT_TRUE(builder->plan());
  const size_t n = root.subtrees().size();
  ASSERT_EQ(a.subtrees().size(), n);
  std::vector<size_t> even, odd;
  for (size_t i = n; i-- > 0;) (i % 2 ? odd : even).push_back(i);  // backwards too
  std::vector<HlodSubtree> baked(n);
  auto keep = [&](size_t i, HlodSubtree&& s) {
    baked[i] = std::move(s);
    return Status::success();
  };
  ASSERT_TRUE(a.bake_subtrees(even, keep));
  ASSERT_TRUE(b.bake_subtrees(odd, keep));
  for (size_t i = 0; i < n; ++i) EXPECT_EQ(a.subtrees()[i].fingerprint, root.subtrees()[i].fingerprint);
  HlodModel model;
  const Status st = root.assemble(baked, model);
  ASSERT_TRUE(st) << st.message;
  EXPECT_EQ(bytes_of(model), local_build(m, 16));
}

// Two builders (the two spatial halves of the frontier) measure the top by sample as a
// distributed build does, a third assembles: the local bytes, from BVHs of parts of the mesh.
// One baked its half; the other's half came from elsewhere (a rerun's cache), so it lists the
// parts of its region itself.
TEST(HlodSplit, TwoBuildersMeasuringTheTopBySampleGiveTheLocalBytes) {
  const MeshData m = mesh();
  const HlodBuildOptions o = options_with(16);
  HlodBuilder a(m, o), b(m, o), elsewhere(m, o), root(m, o);
  for (HlodBuilder* builder : {&a, &b, &elsewhere, &root}) ASSERT_TRUE(builder->plan());
  const size_t n = root.subtrees().size();
  std::vector<size_t> low, high;
  for (size_t i = 0; i < n; ++i) (root.subtrees()[i].spatial < n / 2 ? low : high).push_back(i);
  a.set_region(low);
  b.set_region(high);
  std::vector<HlodSubtree> baked(n);
  auto keep = [&](size_t i, HlodSubtree&& s) {
    baked[i] = std::move(s);
    return Status::success();
  };
  ASSERT_TRUE(a.bake_subtrees(low, keep));
  ASSERT_TRUE(elsewhere.bake_subtrees(high, keep));
  for (const HlodBuilder* x : {&a, &elsewhere}) {
    EXPECT_GT(x->part_triangles(), 0u);
    EXPECT_LT(x->part_triangles(), m.triangle_count());
  }
  std::vector<HlodLayerProbe> probes;
  ASSERT_TRUE(root.build_top(baked, probes));
  std::vector<size_t> first, second;
  for (size_t i = 0; i < probes.size(); ++i) (i % 2 ? second : first).push_back(i);
  std::vector<float> to_a, to_b, from_a, from_b;
  std::vector<std::vector<uint8_t>> ans_a, ans_b;
  ASSERT_TRUE(a.measure_probes_part(probes, first, to_a, ans_a, from_a));
  ASSERT_TRUE(b.measure_probes_part(probes, second, to_b, ans_b, from_b));
  std::vector<float> to(probes.size()), errors(probes.size());
  std::vector<std::vector<uint8_t>> answered(probes.size());
  size_t samples = 0, by_parts = 0, by_b = 0;
  for (size_t i = 0; i < probes.size(); ++i) {
    by_b += size_t(std::count(ans_b[i].begin(), ans_b[i].end(), 1));
    to[i] = std::max(to_a[i], to_b[i]);
    ASSERT_EQ(ans_a[i].size(), ans_b[i].size());
    answered[i].resize(ans_a[i].size());
    for (size_t k = 0; k < answered[i].size(); ++k) answered[i][k] = ans_a[i][k] | ans_b[i][k];
    samples += answered[i].size();
    by_parts += size_t(std::count(answered[i].begin(), answered[i].end(), 1));
  }
  EXPECT_GT(by_parts, samples * 9 / 10) << "the top's samples are answered by their cells' parts";
  EXPECT_GT(by_b, samples / 4) << "the builder that baked none of its region answers its cells' samples";
  ASSERT_TRUE(root.measure_probes_rest(probes, answered, to));
  for (size_t i = 0; i < probes.size(); ++i) errors[i] = std::max(to[i], (i % 2 ? from_b[i / 2] : from_a[i / 2]));
  HlodAssembly assembly;
  ASSERT_TRUE(root.finish_top(baked, errors, assembly));
  for (size_t i = 0; i < assembly.origin.size(); ++i)
    if (const HlodAssembly::Origin org = assembly.origin[i]; org.subtree >= 0)
      assembly.model.payloads[i] = std::move(baked[size_t(org.subtree)].payloads[org.local]);
  EXPECT_EQ(bytes_of(assembly.model), local_build(m, 16));
}

TEST(HlodSplit, AssemblyRefusesASubtreeInTheWrongPlace) {
  const MeshData m = mesh();
  const HlodBuildOptions o = options_with(16);
  HlodBuilder b(m, o), root(m, o);
  ASSERT_TRUE(b.plan());
  ASSERT_TRUE(root.plan());
  std::vector<HlodSubtree> baked;
  ASSERT_TRUE(bake_all(b, baked));
  std::swap(baked[0], baked[1]);
  HlodModel model;
  const Status st = root.assemble(baked, model);
  EXPECT_FALSE(st);
  EXPECT_NE(st.message.find("subtree 0"), std::string::npos) << st.message;
}

TEST(HlodSplit, SubtreeBakedTwiceIsRefused) {
  const MeshData m = mesh();
  const HlodBuildOptions o = options_with(4);
  HlodBuilder b(m, o);
  ASSERT_TRUE(b.plan());
  auto ignore = [](size_t, HlodSubtree&&) { return Status::success(); };
  ASSERT_TRUE(b.bake_subtrees({0}, ignore));
  EXPECT_FALSE(b.bake_subtrees({0}, ignore));
  EXPECT_FALSE(b.bake_subtrees({b.subtrees().size()}, ignore));
}

TEST(HlodSplit, FailureOfTheConsumerNamesTheSubtree) {
  const MeshData m = mesh();
  HlodBuilder b(m, options_with(4));
  ASSERT_TRUE(b.plan());
  const Status st = b.bake_subtrees({1}, [](size_t, HlodSubtree&&) { return Status::error("disk full"); });
  ASSERT_FALSE(st);
  EXPECT_NE(st.message.find("subtree 1"), std::string::npos) << st.message;
  EXPECT_NE(st.message.find("disk full"), std::string::npos) << st.message;
}

}  // namespace
}  // namespace lod
