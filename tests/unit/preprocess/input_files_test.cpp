// The mesh readers, the bake key and the files an OBJ names open regular files only (a FIFO
// or device is refused by name, never opened), and a file whose first bytes cannot be its
// format is refused from them, not read whole (a sparse multi-GB file, /dev/zero).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>

#include "fifo_guard.h"
#include "preprocess/gltf_io.h"
#include "preprocess/height_field_io.h"
#include "preprocess/height_field_png.h"
#include "preprocess/lod_bake.h"
#include "preprocess/mesh_io.h"
#include "test_support.h"

namespace lod {
namespace {

namespace fs = std::filesystem;

bool has(const Status& s, const std::string& part) { return !s && s.message.find(part) != std::string::npos; }

void sparse_file(const fs::path& path, const std::vector<uint8_t>& head, uint64_t size) {
  test::write_bytes(path, head);
  ASSERT_EQ(::truncate(path.c_str(), off_t(size)), 0) << path;
}

constexpr uint64_t kFourGiB = uint64_t(4) << 30;

TEST(InputFiles, MeshReaderAndBakeKeyRefuseAFifoUnopened) {
  const fs::path dir = test::temp_dir("input-fifo");
  test::FifoGuard fifo(dir / "f.off");
  ASSERT_TRUE(fifo.made());
  MeshData mesh;
  const Status load = load_mesh(fifo.path(), mesh);
  EXPECT_TRUE(has(load, "f.off: is a FIFO, not a regular file")) << load.message;
  Status key;
  EXPECT_EQ(bake_key(fifo.path(), BakeSettings{}, &key), 0u);
  EXPECT_TRUE(has(key, "f.off: is a FIFO, not a regular file")) << key.message;
  uint64_t hash = 0;
  const Status hashed = load_mesh_hashed(fifo.path(), mesh, hash);
  EXPECT_TRUE(has(hashed, "f.off: is a FIFO")) << hashed.message;
  EXPECT_FALSE(fifo.fired()) << "the FIFO was opened for reading";
}

TEST(InputFiles, GltfAndHeightFieldReadersRefuseAFifoUnopened) {
  const fs::path dir = test::temp_dir("input-fifo-gltf");
  test::FifoGuard glb(dir / "f.glb");
  test::FifoGuard png(dir / "h.png");
  test::FifoGuard text(dir / "h.txt");
  MeshData mesh;
  const Status g = load_mesh(glb.path(), mesh);
  EXPECT_TRUE(has(g, "f.glb: is a FIFO")) << g.message;
  HeightField field;
  const Status p = read_height_field_png(png.path(), field, HeightFieldOptions{});
  EXPECT_TRUE(has(p, "h.png: is a FIFO")) << p.message;
  const Status t = read_height_field_text(text.path(), field, HeightFieldTextOptions{});
  EXPECT_TRUE(has(t, "h.txt: is a FIFO")) << t.message;
  EXPECT_FALSE(glb.fired() || png.fired() || text.fired()) << "a FIFO was opened for reading";
}

// The OBJ's material names a FIFO as its texture: the load and the bake key refuse it by name.
TEST(InputFiles, MaterialTextureThatIsAFifoIsRefused) {
  const fs::path dir = test::temp_dir("input-mtl-fifo");
  test::FifoGuard fifo(dir / "tex.png");
  test::write_text(dir / "m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
  test::write_text(dir / "m.mtl", "newmtl a\nmap_Kd tex.png\n");
  MeshData mesh;
  const Status load = load_mesh(dir / "m.obj", mesh);
  EXPECT_TRUE(has(load, "tex.png: is a FIFO, not a regular file")) << load.message;
  Status key;
  EXPECT_EQ(bake_key(dir / "m.obj", BakeSettings{}, &key), 0u);
  EXPECT_TRUE(has(key, "tex.png: is a FIFO, not a regular file")) << key.message;
  LodChain chain;
  const Status baked = bake_model(dir / "m.obj", "m", BakeSettings{}, chain, nullptr, {});
  EXPECT_TRUE(has(baked, "tex.png: is a FIFO")) << baked.message;
  EXPECT_FALSE(fifo.fired()) << "the FIFO was opened for reading";
}

TEST(InputFiles, MtlLibraryThatIsAFifoIsRefused) {
  const fs::path dir = test::temp_dir("input-mtllib-fifo");
  test::FifoGuard fifo(dir / "m.mtl");
  test::write_text(dir / "m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
  MeshData mesh;
  const Status load = load_mesh(dir / "m.obj", mesh);
  EXPECT_TRUE(has(load, "m.mtl: is a FIFO, not a regular file")) << load.message;
  Status key;
  bake_key(dir / "m.obj", BakeSettings{}, &key);
  EXPECT_TRUE(has(key, "m.mtl: is a FIFO, not a regular file")) << key.message;
  EXPECT_FALSE(fifo.fired()) << "the FIFO was opened for reading";
}

// A 35-byte MTL naming /dev/zero as its texture used to read it until memory ran out.
TEST(InputFiles, DevZeroIsNeverRead) {
  const fs::path dir = test::temp_dir("input-dev-zero");
  test::write_text(dir / "m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
  test::write_text(dir / "m.mtl", "newmtl a\nmap_Kd /dev/zero\n");
  MeshData mesh;
  const Status load = load_mesh(dir / "m.obj", mesh);
  EXPECT_TRUE(has(load, "/dev/zero: is a character device, not a regular file")) << load.message;
  Status key;
  EXPECT_EQ(bake_key(dir / "m.obj", BakeSettings{}, &key), 0u);
  EXPECT_TRUE(has(key, "/dev/zero: is a character device")) << key.message;
  EXPECT_EQ(bake_key("/dev/zero", BakeSettings{}, &key), 0u);
  EXPECT_TRUE(has(key, "/dev/zero: is a character device")) << key.message;
  fs::create_symlink("/dev/zero", dir / "zero.off");
  const Status linked = load_mesh(dir / "zero.off", mesh);
  EXPECT_TRUE(has(linked, "zero.off: is a character device")) << linked.message;
}

// 4 GiB of holes: each reader says what is wrong from the first bytes, and the bake key does
// not hash what cannot be a mesh.
TEST(InputFiles, SparseMultiGigabyteMeshesAreRefusedFromTheirFirstBytes) {
  const fs::path dir = test::temp_dir("input-sparse");
  sparse_file(dir / "big.off", {}, kFourGiB);
  MeshData mesh;
  Status s = load_mesh(dir / "big.off", mesh);
  EXPECT_TRUE(has(s, "big.off: holds binary data (a NUL byte at offset 0), not OFF text")) << s.message;
  Status key;
  EXPECT_EQ(bake_key(dir / "big.off", BakeSettings{}, &key), 0u);
  EXPECT_TRUE(has(key, "big.off: holds binary data")) << key.message;
  const std::string header = "OFF\n3 1 0\n";
  sparse_file(dir / "headed.off", std::vector<uint8_t>(header.begin(), header.end()), kFourGiB);
  s = load_mesh(dir / "headed.off", mesh);
  EXPECT_TRUE(has(s, "headed.off: holds binary data (a NUL byte at offset 10), not OFF text")) << s.message;
  sparse_file(dir / "big.obj", {}, kFourGiB);
  s = load_mesh(dir / "big.obj", mesh);
  EXPECT_TRUE(has(s, "big.obj: holds binary data")) << s.message;
  sparse_file(dir / "big.ply", {}, kFourGiB);
  s = load_mesh(dir / "big.ply", mesh);
  EXPECT_TRUE(has(s, "big.ply: not a PLY file")) << s.message;
  sparse_file(dir / "big.stl", {}, kFourGiB);
  s = load_mesh(dir / "big.stl", mesh);
  EXPECT_TRUE(has(s, "big.stl: has no faces (binary STL declares 0 triangles)")) << s.message;
  std::vector<uint8_t> stl(84, 0);
  stl[80] = 0xff, stl[81] = 0xff, stl[82] = 0xff, stl[83] = 0xff;  // more triangles than 4 GiB hold
  sparse_file(dir / "many.stl", stl, kFourGiB);
  s = load_mesh(dir / "many.stl", mesh);
  EXPECT_TRUE(has(s, "many.stl: truncated: binary STL declares 4294967295 triangles")) << s.message;
  sparse_file(dir / "big.glb", {}, kFourGiB);
  s = load_mesh(dir / "big.glb", mesh);
  EXPECT_TRUE(has(s, "big.glb: is 4294967296 bytes; a glTF file is at most")) << s.message;
  sparse_file(dir / "big.txt", {}, kFourGiB);
  HeightField field;
  s = read_height_field_text(dir / "big.txt", field, HeightFieldTextOptions{});
  EXPECT_TRUE(has(s, "big.txt: holds binary data")) << s.message;
  sparse_file(dir / "big.png", {}, kFourGiB);
  s = read_height_field_png(dir / "big.png", field, HeightFieldOptions{});
  EXPECT_TRUE(has(s, "big.png: not a PNG file")) << s.message;
}

// A binary STL with bytes after its declared triangles: only the declared ones are read.
TEST(InputFiles, BinaryStlIsReadOnlyAsFarAsItsCount) {
  const fs::path dir = test::temp_dir("input-stl-count");
  std::vector<uint8_t> stl(84 + 50, 0);
  stl[80] = 1;
  const float corners[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::memcpy(stl.data() + 84 + 12, corners, sizeof corners);
  sparse_file(dir / "tail.stl", stl, kFourGiB);
  MeshData mesh;
  const Status s = load_mesh(dir / "tail.stl", mesh);
  ASSERT_TRUE(s) << s.message;
  EXPECT_EQ(mesh.indices.size(), 3u);
}

}  // namespace
}  // namespace lod
