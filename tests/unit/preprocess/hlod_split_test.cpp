// The HLOD build split into plan / subtree bakes / assembly (issue 16): the output never
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

TEST(HlodSplit, SameBytesWhereverTheFrontierIs) {
  const MeshData m = mesh();
  const std::vector<uint8_t> one = local_build(m, 1);
  for (uint32_t subtrees : {2u, 5u, 16u, 64u, 100000u}) EXPECT_EQ(local_build(m, subtrees), one) << subtrees << " subtrees";
}

TEST(HlodSplit, FrontierHoldsNoSplittableSubtreeAboveTheLimit) {
  const MeshData m = mesh();
  const HlodBuildOptions o = options_with(16);
  HlodBuilder b(m, o);
  ASSERT_TRUE(b.plan());
  const auto& specs = b.subtrees();
  ASSERT_GE(specs.size(), 16u);
  std::vector<HlodSubtree> baked(specs.size());
  std::vector<size_t> all(specs.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  ASSERT_TRUE(b.bake_subtrees(all, [&](size_t i, HlodSubtree&& s) {
    baked[i] = std::move(s);
    return Status::success();
  }));
  const uint64_t limit = m.triangle_count() / 16;
  for (size_t i = 0; i < specs.size(); ++i) {
    EXPECT_EQ(baked[i].nodes[0].depth, specs[i].depth);
    if (specs[i].triangles > limit) EXPECT_EQ(baked[i].nodes.size(), 1u) << "subtree " << i << " could have split";
  }
  for (size_t i = 1; i < specs.size(); ++i) EXPECT_NE(specs[i].fingerprint, specs[0].fingerprint);
}

// Three builders as three processes: two bake half the subtrees each, the third only assembles.
TEST(HlodSplit, SubtreesBakedByOtherBuildersSpliceIntoTheSameFile) {
  const MeshData m = mesh();
  const HlodBuildOptions o = options_with(16);
  HlodBuilder a(m, o), b(m, o), root(m, o);
  ASSERT_TRUE(a.plan());
  ASSERT_TRUE(b.plan());
  ASSERT_TRUE(root.plan());
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

TEST(HlodSplit, AssemblyRefusesASubtreeInTheWrongPlace) {
  const MeshData m = mesh();
  const HlodBuildOptions o = options_with(16);
  HlodBuilder b(m, o), root(m, o);
  ASSERT_TRUE(b.plan());
  ASSERT_TRUE(root.plan());
  std::vector<HlodSubtree> baked(b.subtrees().size());
  std::vector<size_t> all(baked.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  ASSERT_TRUE(b.bake_subtrees(all, [&](size_t i, HlodSubtree&& s) {
    baked[i] = std::move(s);
    return Status::success();
  }));
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
