#include "preprocess/mesh_clean.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lod {
namespace {

MeshData make(std::vector<float> positions, std::vector<uint32_t> indices) {
  MeshData m;
  m.positions = std::move(positions);
  m.indices = std::move(indices);
  return m;
}

TEST(MeshClean, LeavesACleanMeshAlone) {
  MeshData m = make({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}, {0, 1, 2, 1, 3, 2});
  const MeshData before = m;
  const CleanReport r = clean_mesh(m);
  EXPECT_FALSE(r.changed());
  EXPECT_EQ(m.positions, before.positions);
  EXPECT_EQ(m.indices, before.indices);
}

// glTF's optional attributes survive cleaning: a welded vertex keeps its first uv, and each
// submesh keeps exactly its surviving triangles (an emptied one goes).
TEST(MeshClean, KeepsUvsAndReRangesSubmeshes) {
  // Vertex 4 repeats vertex 1's position and uv (welded); triangle 1 is degenerate, triangle 3
  // repeats 0.
  MeshData m = make({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 1, 0, 0},
                    {0, 1, 2, 0, 0, 1, 1, 3, 2, 2, 0, 4, 4, 3, 2});
  m.uvs = {0, 0, 0.1f, 0, 0, 1, 1, 1, 0.1f, 0};
  m.submeshes = {{0, 2, 0}, {2, 2, 1}, {4, 1, 0}};
  // Triangles 0 (material 0) and 2 (material 1) share vertices 1 and 2: material 1 gets
  // copies of them (5, 6 after the input's), so the boundary is a seam.
  const CleanReport r = clean_mesh(m);
  EXPECT_EQ(r.material_split_vertices, 5u);  // 1, 2, 0 for material 1; 4, 3 for the last run (material 0)
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 4, 3, 5}));
  EXPECT_EQ(m.uvs, (std::vector<float>{0, 0, 0.1f, 0, 0, 1, 1, 1, 0.1f, 0, 0, 1}));
  ASSERT_EQ(m.submeshes.size(), 2u);  // kept: triangle 0 | triangle 2 | none (4 repeats 2 in place)
  EXPECT_EQ(m.submeshes[0].first_triangle, 0u);
  EXPECT_EQ(m.submeshes[0].triangle_count, 1u);
  EXPECT_EQ(m.submeshes[1].first_triangle, 1u);
  EXPECT_EQ(m.submeshes[1].triangle_count, 1u);
  EXPECT_EQ(m.submeshes[1].material, 1);
}

// The same position with another uv is a seam: two vertices, so the simplifier keeps it.
TEST(MeshClean, KeepsUvSeams) {
  MeshData m = make({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 1, 0, 0},
                    {0, 1, 2, 4, 3, 2});
  m.uvs = {0, 0, 0.1f, 0, 0, 1, 1, 1, 0.9f, 0};
  const CleanReport r = clean_mesh(m);
  EXPECT_EQ(r.duplicate_vertices, 0u);
  EXPECT_EQ(m.vertex_count(), 5u);
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 4, 3, 2}));
  MeshData plain = make({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 1, 0, 0}, {0, 1, 2, 4, 3, 2});
  EXPECT_EQ(clean_mesh(plain).duplicate_vertices, 1u) << "without uvs the same position welds";
}

// Vertex colours and a second uv set key the weld too: vertex 4 repeats vertex 1's position and
// uv, and welds only when its colour and TEXCOORD_1 match as well (a colour or lightmap seam
// stays two vertices); the survivors keep their colours and uv1s.
TEST(MeshClean, KeepsColourAndTexcoord1Seams) {
  auto quad = [] {
    MeshData m = make({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 1, 0, 0}, {0, 1, 2, 4, 3, 2});
    m.uvs = {0, 0, 0.1f, 0, 0, 1, 1, 1, 0.1f, 0};
    m.uvs1 = {0, 0, 0.5f, 0, 0, 0.5f, 0.5f, 0.5f, 0.5f, 0};
    m.colors = {1, 0, 0, 1, 0, 1, 0, 1, 0, 0, 1, 1, 1, 1, 1, 1, 0, 1, 0, 1};
    return m;
  };
  MeshData same = quad();
  EXPECT_EQ(clean_mesh(same).duplicate_vertices, 1u) << "equal colour and uv1: welded";
  EXPECT_EQ(same.vertex_count(), 4u);
  EXPECT_EQ(same.colors, (std::vector<float>{1, 0, 0, 1, 0, 1, 0, 1, 0, 0, 1, 1, 1, 1, 1, 1}));
  EXPECT_EQ(same.uvs1, (std::vector<float>{0, 0, 0.5f, 0, 0, 0.5f, 0.5f, 0.5f}));

  MeshData colour_seam = quad();
  colour_seam.colors[4 * 4 + 2] = 0.5f;  // vertex 4: another blue
  EXPECT_EQ(clean_mesh(colour_seam).duplicate_vertices, 0u);
  EXPECT_EQ(colour_seam.vertex_count(), 5u);
  EXPECT_EQ(colour_seam.colors.size(), 20u);
  EXPECT_EQ(colour_seam.colors[4 * 4 + 2], 0.5f);

  MeshData uv1_seam = quad();
  uv1_seam.uvs1[2 * 4] = 0.75f;
  EXPECT_EQ(clean_mesh(uv1_seam).duplicate_vertices, 0u);
  EXPECT_EQ(uv1_seam.vertex_count(), 5u);
  EXPECT_EQ(uv1_seam.uvs1[2 * 4], 0.75f);

  // Without TEXCOORD_0, colours alone still key the weld.
  MeshData colour_only = quad();
  colour_only.uvs.clear();
  colour_only.uvs1.clear();
  colour_only.colors[4 * 4] = 0.25f;
  EXPECT_EQ(clean_mesh(colour_only).duplicate_vertices, 0u);
  EXPECT_TRUE(colour_only.uvs.empty());
}

TEST(MeshClean, DropsFacesWithARepeatedIndex) {
  MeshData m = make({0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2, 0, 0, 1, 2, 1, 2});
  const CleanReport r = clean_mesh(m);
  EXPECT_EQ(r.degenerate_faces, 2u);
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2}));
}

TEST(MeshClean, DropsZeroAreaFaces) {
  // Collinear corners, all distinct.
  MeshData m = make({0, 0, 0, 1, 1, 1, 2, 2, 2, 0, 1, 0}, {0, 1, 2, 0, 1, 3});
  const CleanReport r = clean_mesh(m);
  EXPECT_EQ(r.degenerate_faces, 1u);
  EXPECT_EQ(r.unreferenced_vertices, 1u);  // vertex 2 only belonged to the degenerate face
  EXPECT_EQ(m.triangle_count(), 1u);
  EXPECT_EQ(m.vertex_count(), 3u);
}

TEST(MeshClean, DropsDuplicateFacesWhateverTheirOrientation) {
  MeshData m = make({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}, {0, 1, 2, 1, 2, 0, 2, 1, 0, 1, 3, 2});
  const CleanReport r = clean_mesh(m);
  EXPECT_EQ(r.duplicate_faces, 2u);
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 1, 3, 2}));
}

// Repeated faces are found among the faces of one least corner: a fan of 40 faces around
// vertex 0 (past the 16 distinct keys a group compares directly), each repeated later in
// another winding, some through a welded copy of its rim vertex; the first of each is kept.
TEST(MeshClean, DropsRepeatsInAWideFanKeepingTheFirstOfEach) {
  constexpr uint32_t kRim = 41;  // rim vertices 1..41, then copies of them at 42..82
  std::vector<float> p = {0, 0, 0};
  for (uint32_t k = 0; k < kRim; ++k) p.insert(p.end(), {std::cos(0.07f * float(k)), std::sin(0.07f * float(k)), 0});
  for (uint32_t k = 0; k < kRim; ++k) p.insert(p.end(), p.begin() + 3 * (1 + k), p.begin() + 3 * (2 + k));
  std::vector<uint32_t> fan, repeats;
  for (uint32_t k = 1; k < kRim; ++k) {
    fan.insert(fan.end(), {0, k, k + 1});
    const uint32_t a = k % 2 ? k + kRim : k;  // every other repeat names the copy
    repeats.insert(repeats.end(), {k + 1, 0, a});
  }
  std::vector<uint32_t> all = fan;
  all.insert(all.end(), repeats.begin(), repeats.end());
  MeshData m = make(p, all);
  const CleanReport r = clean_mesh(m);
  EXPECT_EQ(r.duplicate_faces, kRim - 1);
  EXPECT_EQ(r.duplicate_vertices, kRim);
  EXPECT_EQ(r.degenerate_faces, 0u);
  EXPECT_EQ(m.indices, fan);
  EXPECT_EQ(m.vertex_count(), size_t(kRim) + 1);
}

TEST(MeshClean, WeldsBitIdenticalVerticesOntoTheFirst) {
  // Vertex 3 repeats vertex 1; vertex 4 is -0 where vertex 0 has +0 (the same point).
  MeshData m = make({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 0, 0, -0.0f, 0, 0, 1, 1, 0}, {0, 1, 2, 4, 5, 3});
  const CleanReport r = clean_mesh(m);
  EXPECT_EQ(r.duplicate_vertices, 2u);
  EXPECT_EQ(r.unreferenced_vertices, 0u);
  EXPECT_EQ(m.vertex_count(), 4u);
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 3, 1}));
}

TEST(MeshClean, NearlyEqualVerticesAreNotWelded) {
  MeshData m = make({0, 0, 0, 1, 0, 0, 0, 1, 0, 1.0000001f, 0, 0, 1, 1, 0}, {0, 1, 2, 3, 4, 2});
  const CleanReport r = clean_mesh(m);
  EXPECT_EQ(r.duplicate_vertices, 0u);
  EXPECT_EQ(m.vertex_count(), 5u);
}

TEST(MeshClean, WeldingCanMakeFacesDegenerateOrDuplicate) {
  // Vertices 3,4,5 repeat 0,1,2: face 1 becomes a duplicate of face 0; face 2 (0,3,1)
  // becomes (0,0,1), degenerate.
  MeshData m = make({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2, 3, 4, 5, 0, 3, 1});
  const CleanReport r = clean_mesh(m);
  EXPECT_EQ(r.duplicate_vertices, 3u);
  EXPECT_EQ(r.duplicate_faces, 1u);
  EXPECT_EQ(r.degenerate_faces, 1u);
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2}));
}

TEST(MeshClean, RemovesUnreferencedVerticesKeepingOrder) {
  MeshData m = make({9, 9, 9, 0, 0, 0, 8, 8, 8, 1, 0, 0, 0, 1, 0, 7, 7, 7}, {1, 3, 4});
  m.normals = {1, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 1, 0, 1, 0, 0};
  const CleanReport r = clean_mesh(m);
  EXPECT_EQ(r.unreferenced_vertices, 3u);
  EXPECT_EQ(m.positions, (std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}));
  EXPECT_EQ(m.normals, (std::vector<float>{0, 0, 1, 0, 0, 1, 0, 1, 0}));
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2}));
}

TEST(MeshClean, IsDeterministicAndIdempotent) {
  MeshData a = make({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 0, 0, 5, 5, 5, 1, 1, 0},
                    {0, 1, 2, 2, 1, 0, 3, 5, 2, 0, 0, 2, 1, 5, 2});
  MeshData b = a;
  const CleanReport ra = clean_mesh(a);
  const CleanReport rb = clean_mesh(b);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.indices, b.indices);
  EXPECT_EQ(ra.duplicate_faces, rb.duplicate_faces);
  EXPECT_TRUE(ra.changed());
  const CleanReport again = clean_mesh(a);
  EXPECT_FALSE(again.changed());
}

TEST(MeshClean, EverythingDegenerateLeavesAnEmptyMesh) {
  MeshData m = make({0, 0, 0, 1, 0, 0}, {0, 0, 1, 1, 1, 1});
  const CleanReport r = clean_mesh(m);
  EXPECT_EQ(r.degenerate_faces, 2u);
  EXPECT_EQ(r.unreferenced_vertices, 2u);
  EXPECT_EQ(m.triangle_count(), 0u);
  EXPECT_EQ(m.vertex_count(), 0u);
}

}  // namespace
}  // namespace lod
