// HostTurn: flock on a per-file lock file, removed by its holder on release.
#include "runtime/host_turn.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <string>
#include <system_error>

namespace lod {
namespace {

std::filesystem::path lock_path_for(int fd) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) return {};
  std::error_code ec;
  const std::filesystem::path dir = std::filesystem::temp_directory_path(ec);
  if (ec) return {};
  return dir / ("lodkit-write-" + std::to_string(uint64_t(st.st_dev)) + "-" +
                std::to_string(uint64_t(st.st_ino)) + ".lock");
}

// The holder unlinks the lock file before closing it, so a waiter can win the lock of a file
// no longer under the name: it then tries again with the name's current file.
bool locks_current_file(int fd, const std::filesystem::path& path) {
  struct stat held {
  }, named{};
  return ::fstat(fd, &held) == 0 && ::stat(path.c_str(), &named) == 0 && held.st_dev == named.st_dev &&
         held.st_ino == named.st_ino;
}

}  // namespace

HostTurn::HostTurn(int fd) : path_(lock_path_for(fd)) {
  if (path_.empty()) return;
  for (int attempt = 0; attempt < 64; ++attempt) {
    // Never through a link planted in the shared temporary folder.
    const int lock = ::open(path_.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0600);
    if (lock < 0) return;
    int rc;
    while ((rc = ::flock(lock, LOCK_EX)) != 0 && errno == EINTR) {
    }
    if (rc == 0 && locks_current_file(lock, path_)) {
      fd_ = lock;
      return;
    }
    ::close(lock);
    if (rc != 0) return;
  }
}

HostTurn::~HostTurn() {
  if (fd_ < 0) return;
  ::unlink(path_.c_str());
  ::close(fd_);
}

}  // namespace lod
