// The vertex hierarchy in the .lod asset (optional VHIE section): round trip, assets without
// it, and damaged sections refused with a message that names them.
#include <gtest/gtest.h>

#include <bit>
#include <cstdlib>
#include <cstring>
#include <random>

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
  EXPECT_NE(s.message.find("VHIE section: node 0"), std::string::npos) << s.message;
  EXPECT_TRUE(back.hierarchy.empty());  // never half-loaded
}


// Word offsets (from the VHIE section's start, header included) of each array.
struct VhieLayout {
  size_t positions, parent, radius, cone_axis, cone_cos, error, leaf_lo, leaf_hi, leaf_rank, face_leaves,
      face_owner, children, split_faces, wings, dep_offsets, deps, inc_offsets, inc_faces, end;
};
VhieLayout vhie_layout(const VertexTree& t) {
  const size_t n = t.node_count(), l = t.leaf_count, f = t.face_count, i = n - l;
  VhieLayout o;
  o.positions = 8;
  o.parent = o.positions + 3 * n;
  o.radius = o.parent + n;
  o.cone_axis = o.radius + n;
  o.cone_cos = o.cone_axis + 3 * n;
  o.error = o.cone_cos + n;
  o.leaf_lo = o.error + n;
  o.leaf_hi = o.leaf_lo + n;
  o.leaf_rank = o.leaf_hi + n;
  o.face_leaves = o.leaf_rank + l;
  o.face_owner = o.face_leaves + 3 * f;
  o.children = o.face_owner + f;
  o.split_faces = o.children + 2 * i;
  o.wings = o.split_faces + 2 * i;
  o.dep_offsets = o.wings + 2 * i;
  o.deps = o.dep_offsets + i + 1;
  o.inc_offsets = o.deps + t.deps.size();
  o.inc_faces = o.inc_offsets + i + 1;
  o.end = o.inc_faces + t.inc_faces.size();
  return o;
}

// Each of these edits keeps every id inside its array's range and the checksum valid; the old
// reader accepted all of them (the dependency one then wrote past force_split's stack in
// `lod run`, the incident-face one tripped front_update's assert). Each must be refused by
// name, and the chain left untouched.
TEST(VertexHierarchyAsset, InRangeStructuralEditsAreRefusedNamingTheSection) {
  const LodChain c = sphere_chain(true);
  const VertexTree& t = c.hierarchy;
  const std::vector<uint8_t> good = encode_lod_asset(c);
  const VhieLayout o = vhie_layout(t);
  const uint32_t leaves = t.leaf_count, n = t.node_count();
  // An interior node with a dependency, an incident face and a split face with a wing.
  uint32_t x = kNoNode;
  for (uint32_t v = n; v-- > leaves;) {
    const uint32_t i = v - leaves;
    if (t.dep_offsets[i + 1] > t.dep_offsets[i] && t.inc_offsets[i + 1] > t.inc_offsets[i] &&
        t.wings[2 * i + 1] != kNoNode && !t.is_leaf(t.children[2 * i])) {
      x = v;
      break;
    }
  }
  ASSERT_NE(x, kNoNode);
  const uint32_t i = x - leaves;
  const uint32_t child = t.children[2 * i], grandchild = t.children[2 * (child - leaves)];
  const uint32_t inc0 = t.inc_faces[t.inc_offsets[i]];
  struct Edit {
    const char* what;
    size_t word;
    uint32_t value;
    const char* expect;
  };
  const uint32_t other_face = (inc0 + 1) % t.face_count == t.split_faces[2 * i] ? (inc0 + 2) % t.face_count
                                                                                 : (inc0 + 1) % t.face_count;
  const Edit edits[] = {
      // The case: a dependency on a node below it (force_split climbs forever).
      {"dependency on a grandchild", o.deps + t.dep_offsets[i], grandchild, "dependency"},
      {"dependency on itself-made-later", o.deps + t.dep_offsets[i], x - 1, "dependency"},
      {"incident face swapped for another in range", o.inc_faces + t.inc_offsets[i], other_face, "incident face"},
      {"wing swapped", o.wings + 2 * i + 1, t.wings[2 * i + 1] == 0 ? 1u : 0u, "VHIE section: node"},
      {"second split face equal to the first", o.split_faces + 2 * i + 1, t.split_faces[2 * i], "VHIE section"},
      {"two leaves with one rank", o.leaf_rank + 1, t.leaf_rank[0], "rank"},
      {"face repeating a vertex", o.face_leaves + 1, t.face_leaves[0], "repeats a vertex"},
      {"face owner moved", o.face_owner + t.split_faces[2 * i], x - 1, "VHIE section"},
      {"child swapped", o.children + 2 * i, grandchild, "VHIE section: node"},
      {"parent not listing the node", o.parent + grandchild, x, "VHIE section: node"},
      {"huge radius", o.radius + x, std::bit_cast<uint32_t>(3e38f), "VHIE section: node"},
      {"incidence offsets shifted", o.inc_offsets + i + 1, t.inc_offsets[i + 1] + 1, "VHIE section"},
  };
  for (const Edit& e : edits) {
    LodChain back;
    back.name = "untouched";
    const Status s = decode_lod_asset(damage_vhie(good, e.word, e.value), "ball.lod", back);
    EXPECT_FALSE(s.ok) << e.what;
    EXPECT_EQ(s.message.rfind("ball.lod: VHIE section: ", 0), 0u) << e.what << ": " << s.message;
    EXPECT_NE(s.message.find(e.expect), std::string::npos) << e.what << ": " << s.message;
    EXPECT_EQ(back.name, "untouched") << e.what;
  }
}

// Rewrites bytes anywhere in an asset and fixes the checksum: only the reader's own checks
// stand between the bytes and the runtime.
void fix_checksum(std::vector<uint8_t>& bytes) {
  const uint64_t h = hash_bytes(bytes.data(), bytes.size() - 8);
  std::memcpy(bytes.data() + bytes.size() - 8, &h, 8);
}

// A few frames of a front over `t`: a close view that wants everything split (forced splits),
// then moving away (collapses), with the budget and operation limits biting, whole and in
// regions; every front must stay a valid mesh.
void run_fronts(const VertexTree& t, const std::string& what) {
  View view;
  view.width = 320, view.height = 240, view.fov_y_deg = 60, view.near_plane = 0.01f, view.far_plane = 100;
  const float pos[3] = {0, 0, 0};
  std::vector<uint8_t> regions;
  const uint32_t used = vertex_tree_regions(regions, t, 3);
  for (int variant = 0; variant < 3; ++variant) {
    std::vector<VertexFront> fronts(variant == 2 ? used : 1);
    for (uint32_t r = 0; r < fronts.size(); ++r) {
      if (variant == 2)
        front_init(fronts[r], t, 1, regions, static_cast<uint8_t>(r));
      else
        front_init(fronts[r], t, 1);
    }
    FrontParams params;
    params.max_triangles = variant == 1 ? t.face_count / 2 : 0;
    params.max_operations = variant == 1 ? 7 : 0;
    params.collapse_delay = variant == 2 ? 0.05f : 0;
    for (int frame = 0; frame < 8; ++frame) {
      const float d = frame < 4 ? 1.2f + 0.1f * frame : 3.0f * float(frame);
      view.eye[0] = d, view.eye[1] = 0.3f * frame, view.eye[2] = d;
      view.target[0] = view.target[1] = view.target[2] = 0;
      const FrontView fv = front_view_of(view, pos, 1.f, 0.f);
      params.time = frame * 0.1;
      for (VertexFront& f : fronts) {
        front_update(f, t, fv, params);
        std::string msg;
        ASSERT_TRUE(check_front(f, t, EdgeCheck::corners, &msg)) << what << " frame " << frame << ": " << msg;
      }
    }
    for (VertexFront& f : fronts) {
      front_refine_all(f, t);
      front_coarsen_all(f, t);
      std::string msg;
      ASSERT_TRUE(check_front(f, t, EdgeCheck::corners, &msg)) << what << ": " << msg;
    }
  }
}

// Fuzz-like: random edits of a small valid asset (checksum fixed), biased towards the
// hierarchy's ids; each asset is refused or loads and runs fronts safely (this suite is in
// the ASan/UBSan stage too).
TEST(VertexHierarchyAsset, RandomEditsWithFixedChecksumAreRefusedOrRunSafely) {
  const LodChain c = sphere_chain(true);
  const std::vector<uint8_t> good = encode_lod_asset(c);
  uint64_t vhie_off = 0;
  std::memcpy(&vhie_off, good.data() + 16 + 5 * 24 + 8, 8);
  const VhieLayout o = vhie_layout(c.hierarchy);
  std::mt19937_64 rng(20261201);
  const uint32_t n = c.hierarchy.node_count();
  int loaded = 0, refused = 0;
  // LOD_ASSET_FUZZ_TRIALS=N runs longer (and LOD_ASSET_FUZZ_SEED another sequence).
  const char* trials_env = std::getenv("LOD_ASSET_FUZZ_TRIALS");
  const char* seed_env = std::getenv("LOD_ASSET_FUZZ_SEED");
  const int trials = trials_env ? std::atoi(trials_env) : 1500;
  if (seed_env) rng.seed(std::strtoull(seed_env, nullptr, 10));
  for (int trial = 0; trial < trials; ++trial) {
    std::vector<uint8_t> bytes = good;
    const int edits = 1 + int(rng() % 3);
    for (int e = 0; e < edits; ++e) {
      const uint32_t kind = rng() % 4;
      if (kind == 0) {  // any byte of the file but the checksum
        bytes[rng() % (bytes.size() - 8)] = static_cast<uint8_t>(rng());
      } else {  // a hierarchy word: a nearby value or another id in range
        const size_t word = o.parent + rng() % (o.end - o.parent);
        uint32_t v = 0;
        std::memcpy(&v, bytes.data() + vhie_off + 4 * word, 4);
        v = kind == 1 ? v + uint32_t(rng() % 5) - 2 : kind == 2 ? uint32_t(rng() % n) : v ^ (1u << (rng() % 32));
        std::memcpy(bytes.data() + vhie_off + 4 * word, &v, 4);
      }
    }
    fix_checksum(bytes);
    LodChain back;
    const Status s = decode_lod_asset(bytes, "ball.lod", back);
    if (!s.ok) {
      ++refused;
      EXPECT_EQ(s.message.rfind("ball.lod: ", 0), 0u) << s.message;
      continue;
    }
    ++loaded;
    if (back.hierarchy.empty()) continue;
    run_fronts(back.hierarchy, "trial " + std::to_string(trial));
    if (HasFatalFailure()) return;
  }
  EXPECT_GT(refused, trials * 2 / 3);
  EXPECT_GT(loaded, 0);  // edits of floats the front only reads as values load and run
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
