// lod_model_add opens regular files only: a FIFO named like a mesh or an asset is refused by
// name without being opened, /dev/zero is never read, and a sparse multi-GB .lod or .off is
// refused from its first bytes.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "fifo_guard.h"
#include "lodkit/lodkit.h"
#include "test_support.h"

namespace {

namespace fs = std::filesystem;

// A service without models, its cache in `dir`.
lod_service* empty_service(const fs::path& dir) {
  lod::test::write_text(dir / "scene.toml", "[run]\nthreads = 1\n");
  char error[512] = "";
  lod_service* s = lod_service_create((dir / "scene.toml").c_str(), error, sizeof error);
  EXPECT_NE(s, nullptr) << error;
  return s;
}

// lod_model_add's message for `path`, empty when it succeeded.
std::string add_error(lod_service* s, const fs::path& path) {
  char error[1024] = "";
  lod_model model = 0;
  if (lod_model_add(s, path.c_str(), &model, error, sizeof error) == 0) return {};
  return error;
}

TEST(CApiRegularFile, ModelAddRefusesAFifoUnopened) {
  const fs::path dir = lod::test::temp_dir("c-api-fifo");
  lod_service* s = empty_service(dir);
  ASSERT_NE(s, nullptr);
  for (const char* name : {"f.off", "f.lod", "f.obj", "f.glb"}) {
    lod::test::FifoGuard fifo(dir / name);
    ASSERT_TRUE(fifo.made());
    const std::string error = add_error(s, fifo.path());
    EXPECT_NE(error.find(std::string(name) + ": is a FIFO, not a regular file"), std::string::npos) << error;
    EXPECT_FALSE(fifo.fired()) << name << ": the FIFO was opened for reading";
  }
  lod_service_destroy(s);
}

TEST(CApiRegularFile, ModelAddNeverReadsDevZero) {
  const fs::path dir = lod::test::temp_dir("c-api-dev-zero");
  lod_service* s = empty_service(dir);
  ASSERT_NE(s, nullptr);
  fs::create_symlink("/dev/zero", dir / "zero.off");
  fs::create_symlink("/dev/zero", dir / "zero.lod");
  for (const char* name : {"zero.off", "zero.lod"}) {
    const std::string error = add_error(s, dir / name);
    EXPECT_NE(error.find(std::string(name) + ": is a character device, not a regular file"), std::string::npos)
        << error;
  }
  lod_service_destroy(s);
}

TEST(CApiRegularFile, SparseMultiGigabyteFilesAreRefusedFromTheirFirstBytes) {
  const fs::path dir = lod::test::temp_dir("c-api-sparse");
  lod_service* s = empty_service(dir);
  ASSERT_NE(s, nullptr);
  for (const char* name : {"big.lod", "big.off"}) {
    lod::test::write_text(dir / name, "");
    ASSERT_EQ(::truncate((dir / name).c_str(), off_t(uint64_t(4) << 30)), 0);  // holes: no disk used
  }
  std::string error = add_error(s, dir / "big.lod");
  EXPECT_NE(error.find("big.lod: not a lodkit asset (bad magic bytes)"), std::string::npos) << error;
  error = add_error(s, dir / "big.off");
  EXPECT_NE(error.find("big.off: holds binary data (a NUL byte at offset 0), not OFF text"), std::string::npos) << error;
  lod_service_destroy(s);
}

}  // namespace
