// DrawList and MeshLayout: what the viewer would submit for a frame, without a GL context.
#include <gtest/gtest.h>

#include <cmath>

#include "viewer/draw_list.h"
#include "viewer/mesh_layout.h"

namespace {

using namespace lod;
using namespace lod::viewer;

// A chain whose level k has `tris[k]` triangles over its own `3 * tris[k]` vertices.
LodChain chain_with_levels(std::vector<uint32_t> tris) {
  LodChain c;
  for (uint32_t t : tris) {
    LodLevel l;
    l.first_index = uint32_t(c.indices.size());
    l.index_count = 3 * t;
    l.first_vertex = uint32_t(c.positions.size() / 3);
    l.vertex_count = 3 * t;
    for (uint32_t i = 0; i < 3 * t; ++i) {
      c.indices.push_back(i);
      c.positions.insert(c.positions.end(), {float(i), 0, 0});
      c.normals.insert(c.normals.end(), {0, 1, 0});
    }
    c.levels.push_back(l);
  }
  return c;
}

// Entry i's transform in frame_of: at (i, 2i, 3i), scale 1 + i, turned 0.5 i radians about +y.
Transform transform_at(size_t i) {
  Transform t;
  t.position[0] = float(i);
  t.position[1] = 2 * float(i);
  t.position[2] = 3 * float(i);
  t.rotation[1] = std::sin(0.25f * float(i));
  t.rotation[3] = std::cos(0.25f * float(i));
  t.scale = 1 + float(i);
  return t;
}

// A whole hand-built frame: entry i is object i of model models[i] at levels[i], settled, at
// transform_at(i). No scene is involved: the draw list reads the frame alone.
Frame frame_of(std::vector<uint32_t> models, std::vector<uint8_t> levels) {
  Frame f;
  f.models = models;
  f.levels = levels;
  f.morph.assign(models.size(), 1.f);
  for (size_t i = 0; i < models.size(); ++i) {
    f.transforms.push_back(transform_at(i));
    f.objects.push_back(uint32_t(i));
    f.handles.push_back(ObjectHandle(i + 1));
    f.view_masks.push_back(1);
  }
  f.visible = uint32_t(models.size());
  f.object_count = f.visible;
  return f;
}

TEST(MeshLayout, OffsetsAddEachChainsBases) {
  const std::vector<LodChain> chains = {chain_with_levels({4, 2}), chain_with_levels({5, 3, 1})};
  const MeshLayout m = layout_meshes(chains);
  ASSERT_EQ(m.ranges.size(), 5u);
  EXPECT_EQ(m.first_range, (std::vector<uint32_t>{0, 2}));
  EXPECT_EQ(m.level_count, (std::vector<uint32_t>{2, 3}));
  // Chain 0: 18 indices over 18 vertices; chain 1 starts after them.
  EXPECT_EQ(m.ranges[1].first_index, 12u);
  EXPECT_EQ(m.ranges[1].base_vertex, 12);
  EXPECT_EQ(m.ranges[2].first_index, 18u);
  EXPECT_EQ(m.ranges[2].base_vertex, 18);
  EXPECT_EQ(m.ranges[4].first_index, 18u + 24u);
  EXPECT_EQ(m.ranges[4].index_count, 3u);
  EXPECT_EQ(m.vertex_count, 18u + 27u);
  EXPECT_EQ(m.index_count, 18u + 27u);

  std::vector<float> vertices;
  std::vector<uint32_t> indices;
  pack_vertices(chains, vertices, indices);
  EXPECT_EQ(vertices.size(), 6 * m.vertex_count);
  EXPECT_EQ(indices.size(), m.index_count);
  // Vertex 20 is chain 1's vertex 2: x = 2, normal +y.
  EXPECT_EQ(vertices[6 * 20 + 0], 2.f);
  EXPECT_EQ(vertices[6 * 20 + 4], 1.f);
}

// Chain 0 without materials; chain 1 with two materials, level 0 split into runs of 3 and 2
// triangles, level 1 one run of the default material, level 2 one run of material 1.
TEST(MeshLayout, MaterialRunsSitInTheSharedIndexBufferWithSceneWideMaterials) {
  std::vector<LodChain> chains = {chain_with_levels({4, 2}), chain_with_levels({5, 3, 1})};
  LodChain& c = chains[1];
  c.materials.resize(2);
  c.submeshes = {{0, 0, 9, 1}, {0, 9, 6, 0}, {1, 0, 9, -1}, {2, 0, 3, 1}};
  c.uvs.assign(2 * (c.positions.size() / 3), 0.5f);
  const MeshLayout m = layout_meshes(chains);
  EXPECT_EQ(m.first_material, (std::vector<uint32_t>{0, 0}));
  EXPECT_EQ(m.material_count, 2u);
  EXPECT_EQ(m.ranges[0].run_count, 0u);
  EXPECT_EQ(m.ranges[1].run_count, 0u);
  ASSERT_EQ(m.ranges[2].run_count, 2u);
  ASSERT_EQ(m.runs.size(), 4u);
  const MaterialRun& second = m.runs[m.ranges[2].first_run + 1];
  EXPECT_EQ(second.first_index, 18u + 9u);
  EXPECT_EQ(second.index_count, 6u);
  EXPECT_EQ(second.material, 0);
  EXPECT_EQ(m.runs[m.ranges[3].first_run].material, -1);
  EXPECT_EQ(m.runs[m.ranges[4].first_run].first_index, 18u + 24u);
  EXPECT_EQ(m.runs[m.ranges[4].first_run].material, 1);

  // A third chain's materials come after chain 1's.
  chains.push_back(chains[1]);
  EXPECT_EQ(layout_meshes(chains).first_material, (std::vector<uint32_t>{0, 0, 2}));

  std::vector<float> uvs;
  pack_uvs(chains, uvs);
  ASSERT_EQ(uvs.size(), 2 * (18u + 27u + 27u));
  EXPECT_EQ(uvs[0], 0.f);             // chain 0 has none: zeros
  EXPECT_EQ(uvs[2 * 18], 0.5f);       // chain 1's first vertex
}

// A run reaching past its level (an unvalidated chain) is dropped, not drawn from the next level.
TEST(MeshLayout, RunPastItsLevelIsDropped) {
  std::vector<LodChain> chains = {chain_with_levels({2, 1})};
  chains[0].materials.resize(1);
  chains[0].submeshes = {{0, 0, 3, 0}, {0, 3, 9, 0}, {1, 0, 3, 0}};
  const MeshLayout m = layout_meshes(chains);
  EXPECT_EQ(m.ranges[0].run_count, 1u);
  EXPECT_EQ(m.ranges[1].run_count, 1u);
}

TEST(MeshLayout, ChainWithoutNormalsGetsZeroNormals) {
  LodChain c = chain_with_levels({1});
  c.normals.clear();
  std::vector<float> vertices;
  std::vector<uint32_t> indices;
  pack_vertices(std::vector<LodChain>{c}, vertices, indices);
  ASSERT_EQ(vertices.size(), 18u);
  EXPECT_EQ(vertices[3], 0.f);
  EXPECT_EQ(vertices[4], 0.f);
  EXPECT_EQ(vertices[5], 0.f);
}

TEST(DrawList, OneBatchPerModelAndLevelWithInstancesGrouped) {
  const std::vector<LodChain> chains = {chain_with_levels({4, 2}), chain_with_levels({5, 3, 1})};
  const MeshLayout m = layout_meshes(chains);
  // Entries 0, 2 at model 0 level 1; entry 4 at model 0 level 0; 1, 5 at model 1 level 2; 3 at level 0.
  Frame f = frame_of({0, 1, 0, 1, 0, 1}, {1, 2, 1, 0, 0, 2});
  f.morph = {1, 0.25f, 1, 1, 1, 0.5f};
  DrawList list;
  build_draw_list(f, m, list);
  ASSERT_EQ(list.batches.size(), 4u);
  EXPECT_EQ(list.rejected, 0u);
  // In (model, level) order.
  EXPECT_EQ(list.batches[0].model, 0u);
  EXPECT_EQ(list.batches[0].level, 0u);
  EXPECT_EQ(list.batches[0].instance_count, 1u);
  EXPECT_EQ(list.batches[1].level, 1u);
  EXPECT_EQ(list.batches[1].instance_count, 2u);
  EXPECT_EQ(list.batches[2].model, 1u);
  EXPECT_EQ(list.batches[2].level, 0u);
  EXPECT_EQ(list.batches[3].level, 2u);
  EXPECT_EQ(list.batches[3].range, m.range_of(1, 2));
  // Instances of a batch are contiguous and carry their entry's transform and morph.
  const DrawBatch& b = list.batches[3];
  const InstanceData& a = list.instances[b.first_instance];
  const InstanceData& c = list.instances[b.first_instance + 1];
  EXPECT_EQ(a.position_scale[0], 1.f);  // entry 1
  EXPECT_EQ(a.morph, 0.25f);
  EXPECT_EQ(c.position_scale[2], 15.f);  // entry 5: z = 3 * 5
  EXPECT_EQ(c.position_scale[3], 6.f);
  EXPECT_EQ(c.rotation[1], std::sin(1.25f));
  EXPECT_EQ(c.rotation[3], std::cos(1.25f));
  EXPECT_EQ(c.morph, 0.5f);
  // Triangles: 4 + 2*2 + 5 + 2*1.
  EXPECT_EQ(list.triangles, 4u + 4u + 5u + 2u);
  EXPECT_EQ(list.indices, 3 * list.triangles);
}

TEST(DrawList, InstanceCarriesTheFramesRotationQuaternionPositionAndScaleExactly) {
  const std::vector<LodChain> chains = {chain_with_levels({4, 2}), chain_with_levels({5, 3, 1})};
  const MeshLayout m = layout_meshes(chains);
  Frame f = frame_of({1}, {1});
  // 90 degrees about +x, somewhere no placement rule would put it.
  Transform& t = f.transforms[0];
  const float h = std::sqrt(0.5f);
  t = Transform{{5.5f, -2.25f, 7.f}, {h, 0.f, 0.f, h}, 2.5f};
  DrawList list;
  build_draw_list(f, m, list);
  ASSERT_EQ(list.instances.size(), 1u);
  ASSERT_EQ(list.batches.size(), 1u);
  EXPECT_EQ(list.batches[0].model, 1u) << "the frame's model column";
  EXPECT_EQ(list.batches[0].level, 1u);
  const InstanceData& d = list.instances[0];
  EXPECT_EQ(d.rotation[0], h);
  EXPECT_EQ(d.rotation[1], 0.f);
  EXPECT_EQ(d.rotation[2], 0.f);
  EXPECT_EQ(d.rotation[3], h);
  EXPECT_EQ(d.position_scale[0], 5.5f);
  EXPECT_EQ(d.position_scale[1], -2.25f);
  EXPECT_EQ(d.position_scale[2], 7.f);
  EXPECT_EQ(d.position_scale[3], 2.5f);
  // A quaternion is handed on as the frame gives it (the shader normalises): not rescaled.
  t.rotation[0] = 2 * h;
  t.rotation[3] = 2 * h;
  build_draw_list(f, m, list);
  ASSERT_EQ(list.instances.size(), 1u);
  EXPECT_EQ(list.instances[0].rotation[0], 2 * h);
  EXPECT_EQ(list.instances[0].rotation[3], 2 * h);
}

TEST(DrawList, RefusesUnknownModelsAndLevelsAndCountsThem) {
  const std::vector<LodChain> chains = {chain_with_levels({4, 2})};
  const MeshLayout m = layout_meshes(chains);
  const Frame f = frame_of({0, 0, 9}, {1, 2, 0});  // level 2 does not exist; model 9 neither
  DrawList list;
  build_draw_list(f, m, list);
  EXPECT_EQ(list.rejected, 2u);
  ASSERT_EQ(list.batches.size(), 1u);
  EXPECT_EQ(list.instances.size(), 1u);
  EXPECT_EQ(list.triangles, 2u);
}

TEST(DrawList, RefusesTransformsNoRendererCanDraw) {
  const std::vector<LodChain> chains = {chain_with_levels({4, 2})};
  const MeshLayout m = layout_meshes(chains);
  Frame f = frame_of({0, 0, 0, 0}, {0, 0, 0, 0});
  f.transforms[0].rotation[3] = 0;  // entry 0 has no rotation at all: (0, 0, 0, 0)
  f.transforms[1].scale = 0;
  f.transforms[2].position[1] = std::nanf("");
  DrawList list;
  build_draw_list(f, m, list);
  EXPECT_EQ(list.rejected, 3u);
  ASSERT_EQ(list.instances.size(), 1u);
  EXPECT_EQ(list.instances[0].position_scale[0], 3.f) << "entry 3 only";
}

TEST(DrawList, ColumnsOfDifferentLengthDrawTheCommonPrefixAndRefuseTheRest) {
  const std::vector<LodChain> chains = {chain_with_levels({4, 2})};
  const MeshLayout m = layout_meshes(chains);
  for (int column = 0; column < 4; ++column) {
    SCOPED_TRACE("shortened column " + std::to_string(column));
    Frame f = frame_of({0, 0, 0}, {0, 0, 0});
    if (column == 0) f.levels.pop_back();
    if (column == 1) f.models.pop_back();
    if (column == 2) f.transforms.pop_back();
    if (column == 3) f.morph.pop_back();
    DrawList list;
    build_draw_list(f, m, list);
    EXPECT_EQ(list.instances.size(), 2u);
    EXPECT_EQ(list.triangles, 8u);
    EXPECT_EQ(list.rejected, 1u);
  }
}

TEST(DrawList, EmptyFrameDrawsNothingAndReusesTheList) {
  const std::vector<LodChain> chains = {chain_with_levels({4})};
  const MeshLayout m = layout_meshes(chains);
  DrawList list;
  build_draw_list(frame_of({0}, {0}), m, list);
  EXPECT_EQ(list.batches.size(), 1u);
  build_draw_list(Frame{}, m, list);
  EXPECT_TRUE(list.batches.empty());
  EXPECT_TRUE(list.instances.empty());
  EXPECT_EQ(list.triangles, 0u);
  EXPECT_EQ(list.rejected, 0u);
}

// A vd entry for frame entry `entry` (its object, or `object` when given) with `vertices`
// vertices and the given local indices, appended to the frame's vd arrays.
void add_vd(Frame& f, uint32_t entry, uint32_t vertices, std::vector<uint32_t> indices, int64_t object = -1) {
  VdObjectFrame v;
  v.entry = entry;
  v.object = object >= 0 ? uint32_t(object) : entry < f.objects.size() ? f.objects[entry] : entry;
  v.first_vertex = uint32_t(f.vd_positions.size() / 3);
  v.vertex_count = vertices;
  v.first_index = uint32_t(f.vd_indices.size());
  v.index_count = uint32_t(indices.size());
  for (uint32_t i = 0; i < 3 * vertices; ++i) f.vd_positions.push_back(float(i));
  f.vd_indices.insert(f.vd_indices.end(), indices.begin(), indices.end());
  f.vd_active_tris += indices.size() / 3;
  f.vd_objects.push_back(v);
}

TEST(DrawList, VdObjectsDrawFromTheirActiveMeshNotAnInstance) {
  const std::vector<LodChain> chains = {chain_with_levels({4, 2}), chain_with_levels({5, 3, 1})};
  const MeshLayout m = layout_meshes(chains);
  Frame f = frame_of({0, 1, 0, 1}, {0, 1, 1, 2});
  f.morph = {1, 0.25f, 1, 1};
  f.objects = {0, 10, 20, 30};  // entries and object ids differ: the vd entry says which entry
  f.tris_selected = 4 + 3 + 2 + 1;
  add_vd(f, 1, 4, {0, 1, 2, 0, 2, 3});           // 2 triangles instead of level 1's 3
  add_vd(f, 3, 3, {0, 1, 2, 2, 1, 0, 0, 2, 1});  // 3 triangles instead of level 2's 1
  DrawList list;
  build_draw_list(f, m, list);
  EXPECT_EQ(list.rejected, 0u);
  EXPECT_EQ(list.instances.size(), 2u) << "entries 0 and 2 only";
  EXPECT_EQ(list.triangles, 4u + 2u);
  ASSERT_EQ(list.vd.size(), 2u);
  EXPECT_EQ(list.vd_triangles, 5u);
  EXPECT_EQ(list.vd_level_triangles, 3u + 1u);
  EXPECT_EQ(selected_as_drawn(f, list), list.triangles + list.vd_triangles);
  const VdDraw& a = list.vd[0];
  EXPECT_EQ(a.object, 10u);
  EXPECT_EQ(a.entry, 1u);
  EXPECT_EQ(a.first_vertex, 0u);
  EXPECT_EQ(a.index_count, 6u);
  EXPECT_EQ(a.transform.position_scale[0], 1.f);  // entry 1's transform
  EXPECT_EQ(a.transform.position_scale[3], 2.f);
  EXPECT_EQ(a.transform.rotation[1], std::sin(0.25f));
  EXPECT_EQ(a.transform.morph, 1.f) << "the vd mesh is already geomorphed";
  EXPECT_EQ(list.vd[1].first_vertex, 4u);
  EXPECT_EQ(list.vd[1].first_index, 6u);
  for (const DrawBatch& b : list.batches) EXPECT_EQ(b.model, 0u) << "no model-1 instance is drawn";
}

TEST(DrawList, VdEntriesOutsideTheFrameAreRejectedAndDrawnAtTheirLevel) {
  const std::vector<LodChain> chains = {chain_with_levels({4, 2})};
  const MeshLayout m = layout_meshes(chains);
  Frame f = frame_of({0, 0, 0}, {1, 1, 1});
  add_vd(f, 0, 3, {0, 1, 3});     // index 3 of 3 vertices
  add_vd(f, 1, 3, {0, 1});        // not whole triangles
  add_vd(f, 3, 3, {0, 1, 2});     // entry 3: there is none
  add_vd(f, 2, 3, {0, 1, 2}, 7);  // entry 2 is object 2, not 7
  add_vd(f, 2, 3, {0, 1, 2});
  f.vd_objects.back().first_index = 100;  // past vd_indices
  DrawList list;
  build_draw_list(f, m, list);
  EXPECT_EQ(list.rejected, 5u);
  EXPECT_TRUE(list.vd.empty());
  EXPECT_EQ(list.vd_triangles, 0u);
  EXPECT_EQ(list.vd_level_triangles, 0u);
  EXPECT_EQ(list.instances.size(), 3u) << "a refused vd mesh falls back to the entry's level";
  EXPECT_EQ(list.triangles, 3u * 2u);
}

}  // namespace
