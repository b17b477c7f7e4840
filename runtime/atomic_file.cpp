// Temporary file + rename (POSIX rename replaces the target atomically).
#include "runtime/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <string>
#include <system_error>

namespace lod {

Status write_file_atomically(const std::filesystem::path& path, std::span<const uint8_t> bytes) {
  auto refuse = [&](const std::string& why) { return Status::error(path.string() + ": " + why); };
  static std::atomic<uint64_t> serial{0};
  std::filesystem::path tmp = path;
  std::string suffix = ".";
  suffix += std::to_string(::getpid());
  suffix += '-';
  suffix += std::to_string(serial++);
  suffix += ".tmp";
  tmp += suffix;
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) return refuse(std::string("cannot create ") + tmp.string() + ": " + std::strerror(errno));
    f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    f.flush();
    if (!f) {
      std::error_code ignored;
      std::filesystem::remove(tmp, ignored);
      return refuse("write failed after " + std::to_string(bytes.size()) + " bytes requested");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    return refuse("cannot rename " + tmp.string() + ": " + ec.message());
  }
  return Status::success();
}

}  // namespace lod
