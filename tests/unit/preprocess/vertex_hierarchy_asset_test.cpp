// The vertex hierarchy in the .lod asset (optional VHIE section): round trip, assets without
// it, and damaged sections refused with a message that names them.
#include <gtest/gtest.h>

#include <cstring>

#include "preprocess/vertex_hierarchy.h"
#include "runtime/lod_asset.h"
#include "runtime/vertex_front.h"
#include "test_support.h"
#include "vd_meshes.h"

namespace lod {
namespace {

LodChain sphere_chain(bool with_hierarchy) {
  const MeshData m = test::vd_sphere(10, 12);
  LodChain c;
  c.name = "ball";
  c.positions = m.positions;
  c.indices = m.indices;
  LodLevel lv;
  lv.index_count = static_cast<uint32_t>(m.indices.size());
  lv.vertex_count = static_cast<uint32_t>(m.vertex_count());
  lv.level = level_of_triangles(m.triangle_count());
  lv.bounds.radius = 1;
  c.levels.push_back(lv);
  if (with_hierarchy) {
    EXPECT_TRUE(build_vertex_hierarchy(c.hierarchy, m).ok);
  }
  return c;
}

TEST(VertexHierarchyAsset, RoundTripsEveryArray) {
  const LodChain c = sphere_chain(true);
  LodChain back;
  const Status s = decode_lod_asset(encode_lod_asset(c), "ball.lod", back);
  ASSERT_TRUE(s.ok) << s.message;
  const VertexTree &a = c.hierarchy, &b = back.hierarchy;
  EXPECT_EQ(a.leaf_count, b.leaf_count);
  EXPECT_EQ(a.face_count, b.face_count);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.parent, b.parent);
  EXPECT_EQ(a.radius, b.radius);
  EXPECT_EQ(a.cone_axis, b.cone_axis);
  EXPECT_EQ(a.cone_cos, b.cone_cos);
  EXPECT_EQ(a.error, b.error);
  EXPECT_EQ(a.leaf_lo, b.leaf_lo);
  EXPECT_EQ(a.leaf_hi, b.leaf_hi);
  EXPECT_EQ(a.leaf_rank, b.leaf_rank);
  EXPECT_EQ(a.face_leaves, b.face_leaves);
  EXPECT_EQ(a.face_owner, b.face_owner);
  EXPECT_EQ(a.children, b.children);
  EXPECT_EQ(a.split_faces, b.split_faces);
  EXPECT_EQ(a.wings, b.wings);
  EXPECT_EQ(a.dep_offsets, b.dep_offsets);
  EXPECT_EQ(a.deps, b.deps);
  EXPECT_EQ(a.inc_offsets, b.inc_offsets);
  EXPECT_EQ(a.inc_faces, b.inc_faces);
  ASSERT_EQ(b.bounds.size(), b.node_count());  // packed on load, ready for a front
  VertexFront f;
  front_init(f, b, 1);
  front_refine_all(f, b);
  std::string msg;
  EXPECT_TRUE(check_front(f, b, EdgeCheck::closed, &msg)) << msg;
}

TEST(VertexHierarchyAsset, ChainsWithoutAHierarchyStayAsTheyWere) {
  const LodChain c = sphere_chain(false);
  const std::vector<uint8_t> bytes = encode_lod_asset(c);
  EXPECT_EQ(bytes.size(), encode_lod_asset(sphere_chain(false)).size());
  LodChain back;
  ASSERT_TRUE(decode_lod_asset(bytes, "ball.lod", back).ok);
  EXPECT_TRUE(back.hierarchy.empty());
  // Still version 1, five sections: readers that predate the hierarchy read it unchanged.
  uint32_t version = 0, sections = 0;
  std::memcpy(&version, bytes.data() + 8, 4);
  std::memcpy(&sections, bytes.data() + 12, 4);
  EXPECT_EQ(version, 1u);
  EXPECT_EQ(sections, 5u);
}

// Rewrites one u32 inside the VHIE section and fixes the checksum, so only VHIE's own checks
// can catch it.
std::vector<uint8_t> damage_vhie(std::vector<uint8_t> bytes, size_t word, uint32_t value) {
  uint64_t off = 0;
  std::memcpy(&off, bytes.data() + 16 + 5 * 24 + 8, 8);  // sixth table entry's offset
  std::memcpy(bytes.data() + off + 4 * word, &value, 4);
  const uint64_t h = hash_bytes(bytes.data(), bytes.size() - 8);
  std::memcpy(bytes.data() + bytes.size() - 8, &h, 8);
  return bytes;
}

TEST(VertexHierarchyAsset, DamagedSectionIsRefusedByName) {
  const LodChain c = sphere_chain(true);
  const std::vector<uint8_t> good = encode_lod_asset(c);
  LodChain back;
  // A leaf count that disagrees with level 0.
  Status s = decode_lod_asset(damage_vhie(good, 0, c.hierarchy.leaf_count - 1), "ball.lod", back);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("ball.lod"), std::string::npos);
  // A node count that does not fit the section.
  s = decode_lod_asset(damage_vhie(good, 2, 0x7fffffff), "ball.lod", back);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("VHIE"), std::string::npos) << s.message;
  // A parent pointing at a leaf: the structure check names the node.
  const size_t parent_word = 8 + 3 * size_t(c.hierarchy.node_count());
  s = decode_lod_asset(damage_vhie(good, parent_word, 1), "ball.lod", back);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("hierarchy: node 0"), std::string::npos) << s.message;
  EXPECT_TRUE(back.hierarchy.empty());  // never half-loaded
}

TEST(VertexHierarchyAsset, FileRoundTrip) {
  const LodChain c = sphere_chain(true);
  const auto dir = test::temp_dir("vhie");
  ASSERT_TRUE(write_lod_asset(dir / "ball.lod", c).ok);
  LodChain back;
  ASSERT_TRUE(read_lod_asset(dir / "ball.lod", back).ok);
  EXPECT_EQ(back.hierarchy.node_count(), c.hierarchy.node_count());
}

}  // namespace
}  // namespace lod
