// cache_dir_for: explicit folders, then the environment, then the user's cache folder.
#include "jobs/cache_folder.h"

#include <cstdlib>
#include <system_error>

namespace lod {

namespace {

const char* env(const char* name) {
  const char* v = std::getenv(name);
  return v && *v ? v : nullptr;
}

}  // namespace

std::filesystem::path cache_dir_for(const std::filesystem::path& asked, const std::filesystem::path& configured) {
  if (!asked.empty()) return asked;
  if (!configured.empty()) return configured;
  if (const char* dir = env("LOD_CACHE_DIR")) return dir;
  // A relative XDG_CACHE_HOME is invalid by the spec and would land in the working folder.
  if (const char* xdg = env("XDG_CACHE_HOME"); xdg && std::filesystem::path(xdg).is_absolute())
    return std::filesystem::path(xdg) / "lodkit";
  if (const char* home = env("HOME")) return std::filesystem::path(home) / ".cache" / "lodkit";
  std::error_code ec;
  const std::filesystem::path temp = std::filesystem::temp_directory_path(ec);
  return (ec ? std::filesystem::path("/tmp") : temp) / "lodkit-cache";
}

}  // namespace lod
