// Scene configs, HLOD source hashes and cache entries open regular files only: a FIFO in their
// place is refused by name and never opened; a sparse multi-GB entry is refused from its header.
#include <gtest/gtest.h>
#include <unistd.h>

#include "fifo_guard.h"
#include "jobs/hlod_bake.h"
#include "jobs/hlod_mesh_cache.h"
#include "jobs/hlod_model_cache.h"
#include "jobs/scene_config.h"
#include "test_support.h"

namespace lod {
namespace {

namespace fs = std::filesystem;

bool has(const Status& s, const std::string& part) { return !s && s.message.find(part) != std::string::npos; }

TEST(InputFilesJobs, SceneConfigThatIsAFifoIsRefusedUnopened) {
  const fs::path dir = test::temp_dir("jobs-config-fifo");
  test::FifoGuard fifo(dir / "scene.toml");
  ASSERT_TRUE(fifo.made());
  SceneConfig c;
  const Status s = load_scene_config(fifo.path(), dir, c);
  EXPECT_TRUE(has(s, "scene.toml: is a FIFO, not a regular file")) << s.message;
  const Status dev = load_scene_config("/dev/zero", dir, c);
  EXPECT_TRUE(has(dev, "/dev/zero: is a character device, not a regular file")) << dev.message;
  EXPECT_FALSE(fifo.fired()) << "the FIFO was opened for reading";
}

TEST(InputFilesJobs, SceneConfigOverItsLimitIsRefusedUnread) {
  const fs::path dir = test::temp_dir("jobs-config-big");
  test::write_text(dir / "big.toml", "[run]\n");
  ASSERT_EQ(::truncate((dir / "big.toml").c_str(), off_t(uint64_t(4) << 30)), 0);
  SceneConfig c;
  const Status s = load_scene_config(dir / "big.toml", dir, c);
  EXPECT_TRUE(has(s, "big.toml: is 4294967296 bytes; a config file is at most 16777216 bytes")) << s.message;
}

TEST(InputFilesJobs, HlodSourceHashRefusesAFifoUnopened) {
  const fs::path dir = test::temp_dir("jobs-hlod-fifo");
  test::FifoGuard fifo(dir / "m.ply");
  uint64_t hash = 0;
  const Status s = hlod_source_hash(fifo.path(), 64, hash);
  EXPECT_TRUE(has(s, "m.ply: is a FIFO, not a regular file")) << s.message;
  EXPECT_FALSE(fifo.fired()) << "the FIFO was opened for reading";
}

TEST(InputFilesJobs, CacheEntriesThatAreFifosOrSparseAreRefused) {
  const fs::path dir = test::temp_dir("jobs-cache-fifo");
  const uint64_t source = 0x1234;
  // A FIFO where the model entry should be.
  const fs::path model_entry = hlod_model_entry_path(dir, hlod_model_key(source, "m"));
  {
    test::FifoGuard fifo(model_entry);
    std::vector<uint8_t> bytes;
    std::string why;
    EXPECT_EQ(load_hlod_model(dir, hlod_model_key(source, "m"), "m", source, bytes, nullptr, &why), CacheLookup::refused);
    EXPECT_NE(why.find("is a FIFO, not a regular file"), std::string::npos) << why;
    EXPECT_FALSE(fifo.fired()) << "the FIFO was opened for reading";
  }
  // A 4 GiB sparse file there: refused from its first bytes.
  test::write_text(model_entry, "");
  ASSERT_EQ(::truncate(model_entry.c_str(), off_t(uint64_t(4) << 30)), 0);
  std::vector<uint8_t> bytes;
  std::string why;
  EXPECT_EQ(load_hlod_model(dir, hlod_model_key(source, "m"), "m", source, bytes, nullptr, &why), CacheLookup::refused);
  EXPECT_FALSE(why.empty());
  EXPECT_TRUE(bytes.empty());
  // The cleaned-mesh entry.
  const fs::path mesh_entry = hlod_mesh_entry_path(dir, source);
  test::write_text(mesh_entry, "");
  ASSERT_EQ(::truncate(mesh_entry.c_str(), off_t(uint64_t(4) << 30)), 0);
  MeshData mesh;
  uint64_t triangles = 0;
  EXPECT_EQ(load_hlod_mesh(dir, source, "m", mesh, triangles, &why), CacheLookup::refused);
  EXPECT_NE(why.find("not a cleaned mesh entry (bad magic bytes)"), std::string::npos) << why;
}

}  // namespace
}  // namespace lod
