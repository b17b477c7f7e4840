// Level blending in the viewer without a GL context: how morphing objects are batched and
// weighted, and the morph-target streams the vertex shader mixes towards (checked on a real
// QEM chain by doing on the CPU what the shader does).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <set>

#include "preprocess/lod_bake.h"
#include "test_support.h"
#include "textured_fixture.h"
#include "viewer/draw_list.h"
#include "viewer/mesh_layout.h"
#include "viewer/morph_streams.h"

namespace {

using namespace lod;
using namespace lod::viewer;

// Level k has tris[k] triangles over its own 3 * tris[k] vertices; vertex v of level k
// morphs into vertex v % (next level's vertices).
LodChain chain_with_targets(std::vector<uint32_t> tris) {
  LodChain c;
  for (uint32_t t : tris) {
    LodLevel l;
    l.first_index = uint32_t(c.indices.size());
    l.index_count = 3 * t;
    l.first_vertex = uint32_t(c.positions.size() / 3);
    l.vertex_count = 3 * t;
    for (uint32_t i = 0; i < 3 * t; ++i) {
      c.indices.push_back(i);
      c.positions.insert(c.positions.end(), {float(i), float(c.levels.size()), 0});
      c.normals.insert(c.normals.end(), {0, 1, 0});
    }
    c.levels.push_back(l);
  }
  for (size_t k = 0; k + 1 < c.levels.size(); ++k)
    for (uint32_t v = 0; v < c.levels[k].vertex_count; ++v) c.morph_targets.push_back(v % c.levels[k + 1].vertex_count);
  return c;
}

// The frame's own model and (identity) transform column for entries of these models.
void set_models(Frame& f, std::vector<uint32_t> models) {
  f.models = models;
  f.transforms.assign(models.size(), Transform{});
}

TEST(MorphDraw, DrawsTheFinerLevelWeightedSoBothEndsLookLikeTheirLevel) {
  // Coarsening 1 -> 3: starts as level 1 (weight 0), ends on level 3's surface (weight 1).
  MorphDraw d = morph_draw(1, 3, 0.25f);
  EXPECT_EQ(d.level, 1u);
  EXPECT_EQ(d.target, 3u);
  EXPECT_EQ(d.weight, 0.25f);
  EXPECT_EQ(morph_draw(1, 3, 0.f).weight, 0.f);
  // Refining 3 -> 1: starts on level 3's surface (weight 1), ends as level 1 (weight 0).
  d = morph_draw(3, 1, 0.25f);
  EXPECT_EQ(d.level, 1u);
  EXPECT_EQ(d.target, 3u);
  EXPECT_EQ(d.weight, 0.75f);
  EXPECT_EQ(morph_draw(3, 1, 0.f).weight, 1.f);
  // Settled (or no change): the selected level, nothing blends.
  for (const MorphDraw s : {morph_draw(3, 1, 1.f), morph_draw(2, 2, 0.5f)}) {
    EXPECT_EQ(s.level, s.target);
    EXPECT_EQ(s.weight, 0.f);
  }
  EXPECT_EQ(morph_draw(3, 1, 1.f).level, 1u);
}

TEST(DrawList, GroupsMorphingObjectsByLevelAndTargetAndCountsWhatTheyAdd) {
  const std::vector<LodChain> chains = {chain_with_targets({8, 4, 2}), chain_with_targets({6, 3})};
  const MeshLayout m = layout_meshes(chains);
  ASSERT_EQ(m.morphable, (std::vector<uint8_t>{1, 1}));
  Frame f;
  set_models(f, {0, 0, 0, 0, 1, 1});
  f.objects = {0, 1, 2, 3, 4, 5};
  f.levels = {2, 2, 0, 1, 1, 1};
  f.from_levels = {0, 2, 2, 1, 0, 1};
  f.morph = {0.25f, 1, 0.5f, 1, 0.75f, 1};
  f.visible = 6;
  DrawList list;
  build_draw_list(f, m, list);
  EXPECT_EQ(list.rejected, 0u);
  // Model 0: object 0 coarsens 0 -> 2 and object 2 refines 2 -> 0: both draw level 0 blending
  // to level 2; object 3 level 1; object 1 level 2. Model 1: object 4 coarsens 0 -> 1; object 5 at 1.
  ASSERT_EQ(list.batches.size(), 5u);
  const std::array<std::array<uint32_t, 4>, 5> want = {{
      {0, 0, 2, 2},  // model, level, target, instances
      {0, 1, 1, 1},
      {0, 2, 2, 1},
      {1, 0, 1, 1},
      {1, 1, 1, 1},
  }};
  for (size_t b = 0; b < want.size(); ++b) {
    SCOPED_TRACE("batch " + std::to_string(b));
    EXPECT_EQ(list.batches[b].model, want[b][0]);
    EXPECT_EQ(list.batches[b].level, want[b][1]);
    EXPECT_EQ(list.batches[b].target_level, want[b][2]);
    EXPECT_EQ(list.batches[b].instance_count, want[b][3]);
    EXPECT_EQ(list.batches[b].range, m.range_of(want[b][0], want[b][1]));
  }
  const DrawBatch& blended = list.batches[0];
  EXPECT_EQ(list.instances[blended.first_instance].weight, 0.25f);      // object 0: coarsening
  EXPECT_EQ(list.instances[blended.first_instance + 1].weight, 0.5f);   // object 2: 1 - 0.5
  EXPECT_EQ(list.instances[list.batches[3].first_instance].weight, 0.75f);
  EXPECT_EQ(list.instances[list.batches[1].first_instance].weight, 0.f);
  EXPECT_EQ(list.morphing, 3u);
  // Object 0 draws 8 instead of 2, object 4 draws 6 instead of 3; object 2 goes to level 0.
  EXPECT_EQ(list.morph_triangles, 6u + 3u);
  EXPECT_EQ(list.triangles, 8u + 8u + 4u + 2u + 6u + 3u);
}

TEST(DrawList, BadFromLevelsAreRefusedAndChainsWithoutTargetsNeverBlend) {
  std::vector<LodChain> chains = {chain_with_targets({8, 4, 2}), chain_with_targets({6, 3})};
  chains[1].morph_targets.clear();
  const MeshLayout m = layout_meshes(chains);
  EXPECT_EQ(m.morphable, (std::vector<uint8_t>{1, 0}));
  Frame f;
  set_models(f, {0, 0, 1});
  f.objects = {0, 1, 2};
  f.levels = {1, 1, 1};
  f.from_levels = {7, 1, 0};
  f.morph = {0.5f, 1, 0.5f};
  f.visible = 3;
  DrawList list;
  build_draw_list(f, m, list);
  EXPECT_EQ(list.rejected, 1u);  // object 0 morphs from a level its model lacks
  ASSERT_EQ(list.batches.size(), 2u);
  EXPECT_EQ(list.batches[1].model, 1u);
  EXPECT_EQ(list.batches[1].level, 1u);
  EXPECT_EQ(list.batches[1].target_level, 1u) << "a chain without morph targets pops";
  EXPECT_EQ(list.morphing, 0u);
  // A frame without from_levels (hand-built, culled objects) is settled.
  f.from_levels.clear();
  build_draw_list(f, m, list);
  EXPECT_EQ(list.rejected, 0u);
  EXPECT_EQ(list.morphing, 0u);
}

LodChain baked_sphere(const std::string& tag) {
  const auto path = test::temp_dir(tag) / "sphere.off";
  test::write_text(path, test::sphere_off(20, 28));
  BakeSettings settings;
  settings.method = SimplifyMethod::qem;
  LodChain chain;
  const Status st = bake_model(path, "sphere", settings, chain, nullptr, nullptr);
  EXPECT_TRUE(st) << st.message;
  return chain;
}

// What the vertex shader computes for a blended draw: mix(own, target stream, w).
std::vector<float> shader_positions(const LodChain& c, uint32_t fine, const std::vector<float>& stream,
                                    int64_t first, float w) {
  const LodLevel& l = c.levels[fine];
  std::vector<float> out(3 * size_t(l.vertex_count));
  for (size_t v = 0; v < l.vertex_count; ++v)
    for (int k = 0; k < 3; ++k) {
      const float own = c.positions[3 * (size_t(l.first_vertex) + v) + k];
      const float target = stream[MorphStreams::kFloatsPerVertex * (size_t(first) + v) + k];
      out[3 * v + k] = (1 - w) * own + w * target;
    }
  return out;
}

using Corner = std::array<float, 3>;
using Triangle = std::array<Corner, 3>;
Triangle sorted_triangle(const float* a, const float* b, const float* c) {
  Triangle t = {Corner{a[0], a[1], a[2]}, Corner{b[0], b[1], b[2]}, Corner{c[0], c[1], c[2]}};
  std::sort(t.begin(), t.end());
  return t;
}

TEST(MorphStreams, AtWeightOneTheFinerLevelIsDrawnAsTheCoarserOne) {
  const LodChain c = baked_sphere("morph-streams");
  ASSERT_GE(c.levels.size(), 4u);
  MorphStreams streams(std::span(&c, 1));
  for (const auto& [fine, coarse] : {std::pair{0u, 1u}, std::pair{0u, 3u}, std::pair{1u, 2u}}) {
    SCOPED_TRACE("level " + std::to_string(fine) + " -> " + std::to_string(coarse));
    const int64_t first = streams.offset_of(0, fine, coarse);
    ASSERT_GE(first, 0);
    const std::vector<float>& stream = streams.vertices();
    ASSERT_GE(stream.size(), MorphStreams::kFloatsPerVertex * (size_t(first) + c.levels[fine].vertex_count));
    const LodLevel& f = c.levels[fine];
    const LodLevel& k = c.levels[coarse];
    // Weight 0: exactly the finer level.
    const std::vector<float> at0 = shader_positions(c, fine, stream, first, 0.f);
    EXPECT_TRUE(std::equal(at0.begin(), at0.end(), c.positions.begin() + 3 * size_t(f.first_vertex)));
    // Weight 1: every vertex on a coarse vertex, non-degenerate triangles = coarse triangles.
    const std::vector<float> at1 = shader_positions(c, fine, stream, first, 1.f);
    std::set<Corner> coarse_vertices;
    for (size_t v = 0; v < k.vertex_count; ++v) {
      const float* p = &c.positions[3 * (size_t(k.first_vertex) + v)];
      coarse_vertices.insert({p[0], p[1], p[2]});
    }
    for (size_t v = 0; v < f.vertex_count; ++v)
      ASSERT_TRUE(coarse_vertices.count({at1[3 * v], at1[3 * v + 1], at1[3 * v + 2]})) << "vertex " << v;
    std::set<Triangle> coarse_tris, drawn_tris;
    for (uint32_t i = 0; i < k.index_count; i += 3) {
      const uint32_t* t = &c.indices[k.first_index + i];
      const float* base = &c.positions[3 * size_t(k.first_vertex)];
      coarse_tris.insert(sorted_triangle(base + 3 * t[0], base + 3 * t[1], base + 3 * t[2]));
    }
    for (uint32_t i = 0; i < f.index_count; i += 3) {
      const uint32_t* t = &c.indices[f.first_index + i];
      const Triangle d = sorted_triangle(&at1[3 * t[0]], &at1[3 * t[1]], &at1[3 * t[2]]);
      if (d[0] != d[1] && d[1] != d[2]) drawn_tris.insert(d);
    }
    EXPECT_TRUE(drawn_tris == coarse_tris) << drawn_tris.size() << " drawn vs " << coarse_tris.size() << " coarse";
  }
  // Streams are made once and kept.
  EXPECT_EQ(streams.stream_count(), 3u);
  const size_t floats = streams.vertices().size();
  EXPECT_EQ(streams.offset_of(0, 0, 3), int64_t(c.levels[0].vertex_count));
  EXPECT_EQ(streams.vertices().size(), floats);
  EXPECT_EQ(streams.offset_of(0, 0, 1), 0);
  // Pairs that are not finer -> coarser, unknown models and levels: no stream.
  EXPECT_EQ(streams.offset_of(0, 2, 2), -1);
  EXPECT_EQ(streams.offset_of(0, 3, 1), -1);
  EXPECT_EQ(streams.offset_of(1, 0, 1), -1);
  EXPECT_EQ(streams.offset_of(0, 0, uint32_t(c.levels.size())), -1);
  EXPECT_EQ(streams.stream_count(), 3u);
}

// The stream carries each fine vertex's target uv too (after its position and normal), which the
// shader mixes with the vertex's own uv by the blend weight.
TEST(MorphStreams, UvsBlendTowardsTheTargetVertexsUv) {
  const auto dir = test::temp_dir("morph-streams-uv");
  const auto file = test::write_two_material_gltf(dir, "globe");
  ASSERT_FALSE(file.empty());
  BakeSettings settings;
  settings.method = SimplifyMethod::qem;
  LodChain c;
  const Status st = bake_model(file, "globe", settings, c, nullptr, nullptr);
  ASSERT_TRUE(st) << st.message;
  ASSERT_GE(c.levels.size(), 2u);
  ASSERT_EQ(2 * c.positions.size(), 3 * c.uvs.size());
  MorphStreams streams(std::span(&c, 1));
  const int64_t first = streams.offset_of(0, 0, 1);
  ASSERT_GE(first, 0);
  const LodLevel& f = c.levels[0];
  const LodLevel& k = c.levels[1];
  std::vector<uint32_t> target(f.vertex_count);
  compose_morph_targets(target, c, 0, 1);
  const std::vector<float>& stream = streams.vertices();
  size_t moved = 0;
  for (size_t v = 0; v < f.vertex_count; ++v) {
    const float* own = &c.uvs[2 * (size_t(f.first_vertex) + v)];
    const float* to = &c.uvs[2 * (size_t(k.first_vertex) + target[v])];
    const float* s = &stream[MorphStreams::kFloatsPerVertex * (size_t(first) + v) + 6];
    ASSERT_EQ(s[0], to[0]) << "vertex " << v;
    ASSERT_EQ(s[1], to[1]) << "vertex " << v;
    moved += own[0] != to[0] || own[1] != to[1];
  }
  EXPECT_GT(moved, 0u);  // some uvs do move: the blend is not the identity
}

}  // namespace
