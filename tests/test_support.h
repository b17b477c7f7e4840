// Shared test helpers: where the real meshes are, and small generated fixtures.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace lod::test {

// Whether one of `x.warnings` (a MeshData, a bake report...) contains `part`.
template <class WithWarnings>
bool has_warning(const WithWarnings& x, const std::string& part) {
  for (const std::string& w : x.warnings)
    if (w.find(part) != std::string::npos) return true;
  return false;
}

// ../shared/data/meshes, or empty when it is absent.
std::filesystem::path shared_meshes();
// Debian CGAL meshes extracted by the build (cow.off, bunny00.off, ...), or empty.
std::filesystem::path data_dir();
// A fresh empty directory under the build tree's tmp, unique per call.
std::filesystem::path temp_dir(const std::string& tag);
void write_text(const std::filesystem::path& path, const std::string& text);
void write_bytes(const std::filesystem::path& path, const std::vector<uint8_t>& bytes);
std::vector<uint8_t> read_bytes(const std::filesystem::path& path);

// Closed UV sphere as OFF text: `rings` x `segments`, radius 1.
std::string sphere_off(int rings, int segments);

}  // namespace lod::test

// Skips the current test with a clear message when a mesh is absent.
#define LOD_REQUIRE_SHARED_MESH(var, name)                                                   \
  const std::filesystem::path var = ::lod::test::shared_meshes() / (name);                  \
  if (::lod::test::shared_meshes().empty() || !std::filesystem::exists(var))                \
  GTEST_SKIP() << "needs ../shared/data/meshes/" << (name) << " (absent on this machine)"
