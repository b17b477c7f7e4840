#include "test_support.h"

#include <atomic>
#include <cmath>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace lod::test {

std::filesystem::path shared_meshes() {
  std::filesystem::path p = LOD_SHARED_MESHES;
  return std::filesystem::is_directory(p) ? p : std::filesystem::path{};
}

std::filesystem::path data_dir() {
  std::filesystem::path p = LOD_DATA_DIR;
  return std::filesystem::exists(p / "cow.off") ? p : std::filesystem::path{};
}

std::filesystem::path temp_dir(const std::string& tag) {
  static std::atomic<int> counter{0};
  auto p = std::filesystem::path(LOD_BINARY_DIR) / "test-tmp" /
           (tag + "-" + std::to_string(getpid()) + "-" + std::to_string(counter++));
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p;
}

void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  f << text;
}

void write_bytes(const std::filesystem::path& path, const std::vector<uint8_t>& bytes) {
  std::ofstream f(path, std::ios::binary);
  f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

std::vector<uint8_t> read_bytes(const std::filesystem::path& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

std::string sphere_off(int rings, int segments) {
  std::ostringstream s;
  const int nv = 2 + (rings - 1) * segments;
  const int nf = 2 * segments * (rings - 1);
  s << "OFF\n" << nv << " " << nf << " 0\n";
  s << "0 1 0\n0 -1 0\n";
  for (int r = 1; r < rings; ++r) {
    const double phi = M_PI * r / rings;
    for (int k = 0; k < segments; ++k) {
      const double th = 2 * M_PI * k / segments;
      s << std::sin(phi) * std::cos(th) << " " << std::cos(phi) << " " << std::sin(phi) * std::sin(th) << "\n";
    }
  }
  auto ring = [&](int r, int k) { return 2 + (r - 1) * segments + (k % segments); };
  for (int k = 0; k < segments; ++k) s << "3 0 " << ring(1, k + 1) << " " << ring(1, k) << "\n";
  for (int r = 1; r < rings - 1; ++r)
    for (int k = 0; k < segments; ++k) {
      s << "3 " << ring(r, k) << " " << ring(r, k + 1) << " " << ring(r + 1, k + 1) << "\n";
      s << "3 " << ring(r, k) << " " << ring(r + 1, k + 1) << " " << ring(r + 1, k) << "\n";
    }
  for (int k = 0; k < segments; ++k) s << "3 1 " << ring(rings - 1, k) << " " << ring(rings - 1, k + 1) << "\n";
  return s.str();
}

}  // namespace lod::test
